"""Derived signals against synthetic signals with known answers."""

from __future__ import annotations

import math

import numpy as np
import pytest

from ingest import derive
from ingest.timebase import common_grid, grid_mask, stream_timing, to_grid


def _rate_from_native(t, x, grid_rate=1000.0):
    """Native samples -> uniform grid -> windowed Savitzky-Golay derivative (as read_run does)."""
    timing = stream_timing(t)
    grid = np.arange(0, t[-1], 1 / grid_rate)
    y = to_grid(t, x, grid, grid_mask(t, timing, grid))
    stats = derive.encoder_noise(t, x)
    window_s = derive.choose_window_s(stats)
    rate, window = derive.savgol_derivative(y, grid_rate, window_s)
    return grid, rate, window_s, stats


def test_quantised_ramp_gives_known_omega():
    omega, step = 1.5, 2 * math.pi / 2048
    t = np.arange(0, 20, 1 / 500)
    angle = np.floor(omega * t / step) * step
    grid, rate, window_s, stats = _rate_from_native(t, angle)
    assert stats["quantisation_step"] == pytest.approx(step, rel=1e-9)
    assert window_s == pytest.approx(step / (derive.TARGET_REL_ERROR * omega), rel=1e-3)
    inner = (grid > 1) & (grid < 19)
    error = rate[inner] / omega - 1
    assert abs(np.mean(error)) < 1e-4
    assert np.max(np.abs(error)) < 0.02


def test_noisy_position_error_matches_target():
    """White noise on the position: the window is chosen for ~1 % velocity noise; check it."""
    rng = np.random.default_rng(7)
    v, sigma = 0.1, 2e-4
    t = np.arange(0, 60, 1 / 1000)
    x = v * t + rng.normal(0, sigma, len(t))
    grid, rate, window_s, stats = _rate_from_native(t, x)
    assert stats["noise_std"] == pytest.approx(sigma, rel=0.1)
    predicted = math.sqrt(12) * sigma / (window_s ** 1.5 * math.sqrt(1000)) / v
    assert predicted == pytest.approx(derive.TARGET_REL_ERROR, rel=0.05)
    inner = (grid > 2) & (grid < 58)
    relative_std = np.std(rate[inner] / v - 1)
    assert 0.5 * derive.TARGET_REL_ERROR < relative_std < 1.5 * derive.TARGET_REL_ERROR
    assert abs(np.mean(rate[inner]) / v - 1) < 1e-3


def test_varying_speed_is_followed():
    """omega(t) = 1 + 0.5 sin(0.5 t): the local quadratic fit follows it closely."""
    t = np.arange(0, 30, 1 / 200)
    angle = t - np.cos(0.5 * t) + 1.0  # d/dt = 1 + 0.5 sin(0.5 t)
    grid, rate, _, _ = _rate_from_native(t, angle)
    inner = (grid > 1) & (grid < 29)
    truth = 1 + 0.5 * np.sin(0.5 * grid[inner])
    assert np.max(np.abs(rate[inner] - truth)) < 2e-3


def test_derivative_is_nan_in_gaps_and_short_segments():
    y = np.arange(1000, dtype=float) * 0.01  # slope 10 per second at 1000 Hz
    y[400:420] = np.nan
    y[600:605] = np.nan
    y[605:610] = 1.0  # a 5-sample island, shorter than the window
    y[610:620] = np.nan
    rate, window = derive.savgol_derivative(y, 1000.0, 0.021)
    assert window == 21
    assert np.isnan(rate[400:420]).all() and np.isnan(rate[600:620]).all()
    np.testing.assert_allclose(rate[:400], 10.0, rtol=1e-9)
    np.testing.assert_allclose(rate[620:], 10.0, rtol=1e-9)


@pytest.mark.parametrize("n, window", [(5, 5), (6, 5), (101, 21), (2000, 51)])
def test_savgol_slopes_match_scipy_savgol_filter(n, window):
    """The library's own Savitzky-Golay derivative, edges included, against scipy's."""
    from scipy.signal import savgol_filter

    y = np.cumsum(np.random.default_rng(n).normal(size=n)) + 50.0
    expected = savgol_filter(y, window, derive.POLYORDER, deriv=1, delta=0.004, mode="interp")
    got = derive.savgol_slopes(y, window, 0.004)
    assert np.allclose(got, expected, rtol=0, atol=1e-9 * np.abs(expected).max())


def test_slip_driving_skid_and_undefined():
    rw = np.array([0.2, 0.1, 0.0, 0.1, 0.0, 1e-5, 0.1])
    v = np.array([0.15, 0.2, 0.1, 0.1, 0.0, 0.0, -0.1])
    s = derive.slip(rw, v, eps_mps=1e-3)
    np.testing.assert_allclose(s[:4], [0.25, -0.5, -1.0, 0.0])
    assert np.isnan(s[4]) and np.isnan(s[5])  # both ~0
    assert s[6] == pytest.approx(2.0)  # sled pushed backwards: outside [-1, 1], not clipped
    # identical to the CMU authors' (Vry - Vx) / max(Vx, Vry) for positive speeds
    vry, vx = np.array([3.0, 10.0, 40.0]), np.array([10.0, 10.0, 10.0])
    np.testing.assert_allclose(derive.slip(vry, vx, 1e-9), (vry - vx) / np.maximum(vx, vry))


def test_slip_eps_from_setpoint_or_data():
    assert derive.slip_eps(0.1, np.zeros(3), np.zeros(3)) == pytest.approx(0.002)
    assert derive.slip_eps(0.0, np.full(10, 0.5), np.zeros(10)) == pytest.approx(0.01)


def test_hub_height_and_sinkage_rigid_and_flexible():
    h = derive.hub_height_m(np.array([0.2, 0.3]), 0.5, 0.3)
    np.testing.assert_allclose(h, [0.5 * (math.sin(0.2) - math.sin(0.3)), 0.0])
    hub = np.array([-0.03, -0.03])
    np.testing.assert_allclose(derive.sinkage_m(hub, None, None), [0.03, 0.03])
    # flexible: 100 N on 10 N/mm deflects 10 mm, so sinkage is 30 - 10 = 20 mm
    np.testing.assert_allclose(derive.sinkage_m(hub, np.array([100.0, 0.0]), 10.0), [0.02, 0.03])
    assert np.isnan(derive.sinkage_m(hub, None, 10.0)).all()


def test_grid_rate_is_fastest_stream_capped():
    fast = stream_timing(np.arange(0, 1, 1 / 2000))
    slow = stream_timing(np.arange(0.1, 2, 1 / 100))
    grid, rate = common_grid([fast, slow])
    assert rate == 1000.0 and grid[0] == 0.0 and grid[-1] == pytest.approx(1.99, abs=1e-9)
    grid, rate = common_grid([slow])
    assert rate == pytest.approx(100.0)


def test_stream_timing_reports_gaps_and_jitter():
    t = np.r_[np.arange(0, 1, 0.01), np.arange(1.5, 2, 0.01)]
    timing = stream_timing(t)
    assert timing.rate_hz == pytest.approx(100.0)
    assert timing.gaps == ((pytest.approx(0.99), pytest.approx(1.5)),)
    rng = np.random.default_rng(1)
    jittery = np.cumsum(rng.uniform(0.001, 0.03, 500))
    assert stream_timing(jittery).jitter > 0.5


def test_grid_mask_false_inside_gaps_including_the_first_and_last_interval():
    # median interval 0.1 s: a gap is an interval over 0.5 s; a grid point t belongs to the
    # interval t_s[i] <= t < t_s[i + 1] (hand-counted below)
    grid = np.arange(14) / 10.0  # 0.0 ... 1.3 s
    t_inner = np.array([0.0, 0.1, 0.2, 0.3, 0.9, 1.0, 1.1, 1.2, 1.3])  # gap 0.3 -> 0.9
    inner = grid_mask(t_inner, stream_timing(t_inner), grid)
    assert inner.tolist() == [True] * 3 + [False] * 6 + [True] * 5
    t_first = np.array([0.0, 0.8, 0.9, 1.0, 1.1, 1.2, 1.3])  # gap 0.0 -> 0.8
    first = grid_mask(t_first, stream_timing(t_first), grid)
    assert first.tolist() == [False] * 8 + [True] * 6
    t_last = np.array([0.0, 0.1, 0.2, 0.3, 0.4, 1.3])  # gap 0.4 -> 1.3, the last interval
    last = grid_mask(t_last, stream_timing(t_last), grid)
    assert last.tolist() == [True] * 4 + [False] * 10
