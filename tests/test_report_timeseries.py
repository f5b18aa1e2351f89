"""A run's time series as inline SVG (campaign_report.timeseries): the drawing's numbers read
back through its own tick labels. Each panel's pixel <-> value map is fitted from the printed
tick labels and the grid lines drawn at them (not from the module's transform), then the trace's
path points must land on the stored trace values, the shading on the stable window's times and
the dashed line on the window mean, each within a pixel. Ticks are checked against matplotlib's
MaxNLocator and ScalarFormatter (independent code), and against steps worked by hand."""

from __future__ import annotations

import re
import xml.etree.ElementTree as ET
from dataclasses import replace

import numpy as np
import pytest
from matplotlib.figure import Figure
from matplotlib.ticker import MaxNLocator, ScalarFormatter

from campaign_report import timeseries
from campaign_report.data import RunRecord
from campaign_report.style import Palette
from run_results.traces import TRACE_QUANTITIES, Trace

UNIT = re.compile(r"\[[^\]]+\]$")
SCALE = {"dp_n": 1.0, "torque_nm": 1.0, "sinkage_m": 1000.0, "slip": 100.0}


def _traces(end_s: float = 60.0, n: int = 1600, seed: int = 4) -> dict[str, Trace]:
    rng = np.random.default_rng(seed)
    t = np.linspace(0.0, end_s, n)
    levels = {"dp_n": (25.0, 4.0), "torque_nm": (3.0, 0.5), "sinkage_m": (0.012, 0.002),
              "slip": (0.2, 0.02)}
    out = {}
    for k in TRACE_QUANTITIES:
        mean, sd = levels[k]
        v = (mean + sd * np.sin(t) + 0.3 * sd * rng.standard_normal(n)).astype(np.float32)
        out[k] = Trace(t_s=t, values=v, unit="", samples=n, block=1)
    return out


def _run(traces=None, status="ok", window=(20.0, 45.0), flags=(), dp_trace=None,
         run_id="L070_MP0_SC_s+020") -> RunRecord:
    means = {} if window is None else {"dp_n": 24.5, "torque_nm": 3.1, "sinkage_m": 0.0121,
                                        "slip": 0.199}
    return RunRecord(run_id=run_id, wheel="w", soil="s", mode="speed_control", multipass=0,
                     load_n=70.0, slip_setpoint=0.2, velocity_mps=0.01, status=status,
                     flags=flags, window_start_s=None if window is None else window[0],
                     window_end_s=None if window is None else window[1], dp_trace=dp_trace,
                     traces=traces, means=means)


def _svg(run: RunRecord, loads=(70.0, 180.0)) -> ET.Element:
    return ET.fromstring(timeseries.timeseries_svg(run, Palette(list(loads), [0]), "d"))


def _number(text: str) -> float:
    return float(text.replace("−", "-"))


def _grid(panel: ET.Element) -> tuple[list[float], list[float]]:
    """(x of the vertical grid lines, y of the horizontal ones), panel pixels."""
    d = panel.find("path[@class='grid']").get("d")
    xs = [float(x) for x in re.findall(r"M([-\d.]+) 0v", d)]
    ys = [float(y) for y in re.findall(r"M0 ([-\d.]+)h", d)]
    return xs, ys


def _fit(values: list[float], pixels: list[float]) -> tuple[float, float]:
    """(slope, intercept) of pixel = slope * value + intercept, from >= 2 ticks."""
    assert len(values) == len(pixels) >= 2
    slope, intercept = np.polyfit(values, pixels, 1)
    assert np.allclose(np.polyval((slope, intercept), values), pixels, atol=0.02)
    return slope, intercept


def _maps(root: ET.Element) -> dict[str, dict]:
    """Per quantity: its panel element and its value->pixel maps fitted from the printed
    tick labels and the grid lines at them."""
    time_values = [_number(t.text) for t in root.findall(".//g[@class='xticks']/text")]
    out = {}
    for panel in root.iter("svg"):
        if panel.get("class") != "axes":
            continue
        key = panel.get("data-quantity")
        labels = root.find(f".//g[@class='yticks'][@data-quantity='{key}']")
        values = [_number(t.text) for t in labels.findall("text")]
        xs, ys = _grid(panel)
        out[key] = {"panel": panel, "x": _fit(time_values, xs), "y": _fit(values, ys),
                    "height": float(panel.get("height")), "width": float(panel.get("width"))}
    return out


def _path_points(d: str, scale: float) -> list[np.ndarray]:
    """Absolute (x, y) points of each subpath of ``M x y l dx dy ...`` path data."""
    parts = []
    for sub in re.findall(r"M[^M]+", d):
        numbers = [float(v) for v in re.findall(r"-?\d+(?:\.\d+)?", sub)]
        xy = np.array(numbers, float).reshape(-1, 2)
        parts.append(np.cumsum(xy, axis=0) * scale)
    return parts


def test_trace_points_map_back_to_the_stored_values_within_a_pixel():
    traces = _traces()
    # a NaN block splits the line in two; a spike the robust limits leave off the panel
    values = traces["torque_nm"].values.copy()
    values[700:702] = np.nan
    values[100] = 500.0
    traces["torque_nm"] = Trace(traces["torque_nm"].t_s, values, "", 1600, 1)
    root = _svg(_run(traces))
    maps = _maps(root)
    assert list(maps) == list(TRACE_QUANTITIES)
    for key, m in maps.items():
        path = m["panel"].find("path[@class='trace']")
        scale = float(re.fullmatch(r"scale\(([\d.]+)\)", path.get("transform")).group(1))
        parts = _path_points(path.get("d"), scale)
        t, v = traces[key].t_s, traces[key].values.astype(float) * SCALE[key]
        finite = np.isfinite(v)
        assert len(parts) == (2 if key == "torque_nm" else 1)
        drawn = np.concatenate(parts)
        assert len(drawn) == finite.sum()  # every stored finite point, no other
        x_expected = np.polyval(m["x"], t[finite])
        y_expected = np.polyval(m["y"], v[finite])
        inside = (y_expected > -m["height"]) & (y_expected < 2 * m["height"])
        assert np.abs(drawn[:, 0] - x_expected).max() < 1.0
        assert np.abs(drawn[inside, 1] - y_expected[inside]).max() < 1.0
        # the drawn line's colour is the load's
        assert path.get("stroke") == Palette([70.0, 180.0], [0]).colour(70.0)
    # the spike is drawn beyond the panel (clipped away), not allowed to flatten the trace
    torque = maps["torque_nm"]
    lo, hi = sorted(np.polyval(np.poly1d([1 / torque["y"][0], -torque["y"][1] / torque["y"][0]]),
                               [0.0, torque["height"]]))
    assert hi < 10.0 and lo > 0.0  # 500 N·m is off the axis, which spans the 3 ± 0.5 signal


def test_a_trace_is_drawn_re_zeroed_as_its_mean():
    """The stored traces are before the rests' re-zeroing, the means after it (sample
    L070_MP0_FS: DP mean 0.04 N over a trace at -1.06 N): each trace is drawn shifted by its
    mean's correction, the quantities without one as stored."""
    traces = _traces()
    run = replace(_run(traces), corrections={"dp_n": 1.1, "torque_nm": -0.25})
    maps = _maps(_svg(run))
    for key in TRACE_QUANTITIES:
        m = maps[key]
        path = m["panel"].find("path[@class='trace']")
        scale = float(re.fullmatch(r"scale\(([\d.]+)\)", path.get("transform")).group(1))
        drawn = np.concatenate(_path_points(path.get("d"), scale))
        shifted = (traces[key].values.astype(float) + run.corrections.get(key, 0.0)) * SCALE[key]
        expected = np.polyval(m["y"], shifted)
        inside = (expected > -m["height"]) & (expected < 2 * m["height"])
        assert np.abs(drawn[inside, 1] - expected[inside]).max() < 1.0


def test_window_shading_and_mean_line_sit_at_the_window_times_and_mean():
    run = _run(_traces(), window=(20.0, 45.0))
    maps = _maps(_svg(run))
    for key, m in maps.items():
        rect = m["panel"].find("rect[@class='window']")
        x0 = float(rect.get("x"))
        x1 = x0 + float(rect.get("width"))
        assert np.polyval(m["x"], 20.0) == pytest.approx(x0, abs=1.0)
        assert np.polyval(m["x"], 45.0) == pytest.approx(x1, abs=1.0)
        assert float(rect.get("height")) == pytest.approx(m["height"])
        mean = m["panel"].find("path[@class='mean']")
        xa, y, xb = (float(v) for v in re.fullmatch(r"M([-\d.]+) ([-\d.]+)H([-\d.]+)",
                                                      mean.get("d")).groups())
        assert (xa, xb) == pytest.approx((x0, x1), abs=0.01)
        assert y == pytest.approx(np.polyval(m["y"], run.means[key] * SCALE[key]), abs=1.0)
        assert mean.get("stroke-dasharray")


@pytest.mark.parametrize("seed", range(400))
def test_ticks_are_matplotlib_maxnlocator_ticks_where_it_uses_no_offset(seed):
    rng = np.random.default_rng(seed)
    span = 10.0 ** rng.uniform(-3, 3)  # values within 1e-5..1e6: no scientific notation
    lo = rng.uniform(-60, 60) * span
    hi = lo + span
    bins = int(rng.choice([4, 6]))
    mpl = MaxNLocator(bins).tick_values(lo, hi)
    mpl = mpl[(mpl >= lo - 1e-9 * span) & (mpl <= hi + 1e-9 * span)]
    ours = timeseries.nice_ticks(lo, hi, bins)
    np.testing.assert_allclose(ours, mpl, rtol=0, atol=1e-9 * span)
    # the labels: ScalarFormatter's on an axis showing [lo, hi], without offset
    ax = Figure().subplots()
    ax.set_ylim(lo, hi)
    formatter = ScalarFormatter(useOffset=False)
    ax.yaxis.set_major_formatter(formatter)
    assert timeseries.tick_labels(ours) == formatter.format_ticks(mpl)


def test_ticks_by_hand():
    # slip near 90 %: span 0.55 / 4 bins = 0.1375, next step 0.15: its multiples inside
    assert timeseries.nice_ticks(89.53, 90.08, 4) == pytest.approx([89.55, 89.70, 89.85, 90.0])
    assert timeseries.tick_labels(np.array([89.55, 89.70, 89.85, 90.0])) == [
        "89.55", "89.70", "89.85", "90.00"]
    # 0-60 s with margins, 6 bins: 66 / 6 = 11, next step 15
    assert timeseries.nice_ticks(-3.0, 63.0, 6) == pytest.approx([0, 15, 30, 45, 60])
    assert timeseries.tick_labels(np.array([0.0, 15.0, 30.0])) == ["0", "15", "30"]
    # -1.9..0.3 N: 2.2 / 4 = 0.55, next step 0.6
    assert timeseries.nice_ticks(-1.9, 0.3, 4) == pytest.approx([-1.8, -1.2, -0.6, 0.0])
    assert timeseries.tick_labels(np.array([-1.8, -1.2, -0.6, 0.0])) == [
        "−1.8", "−1.2", "−0.6", "0.0"]


def test_every_axis_has_its_unit_and_a_run_without_a_stable_phase_says_why():
    reason = ("no stable phase: drawbar pull rises to 90.5 N at 6.8 s, then collapses to "
              "20.3 N; sinkage grows from 7.3 to 36.6 mm: wheel digs in, no stable phase")
    root = _svg(_run(_traces(), status="no_stable_phase", window=None, flags=(reason,)))
    labels = [t.text for t in root.iter("text")
              if t.get("class") in ("ylabel", "xlabel")]
    assert len(labels) == 5 and all(UNIT.search(label) for label in labels)
    assert labels[-1] == "time [s]"
    title = root.find(".//g[@class='title']")
    assert title.get("fill") == timeseries.NOT_OK_COLOUR
    lines = [t.text for t in title.findall("text")]
    assert lines[0] == "L070_MP0_SC_s+020: speed_control, 70 N, multipass 0, slip set 20 %"
    assert " ".join(lines[1:]) == reason and len(lines) == 3
    legend = [t.text for t in root.findall(".//g[@class='legend']/text")]
    assert legend == ["stored trace"]  # no window, no mean
    assert root.find(".//rect[@class='window']") is None
    # the panels start lower, under the three title lines
    first = next(p for p in root.iter("svg")
                 if p.get("class") == "axes")
    assert float(first.get("y")) > 3 * 1.2 * timeseries.FONT_PX


def test_an_ok_run_has_a_black_one_line_title_and_the_three_legend_entries():
    root = _svg(_run(_traces()))
    title = root.find(".//g[@class='title']")
    assert title.get("fill") == "#000000" and len(title.findall("text")) == 1
    legend = [t.text for t in root.findall(".//g[@class='legend']/text")]
    assert legend == ["stable window", "mean over window", "stored trace"]


def test_a_run_processed_before_traces_were_stored_says_so_and_shows_its_dp_trace():
    dp = {"t_s": [0.0, 1.0, 2.0, 3.0], "dp_n": [1.0, None, 3.0, 4.0]}
    root = _svg(_run(None, status="no_stable_phase", window=None, dp_trace=dp,
                     flags=("no stable phase",)))
    maps = _maps(root)
    notes = [t.text for t in root.iter("text")
             if t.get("class") == "note"]
    assert notes == [timeseries.NOT_STORED] * 4
    path = maps["dp_n"]["panel"].find("path[@class='trace']")
    parts = _path_points(path.get("d"), 0.1)
    assert [len(p) for p in parts] == [1, 2]  # the missing value splits the line
    drawn = np.concatenate(parts)
    m = maps["dp_n"]
    assert np.abs(drawn[:, 1] - np.polyval(m["y"], [1.0, 3.0, 4.0])).max() < 1.0
    assert np.abs(drawn[:, 0] - np.polyval(m["x"], [0.0, 2.0, 3.0])).max() < 1.0
    legend = [t.text for t in root.findall(".//g[@class='legend']/text")]
    assert legend == ["stored DP trace"]
    assert all(maps[k]["panel"].find("path[@class='trace']") is None
               for k in TRACE_QUANTITIES[1:])


def test_text_from_the_database_is_escaped():
    root = _svg(_run(_traces(), run_id='run <"&$x$'))
    lines = [t.text for t in root.findall(".//g[@class='title']/text")]
    assert lines[0].startswith('run <"&$x$: ')


@pytest.mark.parametrize("values", [np.full(50, 3.0), np.full(50, np.nan), np.array([2.0]),
                                    np.array([np.nan, 1.0, np.nan, 2.0])])
def test_degenerate_traces_give_a_well_formed_drawing_with_labelled_axes(values):
    t = np.linspace(0.0, 10.0, values.size) if values.size > 1 else np.array([5.0])
    traces = {k: Trace(t_s=t, values=values.astype(np.float32), unit="", samples=values.size,
                       block=1) for k in TRACE_QUANTITIES}
    root = _svg(_run(traces, window=(5.0, 5.0)))
    for key in TRACE_QUANTITIES:
        labels = root.find(f".//g[@class='yticks'][@data-quantity='{key}']")
        values_shown = [_number(t.text) for t in labels.findall("text")]
        assert len(values_shown) >= 1 and all(np.isfinite(values_shown))
    assert len(root.findall(".//g[@class='xticks']/text")) >= 2
