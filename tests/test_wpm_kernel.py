"""Issue 37.1: the WPM runtime's compiled queries at random continuous loads give today's
answers -- the curve, its 95 % bands and the inverse -- on many random queries: at and
between the tested loads, beyond them (extrapolated), on the braked branch, inside the jump
at zero slip, above the maximum and below the minimum; scalar and array calls agree; bad
input raises one line naming the keyword argument.

References: the value and bands of :func:`fitting.interpolate_loads` per load followed by
:func:`fitting.band` (the documented method computed another way: grid values interpolated
per query, refit by least squares, covariance by forward differences -- in-family, the same
method); the inverse from the real roots of ``curve - target`` found by ``numpy.roots``
(companion-matrix eigenvalues, polished by Newton) on that curve -- independent of the
kernel's root finder.
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest

from fitting import (LoadExtrapolationWarning, LoadRangeError, band, fit_results,
                     interpolate_loads)
from fitting.polynomial import horner
from wpm_export import (WheelPerformanceModule, WpmCurve, WpmFormatError, WpmSelectionError,
                        inputs_sha256, write_wpm_csv)
from test_fitting_synthetic import model_results_table

QUANTITIES = ("dp_n", "torque_nm", "sinkage_m", "resistance_n")
RELATIVE = 1e-9  # the tolerance


@pytest.fixture(scope="module", params=[(70.0, 180.0, 300.0), (60.0, 110.0, 180.0, 300.0),
                                        (70.0, 300.0)], ids=["3 loads", "4 loads", "2 loads"])
def wpm(request, tmp_path_factory):
    table = model_results_table(loads_n=request.param, multipass=(0, 1), seed=7)
    path = tmp_path_factory.mktemp("wpm") / "wpm.csv"
    write_wpm_csv(fit_results(table), path, inputs_sha256(table), "test")
    return WheelPerformanceModule.load(path)


def _queries(wpm, rng, n: int):
    """Random loads: uniform over the tested span and 20 % beyond it on each side."""
    curves = wpm._by_load("dp_n", {"multipass": 0, "soil": None, "wheel": None})
    lo, hi = min(curves), max(curves)
    loads = rng.uniform(lo - 0.2 * (hi - lo), hi + 0.2 * (hi - lo), n)
    return np.clip(loads, 5.0, None), lo, hi


def _reference_curves(wpm, quantity, loads):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", LoadExtrapolationWarning)
        return interpolate_loads(wpm._by_load(quantity, {"multipass": 0, "soil": None,
                                                         "wheel": None}), loads,
                                 allow_extrapolation=True)


@pytest.mark.parametrize("quantity", QUANTITIES)
def test_values_and_bands_at_random_loads_are_todays_within_1e_9(wpm, quantity):
    rng = np.random.default_rng(3)
    loads, _, _ = _queries(wpm, rng, 150)
    slips = rng.uniform(-0.1, 0.6, loads.size)
    slips[:10] = 0.0  # zero slip belongs to the driven side
    reference = _reference_curves(wpm, quantity, loads)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", LoadExtrapolationWarning)
        vector = wpm.band(quantity, slips, loads, multipass=0, allow_extrapolation=True)
        for i, (s, w) in enumerate(zip(slips, loads)):
            curve = reference.curve(i)
            mean, conf, pred = band(curve, s)
            scale = np.max(np.abs(curve.evaluate(np.linspace(curve.slip_min, curve.slip_max,
                                                             101))))
            one = wpm.band(quantity, s, w, multipass=0, allow_extrapolation=True)
            assert abs(one[0] - mean) <= RELATIVE * scale, (w, s)
            assert one[1] == pytest.approx(float(conf), rel=RELATIVE)
            assert one[2] == pytest.approx(float(pred), rel=RELATIVE)
            assert tuple(float(v[i]) for v in vector) == one  # one kernel for both
    assert np.isfinite(vector[1]).all() and (vector[2] >= vector[1]).all()


def _real_roots(a, level, lo, hi):
    """Real roots of ``sum a_i s**i - level`` in [lo, hi] by numpy.roots, Newton-polished."""
    c = np.array(a, dtype=float)
    c[0] -= level
    roots = np.roots(c[::-1])
    out = []
    for r in roots[np.abs(roots.imag) <= 1e-7 * (1 + np.abs(roots.real))].real:
        for _ in range(3):
            d = horner(c[1:] * np.arange(1, c.size), r)
            r = r - horner(c, r) / d if d else r
        if lo - 1e-12 <= r <= hi + 1e-12:
            out.append(float(min(max(r, lo), hi)))
    return sorted(out)


def _reference_inverse(curve, target):
    """(slip, value, status, margin): the smallest slip where the curve equals ``target``
    (docs/wpm-csv.md, "The inverse"), from its sides' real roots; ``margin``: the target's
    distance to the nearest extreme value (where the answer jumps with rounding)."""
    a = np.array(curve.coefficients)
    braked = a.copy()
    braked[:2] += (curve.step_below_zero, curve.slope_below_zero)
    lo, hi = curve.slip_min, curve.slip_max
    two = lo < 0 <= hi and (curve.step_below_zero or curve.slope_below_zero)
    sides = [(braked, lo, 0.0), (a, 0.0, hi)] if two else [(a if hi >= 0 else braked, lo, hi)]
    extremes = []
    for poly, u, v in sides:
        turns = _real_roots(poly[1:] * np.arange(1, poly.size), 0.0, u, v)
        extremes += [float(horner(poly, x)) for x in [u, v, *turns]]
    top, bottom = max(extremes), min(extremes)
    margin = min(abs(target - e) for e in extremes)
    if target > top:
        return 1.0, top, "above_max", margin
    if target < bottom:
        return np.nan, bottom, "below_min", margin
    for k, (poly, u, v) in enumerate(sides):
        roots = _real_roots(poly, target, u, v)
        if roots:
            return roots[0], target, "ok", margin
        if two and k == 0:
            ends = sorted([float(horner(braked, 0.0)), float(a[0])])
            if ends[0] < target < ends[1]:
                return 0.0, target, "at_step", margin
    raise AssertionError("a target between the extremes has a root")


@pytest.mark.parametrize("quantity", QUANTITIES)
def test_the_inverse_at_random_loads_is_the_smallest_root_within_1e_9(wpm, quantity):
    """Targets over each curve's range and 10 % beyond (above_max, below_min) and inside the
    jump at zero slip; slips compared within 1e-9 relative (with a floor of 1e-9 of the slip
    range where the slip is near 0) unless the target sits within 1e-9 of the curve's scale
    of an extreme value, where the smallest root jumps between branches with rounding."""
    rng = np.random.default_rng(5)
    loads, _, _ = _queries(wpm, rng, 150)
    reference = _reference_curves(wpm, quantity, loads)
    grid = np.linspace(reference.slip_min, reference.slip_max, 201)
    targets, expected, statuses, stepped = [], [], set(), False
    for i in range(loads.size):
        curve = reference.curve(i)
        values = curve.evaluate(grid)
        span = np.ptp(values)
        stepped |= bool(curve.step_below_zero)
        if i % 5 == 0 and curve.step_below_zero:  # inside the jump
            ends = float(horner(np.array(curve.coefficients) + np.r_[curve.step_below_zero,
                                                                  np.zeros(curve.degree)],
                                0.0)), curve.coefficients[0]
            t = float(rng.uniform(min(ends), max(ends)))
        else:
            t = float(rng.uniform(values.min() - 0.1 * span, values.max() + 0.1 * span))
        targets.append(t)
        expected.append((_reference_inverse(curve, t), np.max(np.abs(values))))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", LoadExtrapolationWarning)
        vector = wpm.slip_for(quantity, targets, loads, multipass=0, allow_extrapolation=True)
        checked = 0
        for i, ((slip, value, status, margin), scale) in enumerate(expected):
            one = wpm.slip_for(quantity, targets[i], loads[i], multipass=0,
                                   allow_extrapolation=True)
            assert one == (float(vector.slip[i]), float(vector.value[i]),
                           str(vector.status[i])) or np.isnan(one[0])
            if margin < RELATIVE * scale:
                continue
            checked += 1
            statuses.add(status)
            assert one[2] == status, (loads[i], targets[i])
            if status == "below_min":
                assert np.isnan(one[0])
            else:
                assert abs(one[0] - slip) <= RELATIVE * max(abs(slip), 0.7), (loads[i], one)
            assert abs(one[1] - value) <= RELATIVE * scale
    assert checked > 140 and {"ok", "above_max", "below_min"} <= statuses
    if stepped and quantity == "dp_n":  # DP rises through its jump: at_step
        assert "at_step" in statuses


@pytest.mark.parametrize("quantity", ["dp_n", "sinkage_m"])
def test_slip_bands_at_random_loads_are_the_value_bands_over_the_slope(wpm, quantity):
    """``slip_band``: the reference curve's bands over ``|dy/ds|`` there (docs/wpm-csv.md,
    "Uncertainty"), within 1e-9 relative, scalar and arrays alike; NaN slips stay NaN."""
    rng = np.random.default_rng(13)
    loads, lo, hi = _queries(wpm, rng, 60)
    loads = np.clip(loads, lo, hi)
    slips = rng.uniform(-0.1, 0.6, loads.size)
    reference = _reference_curves(wpm, quantity, loads)
    conf, pred = wpm.slip_band(quantity, slips, loads, multipass=0)
    for i in range(loads.size):
        curve = reference.curve(i)
        _, c, p = band(curve, slips[i])
        a = np.array(curve.coefficients)
        slope = abs(horner(a[1:] * np.arange(1, a.size), slips[i])
                    + (curve.slope_below_zero if slips[i] < 0 else 0.0))
        assert conf[i] == pytest.approx(c / slope, rel=RELATIVE)
        assert pred[i] == pytest.approx(p / slope, rel=RELATIVE)
        one = wpm.slip_band(quantity, float(slips[i]), float(loads[i]), multipass=0)
        assert (float(one[0]), float(one[1])) == (conf[i], pred[i])
    nan = wpm.slip_band(quantity, [np.nan, 0.2], 150.0, multipass=0)
    assert np.isnan(nan[0][0]) and np.isfinite(nan[0][1])


def test_read_only_arrays_are_answered(wpm):
    """Arrays from pandas (copy-on-write) or broadcasting are read-only views."""
    slips, loads = np.array([0.1, 0.3]), np.array([100.0, 200.0])
    slips.flags.writeable = loads.flags.writeable = False
    expected = wpm.at_slip(slips.copy(), loads.copy(), multipass=0)
    np.testing.assert_array_equal(wpm.at_slip(slips, loads, multipass=0)["dp_n"],
                                  expected["dp_n"])
    found = wpm.slip_for("dp_n", slips * 50, loads, multipass=0)
    assert found.reached.all()


def test_curves_without_uncertainty_give_nan_bands_and_their_values():
    """A file without the uncertainty columns (older swtlab, other tools): unknown, not 0."""
    rows = [WpmCurve((1.0 * k, 100.0, -50.0, 10.0), -0.2, 0.6, soil="s", wheel="w",
                     multipass=0, load_n=load, quantity="dp_n", unit="N", n_points=8, rmse=0.0,
                     line=3, step_below_zero=-2.0, slope_below_zero=5.0)
            for k, load in enumerate((100.0, 200.0, 300.0))]
    wpm = WheelPerformanceModule(rows)
    value, conf, pred = wpm.band("dp_n", -0.1, 150.0)
    expected = interpolate_loads({c.load_n: c for c in rows}, [150.0]).curve(0)
    assert value == pytest.approx(float(expected.evaluate(-0.1)), rel=RELATIVE)
    assert np.isnan(conf) and np.isnan(pred)
    assert np.isnan(wpm.slip_band("dp_n", 0.2, 150.0)).all()


def test_numbers_give_floats_and_arrays_give_arrays_with_the_same_answers(wpm):
    """A query of numbers (Python's or NumPy's: a simulator's time step) gives floats and the
    status text, equal to the array call's element (one kernel for both); 0-d arrays give
    0-d arrays; repeated loads (which reuse the cuts in the array kernel) and fresh ones."""
    rng = np.random.default_rng(9)
    loads = np.repeat(rng.uniform(80.0, 290.0, 20), 5)
    targets = rng.uniform(-20.0, 60.0, loads.size)
    slips = rng.uniform(-0.1, 0.6, loads.size)
    found = wpm.slip_for("dp_n", targets, loads, multipass=1)
    bands = wpm.band("dp_n", slips, loads, multipass=1)
    for i in range(loads.size):
        for target, load in ((float(targets[i]), float(loads[i])), (targets[i], loads[i])):
            one = wpm.slip_for("dp_n", target, load, multipass=1)
            assert (type(one.slip), type(one.value), type(one.status)) == (float, float, str)
            assert one.status == found.status[i] and one.value == found.value[i]
            assert one.slip == found.slip[i] or (np.isnan(one.slip) and np.isnan(found.slip[i]))
            assert one.reached == found.reached[i]
        forward = wpm.band("dp_n", float(slips[i]), float(loads[i]), multipass=1)
        assert forward == tuple(float(a[i]) for a in bands)
        assert all(type(v) is float for v in forward)
    zero_d = wpm.slip_for("dp_n", np.array(targets[0]), loads[0], multipass=1)
    assert zero_d.slip.shape == () and str(zero_d.status) == found.status[0]
    assert wpm.slip_for("dp_n", 10, 150, multipass=1) == wpm.slip_for("dp_n", 10.0, 150.0,
                                                                       multipass=1)
    slip, value, status = wpm.slip_for("dp_n", 10.0, 150.0, multipass=1)  # unpacks
    assert value == 10.0 and status == "ok" and 0.0 < slip < 0.6


def test_the_0_14_names_are_the_same_calls():
    assert WheelPerformanceModule.slip_for_one is WheelPerformanceModule.slip_for
    assert WheelPerformanceModule.band_one is WheelPerformanceModule.band


@pytest.mark.parametrize("call, match", [
    (lambda w: w.slip_for("dp_n", float("nan"), 120.0, multipass=0),
     r"^target=nan: dp_n queries need a finite number$"),
    (lambda w: w.slip_for("dp_n", [1.0, np.inf], 120.0, multipass=0),
     r"^target=inf: dp_n queries need a finite number$"),
    (lambda w: w.band("torque_nm", float("nan"), 120.0, multipass=0),
     r"^slip=nan: torque_nm queries need a finite number$"),
    (lambda w: w.at_slip([0.1, np.nan], 120.0, multipass=0),
     r"^slip=nan: dp_n queries need a finite number$"),
    (lambda w: w.slip_for("dp_n", 1.0, float("nan"), multipass=0),
     r"^load_n=nan: the wheel load must be a finite number > 0 N$"),
    (lambda w: w.band("dp_n", 0.1, [120.0, -5.0], multipass=0),
     r"^load_n=-5.0: the wheel load must be a finite number > 0 N$"),
    (lambda w: w.slip_for("dp_n", 1.0, 500.0, multipass=0),
     r"^load_n=500 N is outside the tested loads \(\d+-300 N\) of dp_n; pass "
     r"allow_extrapolation=True to extrapolate linearly from the two nearest loads$"),
    (lambda w: w.curve("dp_n", 20.0, multipass=0), r"^load_n=20 N is outside the tested"),
    (lambda w: w.slip_for("dp_n", "25", 120.0, multipass=0),
     r"^target='25', load_n=120.0: numbers expected$"),
    (lambda w: w.slip_for("dp_n", np.float64("nan"), 120.0, multipass=0),  # NumPy's number
     r"^target=nan: dp_n queries need a finite number$"),
    (lambda w: w.band("dp_n", 0.1, np.int64(0), multipass=0),  # printed as the C library does
     r"^load_n=0.0: the wheel load must be a finite number > 0 N$"),
    (lambda w: w.band("dp_n", [0.1, 0.2], ["120", "130"], multipass=0),
     r"^slip=<list of float64>, load_n=<list of <U3>: numbers expected$"),
    (lambda w: w.slip_for("dp_n", 1.0, 120.0, wheel="mars_wheel"),
     r"^no curves for wheel='mars_wheel' in .*wpm.csv; choices: "
     r"soil='bb2_sand', wheel='bb2', multipass=0; soil='bb2_sand', wheel='bb2', multipass=1$"),
    (lambda w: w.band("drawbar", 0.1, 120.0, multipass=0),
     r"^quantity='drawbar': no such curves for soil='bb2_sand', wheel='bb2', multipass=0 in "
     r".*; it has dp_n, torque_nm, sinkage_m, resistance_n, dp_over_w$"),
])
def test_bad_queries_raise_one_line_naming_the_keyword(wpm, call, match):
    with pytest.raises((ValueError, TypeError)) as raised:
        call(wpm)
    assert "\n" not in str(raised.value)
    assert raised.match(match)
    if match.startswith("^load_n"):
        assert isinstance(raised.value, LoadRangeError)
    if "choices" in match or "quantity=" in match:
        assert isinstance(raised.value, WpmSelectionError)


def test_extrapolated_loads_warn_once_per_call_naming_the_load(wpm):
    with pytest.warns(LoadExtrapolationWarning, match=r"^1 load\(s\) outside the tested loads "
                                                      r"\(.*\) of dp_n, e.g. load_n=400 N"):
        wpm.slip_for("dp_n", 10.0, 400.0, multipass=0, allow_extrapolation=True)
    with pytest.warns(LoadExtrapolationWarning, match=r"^2 load\(s\) outside"):
        wpm.band("dp_n", 0.2, [400.0, 120.0, 10.0], multipass=0, allow_extrapolation=True)


def test_a_file_of_another_format_version_is_refused_naming_file_and_line(wpm, tmp_path):
    text = open(wpm.source, encoding="utf-8").read().replace("swtlab-wpm/1", "swtlab-wpm/2")
    (tmp_path / "wpm.csv").write_text(text, encoding="utf-8")
    with pytest.raises(WpmFormatError, match=r"^.*wpm.csv:\d+: format 'swtlab-wpm/2', this "
                                             r"reader reads 'swtlab-wpm/1'$"):
        WheelPerformanceModule.load(tmp_path / "wpm.csv")
