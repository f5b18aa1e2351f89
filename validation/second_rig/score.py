"""Score the chain's stored means against the second rig's truth files.

Input: the rows of ``swtlab results --json`` (one per run) and the truth folder. For each run
and quantity: ``error = mean - truth`` (truth: the noise-free window means), ``z = error/SE``
and whether ``mean +- 1.96 SE`` covers the truth; also ``z`` after taking out the run's true
load-cell drift over the window and gain error (``z_instrument_out``; diagnostic only: it
reads the truth, no estimator can), which leaves the estimators' own errors (window, SE).
"""

from __future__ import annotations

import json
from collections.abc import Iterable, Mapping
from pathlib import Path

import pandas as pd

QUANTITIES = ("slip", "travel_velocity_mps", "wheel_omega_radps", "wheel_load_n", "dp_n",
              "torque_nm", "thrust_n", "resistance_n", "sinkage_m")
#: the load cell whose drift enters each quantity (R = T/r - DP: both, see ``_drift``)
DRIFT_SOURCE = {"wheel_load_n": "/hub/wrench.fz", "dp_n": "/tether/force.dp",
                "torque_nm": "/hub/wrench.ty"}


def _instrument_error(quantity: str, truth: Mapping) -> float:
    """The true drift (window mean) plus gain error of the cells behind ``quantity``."""
    meas, means = truth["measurement"], truth["window_means"]
    radius_m = truth["condition"]["wheel"]["radius_m"]

    def cell(key: str, value: float) -> float:
        return meas["drift_window_mean"][key] + meas["gain_error_rel"][key] * value

    if quantity in DRIFT_SOURCE:
        return cell(DRIFT_SOURCE[quantity], means[quantity])
    thrust = cell("/hub/wrench.ty", means["torque_nm"]) / radius_m
    dp = cell("/tether/force.dp", means["dp_n"])
    return {"thrust_n": thrust, "resistance_n": thrust - dp}.get(quantity, 0.0)


def score(rows: Iterable[Mapping], truth_dir: str | Path) -> pd.DataFrame:
    """One row per (run, quantity) with a stored mean: mean, se, truth, error, z, covered,
    z_instrument_out; free-sled DP and R are left out (the DP cell has no tether)."""
    out = []
    for row in rows:
        truth = json.loads((Path(truth_dir) / f"{row['run_id']}.json").read_text())
        for q in QUANTITIES:
            mean, se = row.get(f"{q}_mean"), row.get(f"{q}_se")
            if mean is None or se is None or (row["mode"] == "free_sled"
                                              and q in ("dp_n", "resistance_n")):
                continue
            true = truth["window_means"][q]
            error = mean - true
            out.append({"run_id": row["run_id"], "mode": row["mode"], "quantity": q,
                        "mean": mean, "se": se, "truth": true, "error": error,
                        "z": error / se if se > 0 else float("inf"),
                        "covered": abs(error) <= 1.96 * se,
                        "z_instrument_out": (error - _instrument_error(q, truth)) / se
                        if se > 0 else float("inf")})
    return pd.DataFrame(out)


def coverage(scores: pd.DataFrame) -> pd.DataFrame:
    """Per quantity: runs, coverage of ``mean +- 1.96 SE``, median and spread of z, the same
    coverage with the true drift and gain errors taken out, and the median |error|."""
    def summary(g: pd.DataFrame) -> pd.Series:
        return pd.Series({"runs": len(g), "coverage": g["covered"].mean(),
                          "z_median": g["z"].median(), "z_std": g["z"].std(),
                          "coverage_instrument_out": (g["z_instrument_out"].abs() <= 1.96).mean(),
                          "abs_error_median": g["error"].abs().median()})
    return scores.groupby("quantity", sort=False)[list(scores.columns)].apply(summary)
