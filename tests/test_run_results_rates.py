"""Wheel speed, travel velocity and slip from the window's displacements (run_results.rates)
against synthetic encoders whose truth is set by hand (the second rig's low-speed runs
through the whole chain: tests/test_uncertainty_coverage.py, bench coverage).

The synthetic encoders are the issue's case: a 14-bit wheel encoder and a 10 um sled encoder
at 500 Hz, sled at 10.3 mm/s (not a whole number of sled steps a sample), set slip 0.05, so
the wheel turns about half a count per sample. The mean of per-sample ratios ``1 - v/(r w)``
of finite differences is biased there (Jensen's inequality); the ratio of the displacements
is not, and its quantisation term (the window's end values from local lines) bounds what
is left.
"""

from __future__ import annotations

import math
from types import SimpleNamespace

import numpy as np
import pandas as pd
import pytest

from run_results.rates import slip_sensitivities, timing_scatter_s, window_rate, window_slip

RADIUS_M, SLIP, V_MPS, RATE_HZ = 0.1, 0.05, 0.0103, 500.0
WHEEL_STEP = 2 * math.pi / 2**14
SLED_STEP = 1e-5


def _run(rng, jitter_s: float = 0.0, duration_s: float = 20.0, slip: float = SLIP,
         logged_rate: bool = False):
    """A run whose wheel and sled encoders read positions floored to their steps, at true
    sample instants with a random start phase (stamps exact, ``+- jitter_s`` scattered)."""
    omega = V_MPS / (RADIUS_M * (1 - slip))
    t = (np.arange(int(duration_s * RATE_HZ)) + rng.uniform()) / RATE_HZ
    stamps = t + rng.normal(0, jitter_s, t.size)
    angle0, x0 = rng.uniform(0, 1), rng.uniform(0, 1)
    wheel = np.floor((angle0 + omega * t) / WHEEL_STEP) * WHEEL_STEP
    sled = np.floor((x0 + V_MPS * t) / SLED_STEP) * SLED_STEP
    streams = {"/wheel/encoder": pd.DataFrame({"t_s": stamps, "wheel_angle_rad": wheel}),
               "/sled/encoder": pd.DataFrame({"t_s": stamps, "sled_position_m": sled})}
    if logged_rate:  # a logged sled speed read to 0.01 mm/s, noisy by 0.04 mm/s
        v = np.round((V_MPS + rng.normal(0, 4e-5, t.size)) / 1e-5) * 1e-5
        streams["/sled/encoder"] = pd.DataFrame({"t_s": stamps, "sled_velocity_mps": v})
    meta = SimpleNamespace(wheel=SimpleNamespace(radius_m=RADIUS_M))
    return SimpleNamespace(streams=streams, metadata=meta), omega


def _slip(run, start_s=0.5, end_s=19.5):
    omega = window_rate(run, "wheel_omega_radps", start_s, end_s, float("nan"))
    v = window_rate(run, "travel_velocity_mps", start_s, end_s, float("nan"))
    return window_slip(omega, v, RADIUS_M, float("nan")), omega, v


def test_the_mean_of_per_sample_ratios_is_biased_where_the_displacements_are_not():
    """Per-sample ratios of 0-1 count differences, smoothed over 20 ms: biased low by about
    ``(1 - s) var_rel(r w)`` (measured 0.0428 for 0.05; 0.0495 over 50 ms); the
    displacements give 0.05 to within their quantisation."""
    rng = np.random.default_rng(1)
    run, _ = _run(rng)
    t = run.streams["/wheel/encoder"]["t_s"].to_numpy()
    width = int(0.02 * RATE_HZ)
    kernel = np.ones(width) / width
    w = np.convolve(np.diff(run.streams["/wheel/encoder"]["wheel_angle_rad"].to_numpy())
                    / np.diff(t), kernel, "valid")
    v = np.convolve(np.diff(run.streams["/sled/encoder"]["sled_position_m"].to_numpy())
                    / np.diff(t), kernel, "valid")
    ratio_mean = float(np.mean(1 - v / (RADIUS_M * w)))
    assert ratio_mean < SLIP - 0.002
    s, _, _ = _slip(run)
    assert abs(s.stats.mean - SLIP) < 3e-4


def test_the_quantisation_term_bounds_the_end_values_error():
    """200 runs of random encoder phase and window length (a whole number of samples of a
    fixed rate would fix the counts' fractional part over the window): no bias (mean z near
    0), and the quantisation term, which takes the readings' errors as independent, bounds
    the error of the end lines' values: a moving encoder's readings err by a sawtooth, whose
    mean over the fit's counts errs less (z spread measured 0.33); the budget's interval
    (quantisation and statistical terms) covers every run."""
    rng = np.random.default_rng(2)
    z, covered = [], []
    for _ in range(200):
        run, _ = _run(rng)
        s, _, _ = _slip(run, end_s=rng.uniform(10.0, 19.5))
        assert s.timing_u < 1e-12
        error = s.stats.mean - SLIP
        z.append(error / s.quantisation_u)
        covered.append(abs(error) <= 1.96 * math.hypot(s.quantisation_u, s.stats.se))
    assert abs(np.mean(z)) < 0.1
    assert 0.1 < np.std(z) < 1.0
    assert np.mean(covered) >= 0.97


def _leverage(t: np.ndarray, at: float) -> float:
    """``[1, at] (X^T X)^-1 [1, at]^T`` of a straight-line fit to the times ``t``."""
    design = np.column_stack([np.ones(t.size), t])
    point = np.array([1.0, at])
    return float(point @ np.linalg.inv(design.T @ design) @ point)


def _end_leverages(t: np.ndarray, start_s: float, end_s: float) -> float:
    half = (end_s - start_s) / 20 / 2
    first = t[(t >= start_s) & (t < start_s + half)]
    last = t[(t > end_s - half) & (t <= end_s)]
    return _leverage(first, start_s) + _leverage(last, end_s)


def test_quantisation_of_a_window_rate_by_hand():
    """``(q/sqrt(12)) sqrt(h_0 + h_B) / T`` with the sled's 10 um step, ``h`` the leverages of
    the window's two end lines (half a span of samples each, one-sided) at the window's ends,
    from the design matrix."""
    run, _ = _run(np.random.default_rng(3))
    v = window_rate(run, "travel_velocity_mps", 2.0, 12.0, 0.0)
    t = run.streams["/sled/encoder"]["t_s"].to_numpy()
    expected = SLED_STEP / math.sqrt(12) * math.sqrt(_end_leverages(t, 2.0, 12.0)) / 10.0
    assert v.quantisation_u == pytest.approx(expected, rel=1e-6)
    assert v.stats.mean == pytest.approx(V_MPS, abs=3 * v.quantisation_u)


def test_time_stamp_scatter_is_measured_and_enters_as_the_timing_term():
    """Stamps scattered by 200 us: measured within 5 %; the term is ``|rate| sigma_t
    sqrt(h_0 + h_B) / T`` (the end lines' leverages at the window's ends)."""
    rng = np.random.default_rng(4)
    run, omega = _run(rng, jitter_s=2e-4)
    t = run.streams["/wheel/encoder"]["t_s"].to_numpy()
    assert timing_scatter_s(t) == pytest.approx(2e-4, rel=0.05)
    w = window_rate(run, "wheel_omega_radps", 0.5, 19.5, 0.0)
    expected = omega * 2e-4 * math.sqrt(_end_leverages(t, 0.5, 19.5)) / 19.0
    assert w.timing_u == pytest.approx(expected, rel=0.06)


def test_a_logged_rate_is_integrated_and_its_rounding_dithered_away():
    """A logged speed (0.01 mm/s steps, 0.04 mm/s noise): the window rate is its time-weighted
    mean, its quantisation term ~0 (the noise dithers four steps), and the statistical term
    its batch SE (white: about ``0.04 mm/s / sqrt(n)``)."""
    rng = np.random.default_rng(5)
    run, _ = _run(rng, logged_rate=True)
    v = window_rate(run, "travel_velocity_mps", 0.5, 19.5, 0.0)
    frame = run.streams["/sled/encoder"]
    inside = frame[(frame.t_s >= 0.5) & (frame.t_s <= 19.5)]
    assert v.source == "sled_velocity_mps"
    assert v.stats.mean == pytest.approx(inside["sled_velocity_mps"].mean(), abs=2e-8)
    assert v.quantisation_u < 1e-12 and v.timing_u == 0.0
    white = 4e-5 / math.sqrt(len(inside))
    assert 0.3 * white < v.stats.se < 2.5 * white


@pytest.mark.parametrize(("surface", "velocity"), [(0.012, 0.01), (0.008, 0.01)])
def test_slip_sensitivities_match_finite_differences(surface, velocity):
    """Driving ``s = 1 - v/(r w)`` and skid ``s = r w/v - 1``."""
    def spec(a, b):
        return (a - b) / max(a, b)
    h = 1e-9
    c_surface, c_v = slip_sensitivities(surface, velocity)
    assert c_surface == pytest.approx((spec(surface + h, velocity) - spec(surface - h, velocity))
                                      / (2 * h), rel=1e-5)
    assert c_v == pytest.approx((spec(surface, velocity + h) - spec(surface, velocity - h))
                                / (2 * h), rel=1e-5)


def test_skid_slip_from_displacements():
    """A towed-like skid, ``s = -0.1``: ``r w = v (1 + s)``."""
    rng = np.random.default_rng(6)
    run, _ = _run(rng, slip=0.0)
    omega = V_MPS * 0.9 / RADIUS_M
    t = run.streams["/wheel/encoder"]["t_s"].to_numpy()
    run.streams["/wheel/encoder"]["wheel_angle_rad"] = np.floor(omega * t / WHEEL_STEP) * WHEEL_STEP
    s, _, _ = _slip(run)
    assert s.stats.mean == pytest.approx(-0.1, abs=4 * s.quantisation_u)
