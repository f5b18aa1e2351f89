"""The WPM runtime (RUAG WPM): curve at a load, quantities at a slip, and the slip for a
required DP/torque/sinkage/resistance -- checked against dense brute force, with 100 % slip
and the maximum for unreachable targets, vectorised, and clear errors on ambiguous input."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

from fitting import LoadExtrapolationWarning, LoadRangeError, OutsideSlipRangeWarning, fit_results
from wpm_export import (WheelPerformanceModule, WpmCurve, WpmSelectionError, inputs_sha256,
                        read_wpm_csv, solve_slip, write_wpm_csv)
from test_fitting_synthetic import MODEL, model_results_table


@pytest.fixture(scope="module")
def wpm(tmp_path_factory):
    table = model_results_table(multipass=(0, 1), seed=7)
    path = tmp_path_factory.mktemp("wpm") / "wpm.csv"
    write_wpm_csv(fit_results(table), path, inputs_sha256(table), "test")
    return WheelPerformanceModule.load(path)


def _brute_force(curve, target):
    """Smallest slip on a 2e6-point grid where the curve reaches the target."""
    s = np.linspace(curve.slip_min, curve.slip_max, 2_000_001)
    v = curve.evaluate(s)
    hit = (v[:-1] - target) * (v[1:] - target) <= 0
    return s[np.argmax(hit)] if hit.any() else None


@pytest.mark.parametrize("quantity, targets", [
    ("dp_n", [-25.0, 0.0, 10.0, 25.0, 45.0]),
    ("torque_nm", [0.0, 2.0, 6.0, 9.0]),
    ("sinkage_m", [0.0035, 0.004, 0.006]),
    ("resistance_n", [13.0, 16.0, 20.0]),
])
def test_inverse_matches_dense_brute_force(wpm, quantity, targets):
    found = wpm.slip_for(quantity, targets, 120.0, multipass=0)
    curve = wpm.curve(quantity, 120.0, multipass=0)
    for target, slip, status in zip(targets, found.slip, found.status):
        expected = _brute_force(curve, target)
        assert status == "ok" and expected is not None
        assert slip == pytest.approx(expected, abs=1e-6)
    np.testing.assert_allclose(found.value, targets, rtol=0, atol=1e-9)


def test_the_smallest_slip_is_returned_when_a_peaked_curve_reaches_the_target_twice():
    peaked = WpmCurve((0.0, 100.0, -100.0, 0.0), 0.0, 1.0, soil="s", wheel="w", multipass=0,
                      load_n=100.0, quantity="dp_n", unit="N", n_points=8, rmse=0.0, line=3)
    found = solve_slip(np.array([peaked.coefficients]), [0, 0], [16.0, 25.0], 0.0, 1.0)
    assert found.slip[0] == pytest.approx(0.2, abs=1e-12)  # 100 s - 100 s^2 = 16: 0.2 and 0.8
    assert found.slip[1] == pytest.approx(0.5, abs=1e-7) and found.status[1] == "ok"


def test_targets_inside_the_jump_at_zero_slip_are_given_at_zero_slip():
    # hand-made: DP = 100 s driven, 100 s - 5 + 20 s braked (J = -5 N, K = 20 N): the curve
    # rises to -5 N at zero slip from below, jumps to 0 N, rises on
    stepped = WpmCurve((0.0, 100.0, 0.0, 0.0), -0.2, 0.6, soil="s", wheel="w", multipass=0,
                       load_n=100.0, quantity="dp_n", unit="N", n_points=9, rmse=0.0, line=3,
                       step_below_zero=-5.0, slope_below_zero=20.0)
    wpm = WheelPerformanceModule([stepped])
    found = wpm.slip_for("dp_n", [-17.0, -4.0, -2.5, -1.0, 30.0, -30.0, 61.0], 100.0)
    np.testing.assert_allclose(found.slip[:5], [-0.1, 0.0, 0.0, 0.0, 0.3], atol=1e-12)
    assert found.status.tolist() == ["ok"] + ["at_step"] * 3 + ["ok", "below_min", "above_max"]
    assert found.reached.tolist() == [True] * 5 + [False] * 2
    np.testing.assert_allclose(found.value[:5], [-17.0, -4.0, -2.5, -1.0, 30.0], atol=1e-12)
    assert found.value[5] == pytest.approx(-29.0) and found.value[6] == pytest.approx(60.0)
    # the two ends of the jump are values of the curve: reached, at zero slip
    ends = solve_slip([stepped.coefficients], [0, 0], [-5.0, 0.0], -0.2, 0.6, [[-5.0, 20.0]])
    np.testing.assert_allclose(ends.slip, 0.0, atol=1e-15)
    assert ends.status.tolist() == ["ok", "ok"]
    # the same as the dense brute force, across both sides
    s = np.linspace(-0.2, 0.6, 800_001)
    v = stepped.evaluate(s)
    for target in (-20.0, -7.3, 12.0):
        hit = (v[:-1] - target) * (v[1:] - target) <= 0
        assert float(wpm.slip_for("dp_n", target, 100.0).slip) == pytest.approx(
            s[np.argmax(hit)], abs=2e-6)
    # a jump down is passed on the braked side first: the smallest slip is braked
    down = solve_slip([[0.0, 100.0, 0.0, 0.0]], [0], [2.0], -0.2, 0.6, [[5.0, 0.0]])
    assert float(down.slip[0]) == pytest.approx(-0.03) and down.status[0] == "ok"


def test_unreachable_dp_gives_100_percent_slip_and_the_maximum(wpm):
    curve = wpm.curve("dp_n", 120.0, multipass=0)
    s = np.linspace(curve.slip_min, curve.slip_max, 2_000_001)
    peak = curve.evaluate(s).max()
    found = wpm.slip_for("dp_n", [peak + 0.01, 500.0], 120.0, multipass=0)
    assert found.slip.tolist() == [1.0, 1.0]
    assert found.status.tolist() == ["above_max", "above_max"]
    np.testing.assert_allclose(found.value, peak, rtol=1e-10)
    assert not found.reached.any()


def test_a_target_below_the_curve_has_no_slip(wpm):
    found = wpm.slip_for("dp_n", -500.0, 120.0, multipass=0)
    assert np.isnan(found.slip) and str(found.status) == "below_min"
    curve = wpm.curve("dp_n", 120.0, multipass=0)
    assert float(found.value) == pytest.approx(curve.evaluate(curve.slip_min), rel=1e-9)


def test_queries_are_vectorised_over_targets_and_loads(wpm):
    rng = np.random.default_rng(0)
    targets = rng.uniform(-10, 40, (4, 50))
    loads = rng.uniform(70, 300, (4, 1))
    found = wpm.slip_for("dp_n", targets, loads, multipass=1)
    assert found.slip.shape == found.value.shape == found.status.shape == (4, 50)
    for i in (0, 3):
        for j in (0, 17, 49):
            one = wpm.slip_for("dp_n", targets[i, j], loads[i, 0], multipass=1)
            assert float(one.slip) == pytest.approx(found.slip[i, j], abs=1e-12)
    ok = found.reached
    assert ok.mean() > 0.9
    np.testing.assert_allclose(found.value[ok], targets[ok], atol=1e-9)


def test_at_slip_gives_every_quantity(wpm):
    values = wpm.at_slip([0.0, 0.3], 180.0, multipass=0)
    assert list(values) == ["dp_n", "torque_nm", "sinkage_m", "resistance_n", "dp_over_w"]
    for q, v in values.items():
        np.testing.assert_allclose(v, wpm.curve(q, 180.0, multipass=0).evaluate([0.0, 0.3]))
    truth = MODEL.curves(180.0, 0.3, 0)
    assert values["dp_n"][1] == pytest.approx(truth["dp_n"], abs=1.0)  # 56.9 N
    assert values["sinkage_m"][1] == pytest.approx(truth["sinkage_m"], abs=2e-4)
    assert values["dp_over_w"][1] == pytest.approx(values["dp_n"][1] / 180.0, rel=0.03)
    with pytest.warns(OutsideSlipRangeWarning, match=r"slip outside the range of dp_n "
                                                     r"\[-0.1, 0.6\], torque_nm"):
        wpm.at_slip(0.8, 180.0, multipass=0)


def test_the_curve_at_a_load_is_interpolated_on_values(wpm):
    curve = wpm.curve("dp_n", 120.0, multipass=0)
    assert curve.method == "pchip" and curve.tested_loads_n == (70.0, 180.0, 300.0)
    assert (curve.slip_min, curve.slip_max) == (-0.1, 0.6)
    assert curve.evaluate(0.2) == pytest.approx(MODEL.curves(120.0, 0.2, 0)["dp_n"], abs=1.0)


def test_several_curve_sets_need_a_choice(wpm):
    assert wpm.sets() == [("bb2_sand", "bb2", 0), ("bb2_sand", "bb2", 1)]
    with pytest.raises(WpmSelectionError, match="2 curve sets match .*pick one: soil='bb2_sand', "
                                                "wheel='bb2', multipass=0; soil='bb2_sand'"):
        wpm.slip_for("dp_n", 25.0, 120.0)
    with pytest.raises(WpmSelectionError, match="no curves for soil='clay'"):
        wpm.curve("dp_n", 120.0, soil="clay")
    _, rows = read_wpm_csv(wpm.source)
    one_quantity = WheelPerformanceModule([c for c in rows if c.quantity == "dp_n"
                                           and c.multipass == 0])
    with pytest.raises(WpmSelectionError, match="no torque_nm curves .* it has dp_n"):
        one_quantity.slip_for("torque_nm", 2.0, 120.0)


def test_loads_that_do_not_bracket_the_request(wpm):
    with pytest.raises(LoadRangeError, match="load 400 N outside the tested loads"):
        wpm.slip_for("dp_n", 25.0, 400.0, multipass=0)
    with pytest.raises(LoadRangeError, match="load 20 N outside"):
        wpm.at_slip(0.2, [100.0, 20.0], multipass=0)
    with pytest.warns(LoadExtrapolationWarning):
        found = wpm.slip_for("dp_n", 25.0, 400.0, multipass=0, allow_extrapolation=True)
    assert found.status == "ok"
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        wpm.slip_for("dp_n", 25.0, 300.0, multipass=0)  # a tested load: silent


def _bisection(curve, target, points: int = 200_001) -> float | None:
    """Smallest slip where the curve reaches ``target``: the first sign change on a dense
    grid, then bisection on the polynomial there to rounding (independent of the runtime)."""
    s = np.linspace(curve.slip_min, curve.slip_max, points)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        d = curve.evaluate(s) - target
    hit = np.flatnonzero((d[:-1] * d[1:] <= 0))
    if not hit.size:
        return None
    lo, hi = s[hit[0]], s[hit[0] + 1]
    f_lo = float(curve.evaluate(lo)) - target
    for _ in range(100):
        mid = 0.5 * (lo + hi)
        f_mid = float(curve.evaluate(mid)) - target
        if (f_mid <= 0) == (f_lo <= 0) and f_mid != 0:
            lo, f_lo = mid, f_mid
        else:
            hi = mid
    return hi if f_lo != 0 else lo


@pytest.mark.parametrize("quantity", ["dp_n", "torque_nm", "sinkage_m", "resistance_n"])
def test_every_path_of_the_inverse_is_exact_to_1e_6_against_bisection(wpm, quantity):
    """Issue 19.1: the cached table (one load), the table look-up of ``slip_for_one`` and the
    row solver (many loads) against bisection on the curve of ``interpolate_loads`` (not the
    runtime's load polynomial), at tested and untested loads, targets spread over each
    curve's range and crowded just below its maximum (where the slope vanishes)."""
    rng = np.random.default_rng(11)
    loads = [70.0, 97.3, 120.0, 180.0, 244.4, 300.0]
    many_loads, many_targets, expected_many = [], [], []
    for load in loads:
        curve = wpm.curve(quantity, load, multipass=0)
        s = np.linspace(curve.slip_min, curve.slip_max, 200_001)
        v = curve.evaluate(s)
        span = v.max() - v.min()
        targets = np.concatenate([rng.uniform(v.min(), v.max(), 12),
                                  v.max() - span * np.array([1e-3, 1e-5, 1e-7])])
        expected = [_bisection(curve, t) for t in targets]
        table = wpm.slip_for(quantity, targets, load, multipass=0)
        for t, e, slip in zip(targets, expected, table.slip):
            assert e is not None and slip == pytest.approx(e, abs=1e-6), (load, t)
            one = wpm.slip_for_one(quantity, t, load, multipass=0)
            assert one[0] == pytest.approx(e, abs=1e-6) and one[2] in ("ok", "at_step")
        many_loads += [load] * targets.size
        many_targets += list(targets)
        expected_many += expected
    rows = wpm.slip_for(quantity, many_targets, many_loads * 1, multipass=0)
    assert len(set(many_loads)) > 5  # more loads than the tables serve: the row solver
    np.testing.assert_allclose(rows.slip, expected_many, rtol=0, atol=1e-6)


def test_a_turning_point_between_grid_cells_is_found_by_every_path():
    """A hand-made curve y = 100/3 s^3 - 40 s^2 + 15 s (y' = 100 (s - 0.3)(s - 0.5)): a
    peak of 1.8 at s = 0.3, a dip to 1.667 at 0.5, 8.33 at s = 1. Just below the peak and
    at it the target is met before 0.3; above it only after the dip."""
    a = (0.0, 15.0, -40.0, 100.0 / 3.0)
    curve = WpmCurve(a, 0.0, 1.0, soil="s", wheel="w", multipass=0, load_n=100.0,
                     quantity="dp_n", unit="N", n_points=8, rmse=0.0, line=3)
    wpm = WheelPerformanceModule([curve])
    peak = 1.8  # 15 * 0.3 - 40 * 0.09 + 100/3 * 0.027
    targets = [peak - 1e-4, peak, peak + 0.05, 0.5, peak * 2]
    expected = [_bisection(curve, t) for t in targets]
    by_rows = solve_slip([a], [0] * len(targets), targets, 0.0, 1.0)
    by_table = wpm.slip_for("dp_n", targets, 100.0)
    np.testing.assert_allclose(by_rows.slip, expected, atol=1e-6)
    np.testing.assert_allclose(by_table.slip, expected, atol=1e-6)
    assert by_rows.status.tolist() == by_table.status.tolist() == ["ok"] * 5
