"""Confidence and prediction bands of the fitted curves against known truth (issue 18.4).

- in-family: the terramechanics model (the virtual testbed's truth law) plus Gaussian noise
  of exactly the stated SE (tests/test_fitting_synthetic.py), 20 seeds; the fresh runs for
  the prediction band are new draws at the same conditions;
- virtual testbed: raw runs generated (drift, noise, grouser oscillation, clock errors of
  the testbed's sensors), processed by ``swtlab.process_campaign`` like a lab's, fitted from
  the runs' budget uncertainties; the truth is the law's curve; held-out runs (120 N, and
  two extra slips at 70 and 300 N) are processed with the campaign and left out of the fit.

A 95 % band covers the true curve at about 95 % of the grid points of each curve (the points
of one curve are strongly correlated, so a few curves decide: bounds are wide) and about
95 % of new runs. The bounds fail a band of zero width (coverage near 0) and one three times
too wide (near 100 %: the pooled upper bounds).
"""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from fitting import band, curves_by_load, fit_results, from_run_results, interpolate_load
from fitting import validate_load_interpolation
from test_fitting_synthetic import MODEL, model_results_table, sample_like_table

QUANTITIES = ("dp_n", "torque_nm", "sinkage_m", "resistance_n")
GRID = 41
SLIPS = (-0.10, -0.05, 0.0, 0.05, 0.10, 0.20, 0.35, 0.60)
HELD_OUT = {120.0: (-0.05, 0.15, 0.45), 70.0: (0.02, 0.3), 300.0: (0.02, 0.3)}


def _grid_coverage(curve, truth_at) -> float:
    s = np.linspace(curve.slip_min, curve.slip_max, GRID)
    mean, conf, _ = band(curve, s)
    return float(np.mean(np.abs(mean - truth_at(s)) <= conf))


def _inside_prediction(curve, slip, value) -> list[bool]:
    mean, _, pred = band(curve, np.asarray(slip, dtype=float))
    return list(np.abs(mean - np.asarray(value, dtype=float)) <= pred)


def _summary(fits_by_seed, truth, held_out) -> pd.DataFrame:
    """Per quantity: confidence coverage at the tested loads and at 120 N (interpolated), and
    the share of held-out runs inside the prediction band."""
    rows = {q: {"conf": [], "conf_120": [], "pred": []} for q in QUANTITIES}
    for fits, new in zip(fits_by_seed, held_out):
        for f in fits:
            rows[f.quantity]["conf"].append(_grid_coverage(
                f, lambda s, f=f: truth(f.load_n, s)[f.quantity]))
            at = new[np.isclose(new["load_n"], f.load_n)]
            rows[f.quantity]["pred"] += _inside_prediction(f, at["slip"], at[f.quantity])
        for (_, _, _, q), curves in curves_by_load(fits).items():
            curve = interpolate_load(curves, 120.0)
            rows[q]["conf_120"].append(_grid_coverage(curve,
                                                      lambda s, q=q: truth(120.0, s)[q]))
            at = new[np.isclose(new["load_n"], 120.0)]
            rows[q]["pred"] += _inside_prediction(curve, at["slip"], at[q])
    return pd.DataFrame({q: {k: float(np.mean(v)) for k, v in r.items()} | {
        "held_out_runs": len(r["pred"])} for q, r in rows.items()}).T


def _check(table: pd.DataFrame, low_conf: float, low_pred: float,
           many_runs: bool = True) -> None:
    assert (table["conf"] >= low_conf).all(), table["conf"]
    assert (table["pred"] >= low_pred).all(), table["pred"]
    assert table["conf"].mean() <= 0.99  # not 3x too wide
    if many_runs:  # 14 runs all inside is 49 % likely at a true 95 %: no test of width
        assert table["pred"].mean() <= 0.995
    # across load the band also holds the interpolation's error (docs/fitting.md, "Bands")
    assert table["conf_120"].min() >= low_conf


def test_in_family_bands_cover_the_model_and_new_runs():
    """Measured (seeds 0-19): confidence at the tested loads DP 0.91, torque 0.88, sinkage
    0.93, resistance 0.96; at 120 N 0.97 / 0.92 / 0.95 / 0.99 (0.96 / 0.83 / 0.76 / 0.97
    without the interpolation-error term); new runs inside the prediction band 0.98 / 0.955 /
    0.96 / 0.95 (600 each)."""
    fits, new = [], []
    for seed in range(20):
        fits.append(fit_results(model_results_table(seed=seed), quantities=QUANTITIES))
        new.append(pd.concat([model_results_table(seed=seed + 1000),
                              model_results_table((120.0,), (-0.05, 0.15, 0.45),
                                                  seed=seed + 2000)]))
    table = _summary(fits, lambda w, s: MODEL.curves(w, s, 0), new)
    print(f"\nin-family, 20 seeds:\n{table.round(3).to_string()}")
    _check(table, low_conf=0.8, low_pred=0.88)


@pytest.fixture(scope="module")
def virtual_campaigns(tmp_path_factory):
    import swtlab
    from virtual_testbed import RunCondition, generate_campaign
    from virtual_testbed.sample_campaign import SAMPLE_RATES

    out = []
    for seed in (21, 22):
        conds = [RunCondition.of(f"r{int(w)}_{i}", "speed_control", w, 0, s)
                 for w in (70.0, 180.0, 300.0) for i, s in enumerate(SLIPS)]
        conds += [RunCondition.of(f"h{int(w)}_{i}", "speed_control", w, 0, s)
                  for w, slips in HELD_OUT.items() for i, s in enumerate(slips)]
        folder = tmp_path_factory.mktemp(f"bands{seed}")
        generate_campaign(folder, conds, seed=seed, rates=SAMPLE_RATES, form="csv",
                          duration_s=60.0)
        out.append(swtlab.process_campaign(folder / "campaign", soil_flow=False).results)
    return out


@pytest.mark.slow  # two 60 s virtual campaigns generated and processed
@pytest.mark.slow_campaign
def test_virtual_testbed_bands_cover_the_law_and_held_out_runs(virtual_campaigns):
    """Measured (seeds 21, 22, budget uncertainties of processed raw runs): confidence at the
    tested loads DP 0.90, torque 0.87, sinkage 0.89, resistance 0.97; at 120 N 0.94 / 0.84 /
    0.96 / 0.96 (0.68 / 0.62 / 0.52 / 0.95 without the interpolation-error term); held-out
    runs inside the prediction band 1.0 for all four (14 each; 0.93 / 0.93 / 0.79 / 1.0
    without). Fresh seeds 30-49 with 160 held-out 120 N runs: bench/bench_band_coverage.py."""
    from terramechanics.testbed_law import ModelLaw

    law = ModelLaw(MODEL)
    fits, new = [], []
    for results in virtual_campaigns:
        held = results["run_id"].str.startswith("h")
        fits.append(fit_results(from_run_results(results[~held]), quantities=QUANTITIES))
        new.append(from_run_results(results[held]))
    table = _summary(fits, lambda w, s: law.evaluate(w, s, 0), new)
    print(f"\nvirtual testbed, seeds 21, 22:\n{table.round(3).to_string()}")
    _check(table, low_conf=0.75, low_pred=0.75, many_runs=False)


def test_the_120n_check_counts_the_runs_inside_the_interpolated_band():
    """``validate_load_interpolation`` counts the 120 N runs inside the prediction band of
    the interpolated curve: the same count as :func:`band` by hand; the sample's 75 % run,
    outside the tested slips, is not counted."""
    table = sample_like_table(seed=5)
    results = {r.quantity: r for r in validate_load_interpolation(table, 120.0)}
    fits = fit_results(table[table["load_n"] != 120.0])
    curve = interpolate_load(curves_by_load(fits)[("bb2", "bb2_sand", 0, "dp_n")], 120.0)
    runs = table[(table["load_n"] == 120.0) & (table["slip"] <= curve.slip_max)]
    inside = _inside_prediction(curve, runs["slip"], runs["dp_n"])
    dp = results["dp_n"]
    assert dp.n_points - dp.n_outside_slip_range == len(inside) == 4
    assert dp.n_inside_band == sum(inside)
    assert dp.fraction_inside_band == pytest.approx(sum(inside) / 4)
    assert all(0.0 <= r.fraction_inside_band <= 1.0 for r in results.values())
