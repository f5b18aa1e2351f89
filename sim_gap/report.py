"""The gap report as JSON (schema in docs/gap-report.md). Its page (``swtlab gap --html``)
and its section of the campaign report are drawn by :mod:`campaign_report.gap`."""

from __future__ import annotations

import json
from pathlib import Path

from swtlab_base.plain_json import jsonable
from swtlab_base.atomic import write_atomically

SCHEMA = "swtlab.gap-report/2"
#: the schemas :mod:`campaign_report.gap` still reads
READABLE_SCHEMAS = ("swtlab.gap-report/1", SCHEMA)


def build_report(diagnosis: dict, measured_source: str, sim_source: str,
                 settings: dict | None = None) -> dict:
    """The report dict: the verdict and its probabilities first, then the details."""
    shrink = diagnosis["shrink"]
    decision = diagnosis["decision"]
    out = {
        "schema": SCHEMA, "measured": measured_source, "simulated": sim_source,
        "verdict": diagnosis["verdict"],
        "probability": decision["probability"],
        "call_probability": decision["call_probability"],
        "learning_rate": decision["learning_rate"],
        "reason": decision["reason"],
        "separating_test": decision.get("separating_test"),
        "next_tests": decision.get("next_tests") or [],
        "admissible_tests": decision.get("admissible_tests") or [],
        "chosen": decision["chosen"],
        "leaders": decision["leaders"],
        "leaders_separation_sigma": decision["leaders_separation_sigma"],
        "effect_sets": diagnosis["effect_sets"],
        "effect_probabilities": diagnosis["effect_probabilities"],
        "hypotheses": diagnosis["hypotheses"],
        "sibling_contrasts": diagnosis["sibling_contrasts"],
        "noise": diagnosis["noise"],
        **({"base_model": diagnosis["base_model"]} if diagnosis["base_model"] else {}),
        "points": diagnosis["points"],
        "held_out_rmse_before": shrink["held_out_rmse_before"],
        "held_out_rmse_after": shrink["held_out_rmse_after"],
        "shrink_pct": shrink["shrink_pct"],
        "shrink": {"per_quantity": shrink["per_quantity"],
                   "per_slip_band": shrink["per_slip_band"], "n_boot": shrink["n_boot"]},
        "regions": diagnosis["regions"],
        "untestable_effects": diagnosis["untestable_effects"],
        "contrasts": diagnosis["contrasts"], "folds": diagnosis["folds"],
        "n_points": diagnosis["n_points"], "quantities": diagnosis["quantities"],
        "sinkage_relative": diagnosis["sinkage_relative"],
        "settings": settings or {},
    }
    return jsonable(out)


def write_json(report: dict, path: str | Path) -> None:
    write_atomically(path, json.dumps(report, indent=1, allow_nan=False) + "\n")
