"""The gap report: JSON (schema in docs/gap-report.md) and a self-contained HTML page with
the residual heatmap embedded."""

from __future__ import annotations

import base64
import html
import json
from pathlib import Path

from plain_json import jsonable

SCHEMA = "swtlab.gap-report/1"
REGION_HEAD = ["slip band", "load N", "multipass", "gravity", "quantity", "mean residual",
               "per load", "z"]


def build_report(diagnosis: dict, measured_source: str, sim_source: str,
                 settings: dict | None = None) -> dict:
    """The report dict: the issue's required keys first, then the details."""
    shrink = diagnosis["shrink"]
    out = {
        "schema": SCHEMA, "measured": measured_source, "simulated": sim_source,
        "verdict": diagnosis["verdict"],
        "reason": diagnosis["decision"]["reason"],
        "separating_test": diagnosis["decision"].get("separating_test"),
        "chosen": diagnosis["decision"]["chosen"],
        "candidates": [{k: c[k] for k in ("label", "effects", "held_out_score", "held_out_loss",
                                          "z_vs_best", "n_params", "aicc", "parameters",
                                          "fold_parameters", "held_out_run_losses")}
                       for c in diagnosis["candidates"]],
        "held_out_rmse_before": shrink["held_out_rmse_before"],
        "held_out_rmse_after": shrink["held_out_rmse_after"],
        "shrink_pct": shrink["shrink_pct"],
        "shrink": {"per_quantity": shrink["per_quantity"],
                   "per_slip_band": shrink["per_slip_band"], "n_boot": shrink["n_boot"]},
        "regions": diagnosis["regions"],
        "decision": {k: v for k, v in diagnosis["decision"].items()
                     if k not in ("verdict", "reason", "separating_test")},
        "untestable_effects": diagnosis["untestable_effects"],
        "contrasts": diagnosis["contrasts"], "folds": diagnosis["folds"],
        "n_points": diagnosis["n_points"], "quantities": diagnosis["quantities"],
        "sinkage_relative": diagnosis["sinkage_relative"],
        "settings": settings or {},
    }
    return jsonable(out)


def write_json(report: dict, path: str | Path) -> None:
    Path(path).write_text(json.dumps(report, indent=1, allow_nan=False) + "\n")


def _table(rows: list[list], head: list[str]) -> str:
    cells = lambda r, t: "".join(f"<{t}>{html.escape(str(v))}</{t}>" for v in r)  # noqa: E731
    return ("<table><tr>" + cells(head, "th") + "</tr>"
            + "".join("<tr>" + cells(r, "td") + "</tr>" for r in rows) + "</table>")


def _fmt(v) -> str:
    return "n/a" if v is None else f"{v:.4g}" if isinstance(v, float) else str(v)


def _wheel_text(wheel: dict | None) -> str:
    if not wheel:
        return "n/a"
    w = wheel["simulated"]
    text = (f"r = {w['radius_m']:g} m, b = {w['width_m']:g} m, {w['grouser_count']} grousers "
            f"of {w['grouser_height_m']:g} m")
    if wheel["mismatches"]:
        return text + " (simulated); MISMATCH allowed: " + "; ".join(wheel["mismatches"])
    return text + " (measured and simulated agree)"


def render_html(report: dict, heatmap_png: bytes | None) -> str:
    """One HTML page, no external resources."""
    verdict = report["verdict"]
    verdict_text = verdict if isinstance(verdict, str) else (", ".join(verdict) or
                                                             "none (no missing effect)")
    cand_rows = [[c["label"], _fmt(c["held_out_score"]), _fmt(c["z_vs_best"]), c["n_params"],
                  _fmt(c["aicc"]), ", ".join(f"{k}={v:.4g}" for k, v in c["parameters"].items())]
                 for c in report["candidates"]]
    pq = report["shrink"]["per_quantity"]
    shrink_rows = [[q, _fmt(v["before"]), _fmt(v["after"]), _fmt(v["shrink_pct"]),
                    f"[{_fmt(v['shrink_pct_ci95'][0])}, {_fmt(v['shrink_pct_ci95'][1])}]"]
                   for q, v in pq.items()]
    sig = [r for r in report["regions"] if r.get("significant")]
    region_rows = [[r["slip_band"], r["load_n"], r["multipass"], r["gravity_mps2"], r["quantity"],
                    _fmt(r["mean_residual"]), _fmt(r["mean_residual_per_load"]), _fmt(r["z"])]
                   for r in sig]
    img = ("" if heatmap_png is None else
           f'<img alt="residual heatmap" src="data:image/png;base64,'
           f'{base64.b64encode(heatmap_png).decode()}">')
    test = report.get("separating_test") or {}
    return f"""<!doctype html><html><head><meta charset="utf-8"><title>swtlab gap report</title>
<style>body{{font-family:sans-serif;margin:2em}}table{{border-collapse:collapse}}
td,th{{border:1px solid #ccc;padding:2px 6px;font-size:90%}}</style></head><body>
<h1>Sim-to-real gap</h1>
<p>Measured: {html.escape(str(report['measured']))}<br>
Simulated: {html.escape(str(report['simulated']))}<br>
Wheel: {html.escape(_wheel_text(report.get('wheel')))}</p>
<h2>Verdict: {html.escape(verdict_text)}</h2><p>{html.escape(report['reason'])}</p>
{f"<p>Test that would decide: {html.escape(str(test.get('test')))} (leaders differ by "
 f"{test.get('separation_sigma')} sigma there)</p>" if test.get('test') else ""}
<p>Untestable here: {html.escape(json.dumps(report['untestable_effects']))}</p>
<h2>Where: residual map (measured - simulated as given)</h2>{img}
<p>{len(sig)} of {len(report['regions'])} region-quantity cells significant
(chi-square, Benjamini-Hochberg 5 %).</p>
{_table(region_rows, REGION_HEAD)}
<h2>Which: candidates ranked by held-out score</h2>
{_table(cand_rows, ['candidate', 'held-out RMS (sigma)', 'z vs best', 'params', 'AICc', 'fitted'])}
<h2>How far: held-out RMSE, soil-only recalibration vs {html.escape(report['chosen'])}</h2>
{_table(shrink_rows, ['quantity', 'before', 'after', 'shrink %', '95 % CI'])}
</body></html>
"""


def write_html(report: dict, path: str | Path, heatmap_png: bytes | None) -> None:
    Path(path).write_text(render_html(report, heatmap_png))
