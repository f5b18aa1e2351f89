"""A run's time series as an inline SVG drawing, built with NumPy (no matplotlib): drawbar
pull, torque, sinkage and slip against time, stacked, from the traces stored at processing
(``run_results.traces``), the stable window shaded and each quantity's mean over it dashed.

It keeps the look the page's matplotlib figures have (an 8 x 6.4 in figure at 100 dpi,
DejaVu Sans at matplotlib's default sizes, the load colours of
:class:`campaign_report.style.Palette`, the layout, line widths and dashes of matplotlib's
defaults) at a fraction of the cost: a figure is a few string joins, where drawing and
encoding it with matplotlib took about 100 ms a run (issue 19 item 5). Ticks are placed as
matplotlib's ``MaxNLocator`` places them (steps 1, 1.5, 2, 2.5, 3, 4, 5, 6, 8 x 10^k) and
labelled as its ``ScalarFormatter`` labels them (the decimals the labels need to differ),
without offset or scientific notation. A trace is one path per stretch of finite values, its
points in tenths of a pixel, in full (at most ``MAX_TRACE_POINTS`` a quantity): nothing is
dropped between the stored points and the drawing; each panel clips what lies beyond it.
"""

from __future__ import annotations

import math
import textwrap
from html import escape

import numpy as np

from campaign_report.data import RunRecord
from campaign_report.style import QUANTITIES, Palette
from run_results.traces import TRACE_QUANTITIES

#: what a panel says for a run processed before traces were stored
NOT_STORED = "trace not stored; re-run swtlab process"
WINDOW_COLOUR = "#cfe3cf"
NOT_OK_COLOUR = "#a00000"
WIDTH_PX, HEIGHT_PX = 800, 640
#: panel placement (figure fractions, matplotlib's ``subplots_adjust``); the top is lower
#: when the title carries the reason for no stable phase
LEFT, RIGHT, BOTTOM, TOP, TOP_WITH_REASON, HSPACE = 0.1, 0.98, 0.13, 0.93, 0.86, 0.12
#: where the axis labels sit (panel fractions), fixed so the four y labels line up
YLABEL_X, XLABEL_Y = -0.075, -0.32
#: most tick intervals on the time axis and on each quantity's axis
TIME_BINS, VALUE_BINS = 6, 4
#: MaxNLocator's default steps (matplotlib.ticker)
TICK_STEPS = (1.0, 1.5, 2.0, 2.5, 3.0, 4.0, 5.0, 6.0, 8.0, 10.0)
X_MARGIN = 0.05  # matplotlib's axes.xmargin
REASON_WRAP = 110  # characters per line of a title's reason
PX_PER_PT = 100.0 / 72.0
FONT_PX = 10.0 * PX_PER_PT  # matplotlib's default font size
LEGEND_FONT_PX = FONT_PX / 1.2  # "small"
ASCENT_EM, DESCENT_EM = 0.76, 0.24  # DejaVu Sans, of digits and lower case
#: average advance of DejaVu Sans characters (em), to centre the legend
CHAR_EM = 0.58
LINE_PX = 0.8 * PX_PER_PT  # trace, spines, ticks, grid
MEAN_PX = 1.2 * PX_PER_PT
MEAN_DASH = (3.7 * MEAN_PX, 1.6 * MEAN_PX)  # matplotlib's "--", scaled by the line width
TICK_PX = 3.5 * PX_PER_PT  # tick length and the gap to its label
GRID_COLOUR, GRID_OPACITY = "#b0b0b0", 0.3
FONT = "DejaVu Sans,Bitstream Vera Sans,Arial,sans-serif"
SUBPIXELS = 10  # trace coordinates in tenths of a pixel
#: how far beyond its panel a trace point is kept (panel heights): further ones are pulled
#: in to this (clipped away; where the line leaves the panel it moves by at most 1/26 of a
#: step between points, under 0.02 px for 2000 points across the panel)
CLAMP_PANELS = 25.0
#: path numbers (tenths of a pixel) written by table lookup, a tenth of ``str``'s time
_INT_TEXT_LIMIT = 1 << 15
_INT_TEXT = np.array([str(i) for i in range(-_INT_TEXT_LIMIT, _INT_TEXT_LIMIT)], dtype=object)


def nice_ticks(lo: float, hi: float, max_bins: int) -> np.ndarray:
    """Tick values inside ``[lo, hi]``: the multiples of the smallest step of
    :data:`TICK_STEPS` x 10^k that cuts the range into at most ``max_bins`` intervals (two
    ticks at least: a smaller step where one would show)."""
    if not (math.isfinite(lo) and math.isfinite(hi)) or hi <= lo:
        return np.array([lo]) if math.isfinite(lo) else np.array([])
    span = hi - lo
    decade = 10.0 ** math.floor(math.log10(span / max_bins))
    steps = [s * decade * f for f in (0.1, 1.0, 10.0) for s in TICK_STEPS]
    eps = 1e-10 * span
    first = next(i for i, s in enumerate(steps) if s * max_bins >= span - eps)
    for step in reversed(steps[:first + 1]):
        k0, k1 = math.ceil((lo - eps) / step), math.floor((hi + eps) / step)
        if k1 - k0 >= 1:  # two ticks at least
            break
    ticks = np.arange(k0, k1 + 1) * step
    ticks[np.abs(ticks) < eps] = 0.0
    return ticks


def tick_labels(ticks: np.ndarray) -> list[str]:
    """The ticks as fixed-point text with the fewest decimals that keep each tick's value
    (to a thousandth of their range), as matplotlib's ``ScalarFormatter`` does; a Unicode
    minus."""
    if ticks.size == 0:
        return []
    span = float(np.ptp(ticks)) or max(abs(float(ticks[0])), 1.0)
    magnitude = math.floor(math.log10(span))
    tolerance = 1e-3 * 10.0 ** magnitude
    decimals = max(0, 3 - magnitude)
    while decimals > 0 and np.all(np.abs(ticks - np.round(ticks, decimals - 1)) < tolerance):
        decimals -= 1
    texts = [f"{t:.{decimals}f}" for t in ticks]
    return [("0" + t[2:] if t.startswith("-0") and not t.strip("-0.") else t).replace("-", "−")
            for t in texts]


def _robust_limits(values: np.ndarray) -> tuple[float, float] | None:
    """Y limits from the 0.5-99.5 % range, so one spike at a run's start does not flatten
    it; None with fewer than two finite values."""
    finite = values[np.isfinite(values)]
    if finite.size < 2:
        return None
    lo, hi = np.percentile(finite, [0.5, 99.5])
    pad = 0.08 * (hi - lo) if hi > lo else max(abs(hi), 1.0) * 0.1
    return float(lo - pad), float(hi + pad)


def _data_limits(values: list[float]) -> tuple[float, float]:
    """Autoscaled limits of finite ``values`` (5 % margins); (0, 1) without any."""
    finite = [v for v in values if math.isfinite(v)]
    if not finite:
        return 0.0, 1.0
    lo, hi = min(finite), max(finite)
    pad = 0.05 * (hi - lo) if hi > lo else max(abs(hi), 1.0) * 0.1
    return lo - pad, hi + pad


def _num(x: float) -> str:
    return f"{x:.2f}".rstrip("0").rstrip(".")


def _path(t_s: np.ndarray, values: np.ndarray, x_scale: float, x_lo: float, height: float,
          y_lo: float, y_scale: float) -> str:
    """Path data of a trace in the panel's pixels x :data:`SUBPIXELS` (absolute first point,
    then relative steps), one subpath per stretch of finite values."""
    t, v = np.asarray(t_s, float), np.asarray(values, float)
    ok = np.isfinite(t) & np.isfinite(v)
    x = np.rint(SUBPIXELS * (t - x_lo) * x_scale)
    y = np.rint(SUBPIXELS * np.clip(height - (v - y_lo) * y_scale, -CLAMP_PANELS * height,
                                    (CLAMP_PANELS + 1.0) * height))
    # stretches of finite points: starts and ends
    edges = np.diff(np.concatenate(([0], ok.astype(np.int8), [0])))
    starts, ends = np.flatnonzero(edges == 1), np.flatnonzero(edges == -1)
    parts = []
    xi, yi = np.zeros(t.size, np.int64), np.zeros(t.size, np.int64)
    xi[ok], yi[ok] = x[ok], y[ok]
    for s, e in zip(starts, ends):
        steps = np.empty((e - s - 1, 2), np.int64)
        steps[:, 0], steps[:, 1] = np.diff(xi[s:e]), np.diff(yi[s:e])
        parts.append(f"M{xi[s]} {yi[s]}" + ("l" + _int_text(steps.ravel())
                                            if e - s > 1 else ""))  # alone: not drawn
    return "".join(parts)


def _int_text(values: np.ndarray) -> str:
    """Integers as text, separated by spaces."""
    if values.size and np.abs(values).max() < _INT_TEXT_LIMIT:
        return " ".join(_INT_TEXT[values + _INT_TEXT_LIMIT].tolist())
    return " ".join(map(str, values.tolist()))


def _text(x: float, y: float, text: str, size: float = FONT_PX, anchor: str = "middle",
          colour: str | None = None, extra: str = "") -> str:
    fill = f' fill="{colour}"' if colour else ""
    return (f'<text x="{_num(x)}" y="{_num(y)}" font-size="{_num(size)}" '
            f'text-anchor="{anchor}"{fill}{extra}>{escape(text)}</text>')


class _Panel:
    """One quantity's axes: its box in the figure (px) and its data limits."""

    def __init__(self, key: str, x0: float, y0: float, width: float, height: float) -> None:
        self.key, self.x0, self.y0, self.width, self.height = key, x0, y0, width, height
        self.body: list[str] = []  # drawn inside, clipped: window, grid, lines
        self.labels: list[str] = []  # legend labels, in drawing order
        self.y_lim: tuple[float, float] = (0.0, 1.0)


def timeseries_svg(run: RunRecord, palette: Palette, drawing_id: str) -> str:
    """``run``'s time series as an ``<svg>`` element (800 x 640 user units, the figure's
    pixels), its drawing in a group with id ``drawing_id`` (a second ``<svg>`` can show it
    again with ``<use>``). The stored traces (min/max per block; each shifted by the
    re-zeroing correction its mean carries, ``run.corrections``, so that a trace re-zeroed at
    the rests and its mean agree), the stable window shaded with each quantity's mean over
    it; a run with no stable phase gets the reason in its
    title, in red as every run not ``ok``. A run processed before traces were stored says so
    in its panels (and shows its stored DP trace, if it has no stable phase)."""
    colour = palette.colour(run.load_n)
    top = TOP_WITH_REASON if run.status == "no_stable_phase" else TOP
    x0, x1 = LEFT * WIDTH_PX, RIGHT * WIDTH_PX
    y_top, y_bottom = (1.0 - top) * HEIGHT_PX, (1.0 - BOTTOM) * HEIGHT_PX
    n = len(TRACE_QUANTITIES)
    height = (y_bottom - y_top) / (n + HSPACE * (n - 1))
    panels = [_Panel(key, x0, y_top + i * height * (1.0 + HSPACE), x1 - x0, height)
              for i, key in enumerate(TRACE_QUANTITIES)]
    window = (run.window_start_s, run.window_end_s)
    has_window = None not in window
    # the time range: every trace and the window, with matplotlib's margins
    times = [float(w) for w in window if w is not None]
    series: dict[str, tuple[np.ndarray, np.ndarray, str, str, float]] = {}
    for panel in panels:
        q = QUANTITIES[panel.key]
        trace = None if run.traces is None else run.traces.get(panel.key)
        if trace is not None:  # shifted by the mean's re-zeroing, so the two agree
            shift = run.corrections.get(panel.key, 0.0)
            series[panel.key] = (np.asarray(trace.t_s, float),
                                 (np.asarray(trace.values, float) + shift) * q.scale, colour,
                                 "stored trace", LINE_PX)
        elif panel.key == "dp_n" and run.traces is None and run.dp_trace:  # older results
            series[panel.key] = (np.asarray(run.dp_trace["t_s"], float),
                                 np.array([np.nan if v is None else v
                                           for v in run.dp_trace["dp_n"]], float),
                                 "#000000", "stored DP trace", 1.0 * PX_PER_PT)
        if panel.key in series:
            t = series[panel.key][0]
            t = t[np.isfinite(t)]
            if t.size:
                times += [float(t.min()), float(t.max())]
    t_lo, t_hi = (min(times), max(times)) if times else (0.0, 1.0)
    pad = X_MARGIN * (t_hi - t_lo) if t_hi > t_lo else 0.5
    t_lo, t_hi = t_lo - pad, t_hi + pad
    x_scale = (x1 - x0) / (t_hi - t_lo)
    time_ticks = nice_ticks(t_lo, t_hi, TIME_BINS)
    legend: dict[str, str] = {}  # label -> handle markup
    out = [f'<svg viewBox="0 0 {WIDTH_PX} {HEIGHT_PX}" '
           f'width="{WIDTH_PX}" height="{HEIGHT_PX}" role="img" '
           f'aria-label="{escape(run.run_id)}: time series"><g id="{escape(drawing_id)}" '
           f'font-family="{FONT}" fill="#000000">'
           f'<rect width="{WIDTH_PX}" height="{HEIGHT_PX}" fill="#ffffff"/>']
    for i, panel in enumerate(panels):
        q = QUANTITIES[panel.key]
        mean = run.means.get(panel.key) if has_window else None
        mean_px = None if mean is None else mean * q.scale
        drawn = series.get(panel.key)
        if drawn is not None and drawn[3] == "stored trace":
            panel.y_lim = _robust_limits(drawn[1]) or _data_limits(
                [float(v) for v in drawn[1]] + ([mean_px] if mean_px is not None else []))
        elif drawn is not None or mean_px is not None:
            values = [] if drawn is None else [float(v) for v in drawn[1]]
            panel.y_lim = _data_limits(values + ([mean_px] if mean_px is not None else []))
        y_lo, y_hi = panel.y_lim
        y_scale = panel.height / (y_hi - y_lo)
        value_ticks = nice_ticks(y_lo, y_hi, VALUE_BINS)
        w, h = panel.width, panel.height
        body = [f'<svg class="axes" data-quantity="{panel.key}" x="{_num(panel.x0)}" '
                f'y="{_num(panel.y0)}" width="{_num(w)}" height="{_num(h)}">']
        if has_window:
            body.append(f'<rect class="window" x="{_num((window[0] - t_lo) * x_scale)}" y="0" '
                        f'width="{_num((window[1] - window[0]) * x_scale)}" height="{_num(h)}" '
                        f'fill="{WINDOW_COLOUR}"/>')
            legend.setdefault("stable window", f'<rect x="0" y="-4" height="8" '
                              f'width="{_num(2 * LEGEND_FONT_PX)}" fill="{WINDOW_COLOUR}"/>')
        grid = [f"M{_num((t - t_lo) * x_scale)} 0v{_num(h)}" for t in time_ticks]
        grid += [f"M0 {_num(h - (v - y_lo) * y_scale)}h{_num(w)}" for v in value_ticks]
        body.append(f'<path class="grid" d="{"".join(grid)}" stroke="{GRID_COLOUR}" '
                    f'stroke-opacity="{GRID_OPACITY}" stroke-width="{_num(LINE_PX)}" '
                    'fill="none"/>')
        dash = " ".join(_num(d) for d in MEAN_DASH)
        if mean_px is not None:
            y = h - (mean_px - y_lo) * y_scale
            body.append(f'<path class="mean" d="M{_num((window[0] - t_lo) * x_scale)} {_num(y)}'
                        f'H{_num((window[1] - t_lo) * x_scale)}" stroke="#000000" '
                        f'stroke-width="{_num(MEAN_PX)}" stroke-dasharray="{dash}" fill="none"/>')
            legend.setdefault("mean over window", f'<path d="M0 0h{_num(2 * LEGEND_FONT_PX)}" '
                              f'stroke="#000000" stroke-width="{_num(MEAN_PX)}" '
                              f'stroke-dasharray="{dash}"/>')
        if drawn is not None:
            t, v, line_colour, label, width = drawn
            d = _path(t, v, x_scale, t_lo, h, y_lo, y_scale)
            body.append(f'<path class="trace" transform="scale({1 / SUBPIXELS:g})" d="{d}" '
                        f'stroke="{line_colour}" stroke-width="{_num(SUBPIXELS * width)}" '
                        'stroke-linejoin="round" fill="none"/>')
            legend.setdefault(label, f'<path d="M0 0h{_num(2 * LEGEND_FONT_PX)}" '
                              f'stroke="{line_colour}" stroke-width="{_num(width)}"/>')
        if drawn is None or drawn[3] != "stored trace":
            text = NOT_STORED if run.traces is None else "not measured"
            box_w = CHAR_EM * FONT_PX * len(text) + 8.0
            body.append(f'<rect x="{_num((w - box_w) / 2)}" y="{_num(h / 2 - 0.8 * FONT_PX)}" '
                        f'width="{_num(box_w)}" height="{_num(1.6 * FONT_PX)}" fill="#ffffff" '
                        'fill-opacity="0.85"/>')
            body.append(_text(w / 2, h / 2 + 0.38 * FONT_PX, text, colour="#666666",
                              extra=' class="note"'))
        body.append("</svg>")
        out += body
        # frame, ticks and their labels, the axis label (outside the clip)
        out.append(f'<rect x="{_num(panel.x0)}" y="{_num(panel.y0)}" width="{_num(w)}" '
                   f'height="{_num(h)}" fill="none" stroke="#000000" '
                   f'stroke-width="{_num(LINE_PX)}"/>')
        ticks = [f"M{_num(panel.x0 + (t - t_lo) * x_scale)} {_num(panel.y0 + h)}v{_num(TICK_PX)}"
                 for t in time_ticks]
        ticks += [f"M{_num(panel.x0)} {_num(panel.y0 + h - (v - y_lo) * y_scale)}"
                  f"h{_num(-TICK_PX)}" for v in value_ticks]
        out.append(f'<path d="{"".join(ticks)}" stroke="#000000" '
                   f'stroke-width="{_num(LINE_PX)}"/>')
        labels = [_text(panel.x0 - 2 * TICK_PX, panel.y0 + h - (v - y_lo) * y_scale
                        + 0.5 * ASCENT_EM * FONT_PX, text, anchor="end")
                  for v, text in zip(value_ticks, tick_labels(value_ticks))]
        out.append(f'<g class="yticks" data-quantity="{panel.key}">{"".join(labels)}</g>')
        y_mid = panel.y0 + h / 2
        x_label = panel.x0 + YLABEL_X * w - DESCENT_EM * FONT_PX
        out.append(_text(0, 0, q.axis_label, extra=f' class="ylabel" transform="translate('
                                                    f'{_num(x_label)} {_num(y_mid)}) rotate(-90)"'))
        if i == len(panels) - 1:
            labels = [_text(panel.x0 + (t - t_lo) * x_scale,
                            panel.y0 + h + 2 * TICK_PX + ASCENT_EM * FONT_PX, text)
                      for t, text in zip(time_ticks, tick_labels(time_ticks))]
            out.append(f'<g class="xticks">{"".join(labels)}</g>')
            out.append(_text(panel.x0 + w / 2, panel.y0 + h - XLABEL_Y * h
                             + ASCENT_EM * FONT_PX, QUANTITIES["t_s"].axis_label,
                             extra=' class="xlabel"'))
    out += _title(run)
    out.append(_legend(legend))
    out.append("</g></svg>")
    return "".join(out)


def _title(run: RunRecord) -> list[str]:
    """The title lines: the run's condition; the reason for no stable phase, wrapped."""
    lines = [f"{run.run_id}: {run.mode}, {run.load_n:g} N, multipass {run.multipass}"
             + (f", slip set {100 * run.slip_setpoint:g} %"
                if run.slip_setpoint is not None else "")]
    if run.status == "no_stable_phase":
        lines += textwrap.wrap("; ".join(run.flags), REASON_WRAP)
    colour = NOT_OK_COLOUR if run.status != "ok" else "#000000"
    y = 0.02 * HEIGHT_PX + ASCENT_EM * FONT_PX
    return [f'<g class="title" fill="{colour}">'] + [
        _text(WIDTH_PX / 2, y + j * 1.2 * FONT_PX, line) for j, line in enumerate(lines)
    ] + ["</g>"]


def _legend(entries: dict[str, str]) -> str:
    """One row at the figure's foot, centred: each entry's handle (two ems long) and label."""
    em = LEGEND_FONT_PX
    widths = [2.0 * em + 0.8 * em + CHAR_EM * em * len(label) for label in entries]
    x = (WIDTH_PX - sum(widths) - 2.0 * em * (len(widths) - 1)) / 2
    y = HEIGHT_PX - 0.9 * em - DESCENT_EM * em
    parts = ['<g class="legend">']
    for (label, handle), width in zip(entries.items(), widths):
        parts.append(f'<g transform="translate({_num(x)} {_num(y - 0.35 * em)})">{handle}</g>')
        parts.append(_text(x + 2.8 * em, y, label, size=em, anchor="start"))
        x += width + 2.0 * em
    parts.append("</g>")
    return "".join(parts)
