"""The page's built-in sections, from a campaign's gathered data and its rendered figures."""

from __future__ import annotations

from collections import Counter
from collections.abc import Iterable
from dataclasses import replace
from html import escape

from campaign_report import figures, timeseries
from campaign_report.data import CampaignData, RunRecord
from campaign_report.html import Drawing, Heading, Image, Note, Section, Table
from campaign_report.images import to_png
from campaign_report.style import CURVE_QUANTITIES, QUANTITIES, Palette
from run_results.traces import MAX_TRACE_POINTS
from swtlab_base.rounding import plain, value_and_u
from swtlab_base.domain.results import not_measured_heads
from wpm_export import WheelPerformanceModule

RUNS = "runs"
TIMESERIES = "timeseries"
CURVES = "curves"
INTERPOLATION = "interpolation"
WPM = "wpm"


def run_anchor(index: int) -> str:
    """Anchor of a run's time-series thumbnail (run ids may hold characters a slug would merge)."""
    return f"run-{index}"


def _number(value: float | None, scale: float = 1.0, digits: int = 4) -> str:
    return "" if value is None else plain(value * scale, digits)


#: the run table's quantities: (key, short name, unit, display scale, digits of the mean)
TABLE_QUANTITIES = (("slip", "slip", "%", 100.0, 3), ("dp_n", "DP", "N", 1.0, 4),
                    ("torque_nm", "torque", "N·m", 1.0, 4),
                    ("sinkage_m", "sinkage", "mm", 1000.0, 3))


def _mean_and_u(run: RunRecord, key: str, scale: float, digits: int) -> list[str]:
    """A quantity's mean and its combined standard uncertainty, u to two significant digits
    and the mean to the same decimal (``swtlab_base.rounding``); without a budget the mean to
    ``digits`` significant digits and u empty."""
    mean, u = run.means.get(key), run.u.get(key)
    if u is None:
        return [_number(mean, scale, digits), ""]
    return list(value_and_u(mean, u, scale))


def _window(run: RunRecord) -> str:
    if run.window_start_s is None or run.window_end_s is None:
        return "none"
    return f"{run.window_start_s:.1f}-{run.window_end_s:.1f}"


def not_measured_note(data: CampaignData) -> str:
    """What the runs' budgets could not measure, so u( ) leaves it out, with how many runs
    (the ``not_measured`` column of ``swtlab results``); empty when nothing is missing."""
    column = data.results.get("not_measured")
    if column is None:
        return ""
    counts = Counter(head for cell in column for head in not_measured_heads(cell))
    if not counts:
        return ""
    items = ", ".join(f"{head} ({n} of {len(data.results)} runs)"
                      for head, n in sorted(counts.items()))
    return (f"Not measured, so not in u( ): {items}. The budgets hold what these runs "
            "could measure; swtlab results --json gives each run's not_measured in full.")


def runs_section(data: CampaignData) -> Section:
    """Every run: conditions, status, stable window, main means, flags and reasons."""
    header = ["run", "mode", "load [N]", "multipass", "slip set [%]", "velocity [mm/s]",
              "status", "stable window [s]",
              *(h for _, name, unit, _, _ in TABLE_QUANTITIES
                for h in (f"{name} [{unit}]", f"u({name}) [{unit}]"))]
    rows, classes, notes = [], [], []
    for i, run in enumerate(data.runs):
        rows.append([
            f'<a href="#full-{run_anchor(i)}">{escape(run.run_id)}</a>', run.mode,
            f"{run.load_n:g}", str(run.multipass), _number(run.slip_setpoint, 100.0, 3),
            _number(run.velocity_mps, 1000.0, 3),
            f'<span class="status {escape(run.status)}">{escape(run.status)}</span>', _window(run),
            *(cell for key, _, _, scale, digits in TABLE_QUANTITIES
              for cell in _mean_and_u(run, key, scale, digits))])
        classes.append(run.status)
        notes.append("; ".join(run.flags))
    for run_id, stage, reason in data.failed:
        rows.append([escape(run_id), "", "", "", "", "", '<span class="status failed">failed'
                     '</span>', "none", *[""] * (2 * len(TABLE_QUANTITIES))])
        classes.append("failed")
        notes.append(f"{stage} failed: {reason}")
    counts = {s: sum(r.status == s for r in data.runs) for s in ("ok", "flagged",
                                                                   "no_stable_phase")}
    summary = (f"{len(data.runs) + len(data.failed)} runs: {counts['ok']} ok, "
               f"{counts['flagged']} flagged (a check failed; kept out of the fits), "
               f"{counts['no_stable_phase']} without a stable phase"
               + (f", {len(data.failed)} failed (could not be processed; the reason says why)"
                  if data.failed else "")
               + ". Means over the stable window and u( ), their combined standard uncertainty "
                 "(the run's uncertainty budget: within-window statistics, zero drift, "
                 "calibration, quantisation, phase sampling, clock; GUM, docs/run-results.md); "
                 "their 95 % expanded uncertainty is k·u with k about 2 (swtlab results lists "
                 "k, u95 and every term). Each u has two significant digits and its mean the "
                 "same decimal (GUM 7.2.6). A run's flags and reasons are under its row. A run "
                 "id opens its time series.")
    numeric = frozenset({2, 3, 4, 5, *range(8, 8 + 2 * len(TABLE_QUANTITIES))})
    heads = [Note(summary)] + ([Note(missing)] if (missing := not_measured_note(data)) else [])
    return Section(RUNS, "Runs", [*heads, Table(
        header, rows, numeric=numeric, row_classes=classes, html_columns=frozenset({0, 6}),
        row_notes=notes)])


def timeseries_image(index: int, run: RunRecord, palette: Palette) -> Drawing:
    """A run's time series (:func:`timeseries.timeseries_svg`), shown as a thumbnail that
    opens full size; the caption says so when the run was processed before its traces were
    stored."""
    anchor = run_anchor(index)
    caption = (f"{run.run_id} · {run.status}"
               + (f" · {timeseries.NOT_STORED}" if run.traces is None else ""))
    drawing = Drawing(anchor, caption, "", timeseries.WIDTH_PX, timeseries.HEIGHT_PX,
                      run.status)
    return replace(drawing, svg=timeseries.timeseries_svg(run, palette, drawing.drawing_id))


def timeseries_section(images: Iterable[Image | Drawing]) -> Section:
    return Section(TIMESERIES, "Time series per run", [Note(
        "Drawbar pull, torque, sinkage and slip as stored by processing (each channel's "
        f"minimum and maximum per block of samples, at most {MAX_TRACE_POINTS} points: the "
        "envelope of the full signal); the stable window shaded, the dashed line its mean. "
        "Runs with no stable phase give the reason in the title. Click a thumbnail for full "
        "size."),
        *images])


def _source_notes(data: CampaignData) -> list[Note]:
    src = data.source
    statuses = ", ".join(src.statuses)
    if src.exported:
        when = src.created_at.strftime("%Y-%m-%d %H:%M UTC") if src.created_at else "?"
        notes = [Note(f"Curves of the newest WPM export {src.export_path} (sha256 "
                      f"{src.file_sha256[:12]}, {when}), degree {src.degree}, fitted from runs "
                      f"with status {statuses}.")]
        if src.stale:
            notes.append(Note("The export was fitted from older results than the newest "
                              "ones: run swtlab export again to bring it up to date.",
                              warning=True))
    else:
        notes = [Note(f"No WPM export of this campaign in the database: curves fitted here "
                      f"(degree {src.degree}, runs with status {statuses}); swtlab export "
                      "writes and records them.")]
    for (wheel, soil, mp), load, slips in data.unfitted_groups():
        notes.append(Note(f"{wheel} on {soil}, multipass {mp}, {load:g} N: {slips} distinct "
                          "slips, no curve (too few to fit); shown as points."))
    return notes


def _errorbar_note(fig) -> list[Note]:
    """The note under a drawn slip figure whose error bars hide behind their markers."""
    text = figures.hidden_errorbars(fig, CURVE_QUANTITIES)
    return [] if text is None else [Note(text)]


def curves_section(data: CampaignData, palette: Palette) -> Section:
    """DP, torque, sinkage and resistance against slip per wheel and soil."""
    blocks: list = _source_notes(data)
    for wheel, soil in sorted({(w, s) for w, s, _ in data.sets()}):
        fig = figures.performance_curves(data.points, data.fits, wheel, soil,
                                         data.source.statuses, palette)
        blocks.append(Image(f"curves-{len(blocks)}", f"{wheel} on {soil}: performance curves",
                            to_png(fig)[0]))
        blocks += _errorbar_note(fig)
        blocks.append(Note(figures.band_text(
            [f for f in data.fits if (f.wheel, f.soil) == (wheel, soil)], CURVE_QUANTITIES)))
    return Section(CURVES, "Performance curves", blocks)


def _inside_band(check) -> str:
    """``k of n`` runs in the slip range inside the interpolated prediction band."""
    n = check.n_points - check.n_outside_slip_range
    if check.fraction_inside_band != check.fraction_inside_band:  # NaN: no band
        return "unknown (no band)"
    return f"{check.n_inside_band} of {n}"


def interpolation_section(data: CampaignData, palette: Palette) -> Section | None:
    """Curves interpolated to a load kept aside, against that load's runs; None without one."""
    if not data.validation:
        return None
    blocks: list = [Note("Runs at a load with too few slips for a curve of its own, between "
                         "tested loads, check the load interpolation (RUAG WPAT's 120 N "
                         "check): the curves at the other loads are interpolated to it, with "
                         "the 95 % bands propagated through the interpolation; the table "
                         "counts the runs inside its prediction band.")]
    for key, (load, checks) in data.validation.items():
        blocks.append(Heading(f"{key[0]} on {key[1]}, multipass {key[2]}: {load:g} N"))
        fig = figures.load_validation(data.points, data.fits, key, load, checks, palette)
        blocks.append(Image(f"interp-{len(blocks)}", f"interpolated to {load:g} N",
                            to_png(fig)[0]))
        blocks += _errorbar_note(fig)
        rows = [[(q := QUANTITIES[c.quantity]).label, f"{c.rmse * q.scale:.3g} {q.unit}",
                 f"{c.rmse_pct_of_range:.2g}", str(c.n_points), str(c.n_outside_slip_range),
                 _inside_band(c)] for c in checks]
        blocks.append(Table(["quantity", "RMSE", "% of measured range", "runs",
                             "beyond the tested slips (not in RMSE)",
                             "inside the 95 % prediction band"], rows,
                            numeric=frozenset({1, 2, 3, 4, 5})))
    return Section(INTERPOLATION, "Load interpolation check", blocks)


def wpm_section(data: CampaignData, palette: Palette) -> Section | None:
    """The exported WPM curves as the WPM runtime evaluates them; None without an export."""
    if not data.source.exported:
        return None
    wpm = WheelPerformanceModule(data.fits, source=data.source.export_path)
    blocks: list = [Note(f"{data.source.export_path}: every curve set as a simulator reads it "
                         "(swtlab wpm query), at the tested loads and half-way between.")]
    for wheel, soil, mp in data.sets():
        tested: dict[str, list[float]] = {}
        for f in data.fits:
            if (f.wheel, f.soil, f.multipass) == (wheel, soil, mp):
                tested.setdefault(f.quantity, []).append(f.load_n)
        fig = figures.wpm_curves(wpm, tested, soil, wheel, mp, palette)
        blocks.append(Image(f"wpm-{len(blocks)}", f"WPM curves, {wheel} on {soil}, "
                            f"multipass {mp}", to_png(fig)[0]))
    return Section(WPM, "WPM curves as exported", blocks)
