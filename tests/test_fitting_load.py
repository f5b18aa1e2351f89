"""Load interpolation on curve values (RUAG WPAT: "an interpolation for various wheel loads"):
exactness, method, slip range, and loads that do not bracket the request."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.interpolate import PchipInterpolator

from fitting import (LoadExtrapolationWarning, LoadRangeError, PowerCurve, interpolate_load,
                     interpolate_loads)

LOW = PowerCurve((1.0, 40.0, -30.0, 10.0), -0.1, 0.6)
HIGH = PowerCurve((3.0, 120.0, -100.0, 30.0, 5.0, -2.0), -0.2, 0.8)  # other degree and range
TOP = PowerCurve((5.0, 200.0, -150.0, 40.0), -0.1, 0.7)


def test_linear_interpolation_is_the_weighted_sum_of_the_curves():
    curve = interpolate_load({70.0: LOW, 180.0: HIGH}, 120.0)
    assert curve.method == "linear" and not curve.extrapolated
    assert (curve.slip_min, curve.slip_max, curve.degree) == (-0.1, 0.6, 5)  # shared range
    t = 50.0 / 110.0
    s = np.linspace(-0.1, 0.6, 57)
    np.testing.assert_allclose(curve.evaluate(s), (1 - t) * LOW.evaluate(s) + t * HIGH.evaluate(s),
                               rtol=0, atol=1e-11)
    assert curve.fit_rmse < 1e-12


def test_the_braked_branch_is_interpolated_with_the_values():
    stepped = PowerCurve(HIGH.coefficients, -0.2, 0.8, step_below_zero=4.0, slope_below_zero=-30.0)
    curve = interpolate_load({70.0: LOW, 180.0: stepped}, 120.0)
    t = 50.0 / 110.0  # linear: the weighted sum, branch included (LOW has none)
    assert curve.step_below_zero == pytest.approx(t * 4.0, abs=1e-10)
    assert curve.slope_below_zero == pytest.approx(t * -30.0, abs=1e-9)
    s = np.concatenate([np.linspace(-0.1, -1e-9, 20), np.linspace(0.0, 0.6, 20)])
    np.testing.assert_allclose(curve.evaluate(s), (1 - t) * LOW.evaluate(s)
                               + t * stepped.evaluate(s), rtol=0, atol=1e-10)
    # a shared range that stays at or above zero slip needs no branch
    driven = interpolate_load({70.0: PowerCurve(LOW.coefficients, 0.0, 0.6), 180.0: stepped},
                              120.0)
    assert (driven.step_below_zero, driven.slope_below_zero) == (0.0, 0.0)


def test_pchip_across_three_loads_at_every_slip():
    curves = {70.0: LOW, 180.0: HIGH, 300.0: TOP}
    curve = interpolate_load(curves, 120.0)
    assert curve.method == "pchip" and curve.tested_loads_n == (70.0, 180.0, 300.0)
    s = np.linspace(-0.1, 0.6, 41)
    across = PchipInterpolator([70.0, 180.0, 300.0],
                               np.array([c.evaluate(s) for c in curves.values()]), axis=0)(120.0)
    # the polynomial fitted to the interpolated values follows them to its fit misfit
    assert np.max(np.abs(curve.evaluate(s) - across)) < 5 * curve.fit_rmse + 1e-9
    assert curve.fit_rmse < 0.05
    linear = interpolate_load(curves, 120.0, method="linear")
    assert linear.method == "linear"
    assert interpolate_load(curves, 120.0, degree=7).degree == 7


def test_at_a_tested_load_the_curve_is_reproduced():
    curve = interpolate_load({70.0: LOW, 180.0: HIGH, 300.0: TOP}, 180.0)
    s = np.linspace(-0.1, 0.6, 11)
    np.testing.assert_allclose(curve.evaluate(s), HIGH.evaluate(s), rtol=0, atol=1e-10)


def test_many_loads_at_once_match_one_at_a_time():
    curves = {70.0: LOW, 180.0: HIGH, 300.0: TOP}
    loads = np.array([75.0, 120.0, 250.0, 299.0])
    many = interpolate_loads(curves, loads)
    for i, load in enumerate(loads):
        np.testing.assert_allclose(many.coefficients[i],
                                   interpolate_load(curves, load).coefficients, rtol=0, atol=1e-9)


def test_loads_outside_the_tested_ones_need_allow_extrapolation():
    curves = {70.0: LOW, 180.0: HIGH, 300.0: TOP}
    with pytest.raises(LoadRangeError, match=r"load 350 N outside the tested loads \(70-300 N\)"):
        interpolate_load(curves, 350.0)
    with pytest.raises(LoadRangeError, match="load 50 N outside"):
        interpolate_loads(curves, [100.0, 50.0])
    with pytest.warns(LoadExtrapolationWarning, match="350 N: extrapolated linearly"):
        curve = interpolate_load(curves, 350.0, allow_extrapolation=True)
    assert curve.extrapolated
    s = np.linspace(-0.1, 0.6, 9)
    t = (350.0 - 180.0) / 120.0  # linear from the two nearest loads
    np.testing.assert_allclose(curve.evaluate(s), (1 - t) * HIGH.evaluate(s) + t * TOP.evaluate(s),
                               rtol=0, atol=1e-10)


def test_unusable_load_sets_are_errors():
    with pytest.raises(LoadRangeError, match="one tested load \\(180 N only\\)"):
        interpolate_load({180.0: HIGH}, 120.0, allow_extrapolation=True)
    assert interpolate_load({180.0: HIGH}, 180.0).degree == 5
    with pytest.raises(LoadRangeError, match="no tested loads"):
        interpolate_load({}, 120.0)
    with pytest.raises(LoadRangeError, match="share no slip range"):
        interpolate_load({70.0: PowerCurve((0, 1, 0, 0), 0.0, 0.2),
                          180.0: PowerCurve((0, 1, 0, 0), 0.3, 0.6)}, 120.0)
    with pytest.raises(LoadRangeError, match="finite and > 0"):
        interpolate_load({70.0: LOW, 180.0: HIGH}, -5.0)
    with pytest.raises(ValueError, match="method 'cubic'"):
        interpolate_load({70.0: LOW, 180.0: HIGH}, 120.0, method="cubic")
