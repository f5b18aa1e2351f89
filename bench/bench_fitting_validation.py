"""The 120 N load-interpolation check of docs/fitting.md (RUAG WPAT's validation): curves fitted
at 70/180/300 N, interpolated to 120 N, against the 120 N runs, as % of the measured range.

On the terramechanics model ``bb2_sand`` with the synthetic tables of
tests/test_fitting_synthetic.py (noise-free, and 20 noisy draws: seeds 1-20), and on the
sample campaign's true stable-phase means (tests/test_fitting_sample_truth.py). Both tables
are made by the tests' own helpers (one definition), hence the tests folder on the path.
"""

from __future__ import annotations

import sys
import warnings
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).parents[1] / "tests"))

from fitting import fit_results, validate_load_interpolation
from test_fitting_sample_truth import truth_results_table
from test_fitting_synthetic import model_results_table, sample_like_table

QUANTITIES = ("dp_n", "torque_nm", "sinkage_m", "resistance_n", "dp_over_w")


def _check(table, multipass: int = 0, **options) -> dict:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return {r.quantity: r for r in validate_load_interpolation(table, 120.0, **options)
                if r.multipass == multipass}


def main(quick: bool = False) -> dict:
    draws = range(1, 6 if quick else 21)
    exact = _check(sample_like_table(None))
    noisy = [_check(sample_like_table(seed)) for seed in draws]
    truth = _check(truth_results_table())
    fits = fit_results(sample_like_table(None).query("load_n != 120"))
    out = {}
    print(f"{'quantity':14s} {'no noise: RMSE':>16s} {'%':>6s} {'noisy mean':>11s} "
          f"{'(worst)':>8s} {'incl. 75 %':>10s} {'sample truth %':>15s}")
    for q in QUANTITIES:
        pct = np.array([r[q].rmse_pct_of_range for r in noisy])
        with_75 = np.mean([100 * r[q].rmse_all / r[q].measured_range for r in noisy])
        out[q] = {"noise_free_rmse": exact[q].rmse, "noise_free_pct": exact[q].rmse_pct_of_range,
                  "noisy_mean_pct": float(pct.mean()), "noisy_worst_pct": float(pct.max()),
                  "noisy_mean_pct_incl_75": float(with_75),
                  "sample_truth_pct": truth[q].rmse_pct_of_range,
                  "sample_truth_pct_incl_75": 100 * truth[q].rmse_all / truth[q].measured_range}
        print(f"{q:14s} {exact[q].rmse:16.4g} {exact[q].rmse_pct_of_range:6.2f} "
              f"{pct.mean():11.2f} {pct.max():8.2f} {with_75:10.2f} "
              f"{truth[q].rmse_pct_of_range:15.2f}")
    out["choices_noise_free"] = sorted(f"{f.quantity}@{f.load_n:g}: {_choice(f)}" for f in fits)
    print("noise-free choices:", "; ".join(out["choices_noise_free"]))
    for branch in (0, 1, 2):  # cubic, no noise: what each braked-branch form gives
        forced = _check(sample_like_table(None), degree=3, branch=branch)
        out[f"cubic_branch_{branch}_pct"] = {q: forced[q].rmse_pct_of_range for q in QUANTITIES}
        print(f"cubic, {branch} branch terms, no noise: " + ", ".join(
            f"{q} {forced[q].rmse_pct_of_range:.2f} %" for q in QUANTITIES))
    for criterion in ("loo", "aicc"):
        noisy_fits = [f for seed in draws
                      for f in fit_results(model_results_table(seed=seed), degree=criterion)]
        counts = {c: sum(_choice(f) == c for f in noisy_fits)
                  for c in sorted({_choice(f) for f in noisy_fits})}
        condition = [f.condition_number for f in noisy_fits]
        out[f"choices_{criterion}"] = counts
        print(f"{criterion}, {len(noisy_fits)} noisy fits: {counts}; condition numbers "
              f"{min(condition):.1f}-{max(condition):.1f}")
    return out


def _choice(fit) -> str:
    """``degree d + J`` / ``+ J, K`` / plain: the chosen degree and braked-branch terms."""
    branch = " + J, K" if fit.slope_below_zero else " + J" if fit.step_below_zero else ""
    return f"degree {fit.degree}{branch}"
