"""The gap report as JSON (schema in docs/gap-report.md). Its page (``swtlab gap --html``)
and its section of the campaign report are drawn by :mod:`campaign_report.gap`."""

from __future__ import annotations

import json
from pathlib import Path

from plain_json import jsonable
from swtlab.atomic import write_atomically

SCHEMA = "swtlab.gap-report/1"


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
        "candidates": [{k: c[k] for k in ("label", "effects", "laws", "held_out_score",
                                          "held_out_loss", "z_vs_best", "n_params", "aicc",
                                          "parameters", "fold_parameters",
                                          "held_out_run_losses")}
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
    write_atomically(path, json.dumps(report, indent=1, allow_nan=False) + "\n")
