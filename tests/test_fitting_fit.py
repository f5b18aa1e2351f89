"""Curve fits: exact recovery, weights, power-coefficient conversion, degree choice,
diagnostics and flags, and every bad input (RUAG WPAT method, docs/fitting.md)."""

from __future__ import annotations

import warnings

import numpy as np
import pandas as pd
import pytest
from numpy.polynomial import Chebyshev, Polynomial

from fitting import (CurveFit, DegreeError, FittingError, OutsideSlipRangeWarning,
                     TooFewPointsError, fit_curve, fit_results)
from fitting.polynomial import horner, power_matrix
from test_fitting_synthetic import TESTED_SLIPS, model_results_table

KNOWN = (2.0, 80.0, -60.0, 25.0, -9.0, 4.0, -3.0, 1.5)  # a_i of slip**i
SLIPS = np.linspace(-0.3, 0.9, 25)


@pytest.mark.parametrize("degree", [3, 4, 5, 6, 7])
def test_noise_free_polynomial_is_recovered_exactly(degree):
    truth = KNOWN[:degree + 1]
    fit = fit_curve(SLIPS, horner(truth, SLIPS), degree=degree)
    assert fit.degree == degree and fit.degree_choice == "user" and fit.degree_scores == ()
    np.testing.assert_allclose(fit.coefficients, truth, rtol=1e-9, atol=1e-9)
    assert fit.rmse < 1e-11 and fit.loo_rmse < 1e-10 and fit.r2 == pytest.approx(1.0, abs=1e-12)
    assert not fit.oscillates
    assert fit.weighting == "equal weights (no standard errors)"


def test_power_coefficients_are_the_exact_conversion_of_the_chebyshev_series():
    rng = np.random.default_rng(0)
    for lo, hi, degree in [(-0.1, 0.6, 7), (0.0, 1.0, 5), (-0.95, -0.2, 3)]:
        cheb = rng.normal(size=degree + 1)
        mine = power_matrix(lo, hi, degree) @ cheb
        numpy_power = Chebyshev(cheb, domain=[lo, hi]).convert(kind=Polynomial).coef
        np.testing.assert_allclose(mine, numpy_power, rtol=1e-12, atol=1e-12)
        s = np.linspace(lo, hi, 101)
        # the power form evaluates to the series within rounding of its coefficients
        np.testing.assert_allclose(horner(mine, s), Chebyshev(cheb, domain=[lo, hi])(s),
                                   rtol=0, atol=1e-11 * np.abs(mine).sum())


def test_noisy_fit_is_within_the_standard_errors():
    rng = np.random.default_rng(3)
    truth = KNOWN[:4]
    se = np.where(SLIPS > 0.3, 2.0, 0.5)  # heteroscedastic: weights matter
    value = horner(truth, SLIPS) + rng.normal(0, se)
    fit = fit_curve(SLIPS, value, se, degree=3)
    # the fitted curve sits within its points' SEs of the truth: mean ((fit-truth)/se)^2 is
    # p/n = 4/25 in expectation
    chi2 = np.mean(((fit.evaluate(SLIPS) - horner(truth, SLIPS)) / se) ** 2)
    assert chi2 < 0.5
    assert fit.rmse == pytest.approx(np.sqrt(np.mean((value - fit.evaluate(SLIPS)) ** 2)))
    assert 0.5 < fit.loo_rmse / fit.rmse < 2.0
    assert fit.weighting.startswith("1/SE^2")


def test_weights_follow_the_standard_errors_and_are_floored():
    slip = np.linspace(0, 0.6, 8)
    value = horner((0, 10, 0, 5), slip)
    value[3] += 1.0  # one bad point
    loose = fit_curve(slip, value, np.where(np.arange(8) == 3, 10.0, 0.1), degree=3)
    tight = fit_curve(slip, value, np.where(np.arange(8) == 3, 0.001, 0.1), degree=3)
    # a large SE lets the bad point go; a tiny SE is floored at 0.2 x median (0.02): the
    # point pulls hard but cannot dominate infinitely
    assert abs(loose.evaluate(slip[3]) - value[3]) > 0.8
    assert abs(tight.evaluate(slip[3]) - value[3]) < 0.2
    assert "floored at 0.2 x median SE (0.02)" in tight.weighting
    nan_se = fit_curve(slip, value, np.where(np.arange(8) == 3, np.nan, 0.1), degree=3)
    np.testing.assert_allclose(nan_se.coefficients, fit_curve(slip, value, None,
                                                              degree=3).coefficients)


@pytest.mark.parametrize("criterion", ["loo", "aicc"])
def test_degree_choice_finds_the_true_degree_and_states_it(criterion):
    rng = np.random.default_rng(11)
    slip = np.linspace(-0.1, 0.9, 30)
    truth = (1.0, 30.0, -20.0, 40.0, -45.0)  # degree 4
    fit = fit_curve(slip, horner(truth, slip) + rng.normal(0, 0.05, slip.size),
                    np.full(slip.size, 0.05), degree=criterion)
    assert fit.degree_choice == criterion
    assert [d for d, _ in fit.degree_scores] == [3, 4, 5, 6, 7]
    assert fit.degree == 4
    assert fit.to_dict()["degree_scores"]["4"] == min(s for _, s in fit.degree_scores)


def test_degree_choice_on_model_curves_is_low_with_the_sample_slips():
    fits = fit_results(model_results_table(seed=1))
    assert len(fits) == 15  # 3 loads x 5 quantities
    assert {f.degree_choice for f in fits} == {"loo"}
    degrees = [f.degree for f in fits]
    assert set(degrees) <= {3, 4} and degrees.count(3) >= 12  # 9 slips: cubic, some quartic
    assert not any(f.oscillates for f in fits)
    assert all(f.r2 > 0.99 for f in fits if f.quantity in ("dp_n", "torque_nm", "dp_over_w"))


def test_degree_choice_on_dense_model_curves_is_sensible():
    slips = tuple(np.round(np.linspace(-0.1, 0.6, 15), 4))
    for criterion in ("loo", "aicc"):
        fits = fit_results(model_results_table(slips=slips, seed=1), degree=criterion)
        for f in fits:
            assert 3 <= f.degree <= 7 and not f.oscillates
            assert f.rmse < 2.0 * f.loo_rmse  # no fit chases its points
            assert f.r2 > 0.98


def test_degree_seven_through_few_noisy_points_is_flagged_as_oscillating():
    rng = np.random.default_rng(5)
    slip = np.array([-0.1, 0.0, 0.05, 0.1, 0.2, 0.35, 0.6, 0.9, 0.95])
    value = 100 * slip / (slip + 0.15) + rng.normal(0, 3.0, slip.size)
    fit = fit_curve(slip, value, degree=7)
    assert fit.oscillates and fit.max_departure > 5.0
    smooth = fit_curve(slip, value, degree=3)
    assert not smooth.oscillates
    # the automatic choice never takes an oscillating degree while a smooth one exists
    assert not fit_curve(slip, value, degree="loo").oscillates


def test_evaluation_outside_the_slip_range_warns_and_is_flagged():
    fit = fit_curve(SLIPS, horner(KNOWN[:4], SLIPS), degree=3)
    assert (fit.slip_min, fit.slip_max) == (-0.3, 0.9)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        fit.evaluate([-0.3, 0.0, 0.9])  # inside: silent
    with pytest.warns(OutsideSlipRangeWarning, match=r"1 slip\(s\) outside the fitted range "
                                                     r"\[-0.3, 0.9\] \(e.g. 0.95\)"):
        value = fit.evaluate([0.1, 0.95])
    assert value[1] == pytest.approx(horner(KNOWN[:4], 0.95))
    assert fit.outside_range([-0.31, 0.5, 1.0]).tolist() == [True, False, True]


def test_fit_record_carries_its_diagnostics():
    table = model_results_table(seed=2)
    fit = fit_results(table, degree=3, quantities=["dp_n"])[1]
    assert isinstance(fit, CurveFit)
    d = fit.to_dict()
    assert (d["wheel"], d["soil"], d["multipass"], d["load_n"]) == ("bb2", "bb2_sand", 0, 180.0)
    assert (d["quantity"], d["unit"], d["degree"], d["n_points"]) == ("dp_n", "N", 3, 9)
    assert (d["slip_min"], d["slip_max"]) == (-0.1, 0.6)
    assert 0 < d["rmse"] < 1.5 and d["loo_rmse"] > d["rmse"] and d["r2"] > 0.999
    assert 1.0 < d["condition_number"] < 100.0  # Chebyshev basis: well conditioned
    assert len(d["coefficients"]) == 4
    # the braked branch, chosen by LOO at a set degree: the model's braked side lies above
    # its driven side at zero slip (DP -7.7 N at 0-, -11.0 N at 0 at 180 N), so J > 0
    assert d["branch_choice"] == "loo" and set(d["branch_scores"]) == {"3+1", "3+2"}
    assert d["step_below_zero"] > 0 and 0 < d["step_se"] < d["step_below_zero"]


def test_dp_over_w_uses_the_measured_load():
    table = model_results_table(seed=None)
    table["wheel_load_n"] = table["load_n"] * 1.1
    fits = {(f.load_n, f.quantity): f for f in fit_results(table, degree=3)}
    s = np.array(TESTED_SLIPS)
    np.testing.assert_allclose(fits[180.0, "dp_over_w"].evaluate(s) * 198.0,
                               fits[180.0, "dp_n"].evaluate(s), atol=1e-9)
    assert fits[180.0, "dp_over_w"].unit == "1"


@pytest.mark.parametrize("degree", [2, 8, 0, 3.5, "best", True])
def test_degree_outside_3_to_7_is_an_error(degree):
    with pytest.raises(DegreeError, match="3-7"):
        fit_curve(SLIPS, SLIPS, degree=degree)
    with pytest.raises(DegreeError):
        fit_results(model_results_table(), degree=degree)


def test_too_few_points_for_the_degree_names_group_and_quantity():
    table = model_results_table(slips=(-0.1, 0.0, 0.1, 0.2, 0.35, 0.6))  # 6 slips
    fit_results(table, degree=4)  # 6 >= 4 + 2
    with pytest.raises(TooFewPointsError,
                       match=r"bb2/bb2_sand multipass 0 at 70 N, dp_n: 6 distinct slips "
                             r"\(6 points\); degree 5 needs at least 7"):
        fit_results(table, degree=5)
    few = model_results_table(slips=(0.0, 0.1, 0.2, 0.4))
    with pytest.raises(TooFewPointsError, match="too few to choose a degree by loo"):
        fit_results(few)
    # replicates add points, not distinct slips
    with pytest.raises(TooFewPointsError, match="4 distinct slips \\(8 points\\)"):
        fit_curve(np.repeat([0.0, 0.1, 0.2, 0.4], 2), np.arange(8.0), degree=3)


def test_bad_tables_are_errors():
    table = model_results_table()
    with pytest.raises(FittingError, match=r"lacks column\(s\) \['soil'\]"):
        fit_results(table.drop(columns="soil"))
    with pytest.raises(FittingError, match="lacks column 'dp_over_w' \\(needs dp_n and "
                                           "wheel_load_n\\)"):
        fit_results(table.drop(columns="wheel_load_n"), quantities=["dp_over_w"])
    with pytest.raises(FittingError, match="unknown quantity 'thrust_n'"):
        fit_results(table, quantities=["thrust_n"])
    with pytest.raises(FittingError, match="finite"):
        fit_curve([0.0, np.inf, 0.2, 0.3, 0.4], [1.0] * 5, degree=3)


def test_missing_values_leave_only_that_quantity():
    table = model_results_table(slips=TESTED_SLIPS + (0.02,))
    table.loc[table["slip"] == 0.02, "dp_n"] = np.nan  # e.g. a free-sled run: no tether
    fits = {(f.load_n, f.quantity): f for f in fit_results(table)}
    assert fits[70.0, "dp_n"].n_points == 9 and fits[70.0, "torque_nm"].n_points == 10
    assert pd.isna(table["dp_n"]).sum() == 3


def test_the_results_table_of_swtlab_results_is_adapted():
    from fitting import from_run_results

    ours = model_results_table(slips=tuple(np.round(np.linspace(-0.1, 0.6, 10), 3)), seed=3)
    theirs = ours.rename(columns={"load_n": "load_set_n", "slip": "slip_mean",
                                  "wheel_load_n": "wheel_load_n_mean",
                                  **{q: f"{q}_mean" for q in ("dp_n", "torque_nm", "sinkage_m",
                                                              "resistance_n")}})
    theirs["status"] = "ok"
    theirs["mode"] = "speed_control"
    theirs["run_id"] = [f"r{i}" for i in range(len(theirs))]
    theirs.loc[0, "status"] = "no_stable_phase"
    theirs.loc[1, "status"] = "flagged"
    theirs.loc[2, "mode"] = "steered"
    adapted = from_run_results(theirs)
    assert len(adapted) == len(ours) - 3 and "run_id" in adapted
    assert len(from_run_results(theirs, statuses=("ok", "flagged"))) == len(ours) - 2
    a = {(f.load_n, f.quantity): f for f in fit_results(adapted)}
    b = {(f.load_n, f.quantity): f for f in fit_results(ours.iloc[3:])}
    assert a.keys() == b.keys()
    assert all(a[k].coefficients == b[k].coefficients for k in a)


BRANCH_SLIPS = np.linspace(-0.3, 0.6, 19)  # 6 braked slips, 13 driven ones (zero included)
STEP_N, SLOPE_N = -6.0, 25.0  # hand-made branch: y += J + K s below zero slip


def _stepped(slip):
    """A hand-made curve with a step and a slope change at zero slip (no model involved)."""
    slip = np.asarray(slip, dtype=float)
    return horner(KNOWN[:4], slip) + np.where(slip < 0, STEP_N + SLOPE_N * slip, 0.0)


def test_noise_free_step_and_slope_are_recovered_exactly():
    fit = fit_curve(BRANCH_SLIPS, _stepped(BRANCH_SLIPS), degree=3, branch=2)
    np.testing.assert_allclose(fit.coefficients, KNOWN[:4], rtol=1e-9, atol=1e-9)
    assert fit.step_below_zero == pytest.approx(STEP_N, abs=1e-9)
    assert fit.slope_below_zero == pytest.approx(SLOPE_N, abs=1e-8)
    assert fit.branch_choice == "user" and fit.rmse < 1e-11 and not fit.oscillates
    # the curve jumps at zero slip: zero itself belongs to the driven side
    assert fit.evaluate(-1e-12) - fit.evaluate(0.0) == pytest.approx(STEP_N, abs=1e-9)


def test_the_step_is_recovered_within_its_standard_error():
    rng = np.random.default_rng(21)
    se = np.full(BRANCH_SLIPS.size, 0.4)
    fits = [fit_curve(BRANCH_SLIPS, _stepped(BRANCH_SLIPS) + rng.normal(0, se), se, degree=3,
                      branch=2) for _ in range(400)]
    step = np.array([f.step_below_zero for f in fits])
    step_se = fits[0].step_se  # the same design and SEs every draw: the same SE
    assert all(f.step_se == pytest.approx(step_se) for f in fits)
    # unbiased (mean within 3 SE of the mean) and the stated SE is the scatter (+-10 %)
    assert abs(step.mean() - STEP_N) < 3 * step_se / np.sqrt(step.size)
    assert np.std(step, ddof=1) == pytest.approx(step_se, rel=0.1)
    assert np.mean(np.abs(step - STEP_N) < step_se) == pytest.approx(0.683, abs=0.06)
    slope = np.array([f.slope_below_zero for f in fits])
    assert np.std(slope, ddof=1) == pytest.approx(fits[0].slope_se, rel=0.1)
    # without standard errors the SE is scaled by the residual scatter: about the same
    unweighted = fit_curve(BRANCH_SLIPS, _stepped(BRANCH_SLIPS) + rng.normal(0, se),
                           degree=3, branch=2)
    assert unweighted.step_se == pytest.approx(step_se, rel=0.5)


def test_the_choice_takes_a_branch_only_where_the_data_have_one():
    rng = np.random.default_rng(8)
    se = np.full(BRANCH_SLIPS.size, 0.2)
    noise = rng.normal(0, se)
    stepped = fit_curve(BRANCH_SLIPS, _stepped(BRANCH_SLIPS) + noise, se)
    smooth = fit_curve(BRANCH_SLIPS, horner(KNOWN[:4], BRANCH_SLIPS) + noise, se)
    assert stepped.branch_choice == "loo" and stepped.degree == 3
    assert abs(stepped.step_below_zero - STEP_N) < 3 * stepped.step_se
    assert abs(stepped.slope_below_zero - SLOPE_N) < 3 * stepped.slope_se
    assert (smooth.degree, smooth.step_below_zero, smooth.slope_below_zero) == (3, 0.0, 0.0)
    assert {(d, b) for d, b, _ in smooth.branch_scores} >= {(3, 1), (3, 2)}


def test_one_braked_run_cannot_carry_a_branch():
    slip = np.array([-0.1, 0.0, 0.05, 0.1, 0.2, 0.35, 0.6, 0.8])
    fit = fit_curve(slip, _stepped(slip), degree=3)
    assert fit.branch_scores == () and fit.step_below_zero == 0.0
    with pytest.raises(TooFewPointsError, match="2 distinct slips below zero"):
        fit_curve(slip, _stepped(slip), degree=3, branch=1)
    with pytest.raises(FittingError, match="branch 'yes': give 'auto', 0, 1 or 2"):
        fit_curve(slip, _stepped(slip), degree=3, branch="yes")


@pytest.mark.parametrize("dof, t975, chi2_95", [(1, 12.706, 3.841), (5, 2.571, 11.070),
                                                (10, 2.228, 18.307), (30, 2.042, 43.773)])
def test_the_band_quantiles_are_the_tabulated_ones(dof, t975, chi2_95):
    """Student's t 0.975 and chi^2 0.95 quantiles against the printed tables (NIST/SEMATECH
    e-Handbook of Statistical Methods, 2012, sections 1.3.6.7.2 and 1.3.6.7.4; 3 decimals)."""
    from fitting.fit import _chi2_quantile, _t_quantile

    assert _t_quantile(0.975, dof) == pytest.approx(t975, abs=5e-4)
    assert _chi2_quantile(0.95, dof) == pytest.approx(chi2_95, abs=5e-4)
