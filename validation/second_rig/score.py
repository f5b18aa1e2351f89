"""Score the chain's stored means against the second rig's truth files.

Input: the rows of ``swtlab results --json`` (one per run) and the truth folder. For each run
and quantity: ``error = mean - truth``, ``z = error/SE``
and whether ``mean +- 1.96 SE`` covers the truth, and whether the budget's ``mean +- u95``
does (``covered_u95``, where the rows carry ``<q>_u95``); also ``z`` after taking out what the
instruments alone add (load-cell drift over the window, gain and offset errors, encoder clock
rates: ``z_instrument_out``; diagnostic only: it reads the truth, no estimator can), which
leaves the estimators' own errors (window, transient, SE, quantisation).

The truth (``target``) is by default the ``steady`` values (the caller's law, what a stable
phase estimates); ``window_means`` (the noise-free signals over the rig's truth window) also
carry that window's share of the drives' speed ripple, which the chain's window, another
stretch of the run, does not share, and the two windows overlap, so they flatter or blur
the speeds' coverage; the grouser wave averages out over both (whole periods).
"""

from __future__ import annotations

import json
from collections.abc import Iterable, Mapping
from pathlib import Path

import pandas as pd

QUANTITIES = ("slip", "travel_velocity_mps", "wheel_omega_radps", "wheel_load_n", "dp_n",
              "torque_nm", "thrust_n", "resistance_n", "sinkage_m")
#: the load cell behind each single-cell quantity
CELL_OF = {"wheel_load_n": "/hub/wrench.fz", "dp_n": "/tether/force.dp",
           "torque_nm": "/hub/wrench.ty"}


def _instrument_error(quantity: str, truth: Mapping, target: str) -> float:
    """What the instruments alone add to ``quantity``'s window mean: drift (window mean),
    gain error and DP offset error of the load cells, the encoders' clock rate errors
    (a clock fast by p reads rates low by p), and a flexible wheel's deflection error."""
    meas, means = truth["measurement"], truth[target]
    wheel = truth["condition"]["wheel"]

    def cell(key: str, value: float) -> float:
        offset = meas["dp_offset_error_n"] if key == "/tether/force.dp" else 0.0
        return meas["drift_window_mean"][key] + meas["gain_error_rel"][key] * value + offset

    if quantity in CELL_OF:
        return cell(CELL_OF[quantity], means[quantity])
    thrust = cell("/hub/wrench.ty", means["torque_nm"]) / wheel["radius_m"]
    if quantity in ("thrust_n", "resistance_n"):
        return thrust - (cell("/tether/force.dp", means["dp_n"]) if quantity == "resistance_n"
                         else 0.0)
    if quantity == "sinkage_m":
        k = wheel["stiffness_n_per_mm"]
        return 0.0 if k is None else -cell(CELL_OF["wheel_load_n"],
                                           means["wheel_load_n"]) / (1000 * k)
    ppm = {t: c["rate_error_ppm"] * 1e-6 for t, c in meas["clocks"].items()}
    v = means["travel_velocity_mps"] / (1 + ppm["/sled/encoder"])
    omega = means["wheel_omega_radps"] / (1 + ppm["/wheel/encoder"])
    if quantity == "travel_velocity_mps":
        return v - means["travel_velocity_mps"]
    if quantity == "wheel_omega_radps":
        return omega - means["wheel_omega_radps"]
    surface = wheel["radius_m"] * omega
    slip = (surface - v) / (surface if surface >= v else v)
    return slip - means["slip"]


def score(rows: Iterable[Mapping], truth_dir: str | Path, target: str = "steady") -> pd.DataFrame:
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
            true = truth[target][q]
            error = mean - true
            u95 = row.get(f"{q}_u95")
            out.append({"run_id": row["run_id"], "mode": row["mode"], "quantity": q,
                        "mean": mean, "se": se, "truth": true, "error": error,
                        "z": error / se if se > 0 else float("inf"),
                        "covered": abs(error) <= 1.96 * se,
                        "covered_u95": None if u95 is None else abs(error) <= u95,
                        "z_instrument_out": (error - _instrument_error(q, truth, target)) / se
                        if se > 0 else float("inf")})
    return pd.DataFrame(out)


def coverage(scores: pd.DataFrame) -> pd.DataFrame:
    """Per quantity: runs, coverage of ``mean +- 1.96 SE``, of ``mean +- u95`` (the budget),
    median and spread of z, the same coverage with the instruments' errors taken out, and the
    median |error|."""
    def summary(g: pd.DataFrame) -> pd.Series:
        return pd.Series({"runs": len(g), "coverage": g["covered"].mean(),
                          "coverage_u95": g["covered_u95"].dropna().astype(float).mean(),
                          "z_median": g["z"].median(), "z_std": g["z"].std(),
                          "coverage_instrument_out": (g["z_instrument_out"].abs() <= 1.96).mean(),
                          "abs_error_median": g["error"].abs().median()})
    return scores.groupby("quantity", sort=False)[list(scores.columns)].apply(summary)
