"""The 120 N check on the committed sample campaign, from the runs' true stable-phase means
(sample_data/truth, tests only): what the processed campaign should give once its results
are recovered exactly. The lead adds the same check on the processed results."""

from __future__ import annotations

import json
from pathlib import Path

import pandas as pd
import pytest

from fitting import validate_load_interpolation
from test_fitting_synthetic import run_se

TRUTH = Path(__file__).parents[1] / "sample_data" / "truth"
QUANTITIES = {"dp_n": "dp_n", "torque_nm": "torque_nm", "sinkage_m": "sinkage_m",
              "resistance_n": "motion_resistance_n"}


def truth_results_table() -> pd.DataFrame:
    """One row per sample run with a stable phase: its true stable means, SEs of run_se."""
    rows = []
    for path in sorted(TRUTH.glob("*.json")):
        truth = json.loads(path.read_text())
        means, condition = truth["stable_means"], truth["condition"]
        if means is None or condition["mode"] == "steered":  # dig-in; not a curve point
            continue
        se = run_se(condition["load_n"])
        rows.append({"wheel": "bb2", "soil": "es3", "multipass": condition["multipass"],
                     "load_n": condition["load_n"], "slip": means["slip"],
                     "wheel_load_n": means["wheel_load_n"],
                     **{q: means[key] for q, key in QUANTITIES.items()},
                     **{f"{q}_se": se[q] for q in QUANTITIES}})
    return pd.DataFrame(rows)


def test_sample_campaign_120n_validation_from_true_stable_means():
    table = truth_results_table()
    assert len(table) == 56  # 60 runs, 3 dig-in, 1 steered
    results = {r.quantity: r for r in validate_load_interpolation(table, 120.0)}
    dp = results["dp_n"]
    assert (dp.multipass, dp.n_points, dp.n_outside_slip_range) == (0, 5, 1)
    # docs/fitting.md's number (python -m bench fitting_validation); the goal: < 3 %
    assert dp.rmse_pct_of_range == pytest.approx(0.91, abs=0.02)
    # Bounds as before at about 1.3-2x the measured numbers. With the truth's braked branch
    # (Wong & Reece part II) fitted, sinkage (0.62 %), resistance (0.70 %) and DP/W (0.36 %)
    # are tighter than before (1.70, 2.04, 0.47 %: bounds 2.0, 2.5, 1.0 -> 1.0, 1.0, 1.0).
    # Torque is looser (0.47 % -> 1.86 %, bound 1.0 -> 2.5 %, still under the 3 % goal): at
    # 180 N LOO's one-standard-error rule takes the quartic without a branch (5 parameters,
    # LOO 0.80 N*m) over the cubic with step and slope (6, LOO 0.63 N*m) -- the choice, not
    # the representation (the cubic with J and K gives 0.44 %).
    assert results["torque_nm"].rmse_pct_of_range < 2.5
    assert results["dp_over_w"].rmse_pct_of_range < 1.0
    assert results["sinkage_m"].rmse_pct_of_range < 1.0
    assert results["resistance_n"].rmse_pct_of_range < 1.0
