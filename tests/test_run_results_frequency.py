"""Grouser frequency on signals written here, not by the virtual testbed: a settling drawbar
pull with a non-sinusoidal grouser wave over few periods, where a local search from a spectral
peak ended in a side basin of the least-squares fit (0.170 Hz for 0.200 Hz)."""

from __future__ import annotations

import numpy as np
import pytest

from run_results.oscillation import measure_frequency_hz


def _settling_lugged_dp(rng, frequency_hz, periods, rate_hz=40.0, tau_s=30.0):
    """Saturating rise with a sawtooth-like lug wave (grouser entry/exit) and white noise."""
    t = np.arange(0.0, periods / frequency_hz, 1.0 / rate_hz) + 28.0
    phase = (frequency_hz * t + rng.uniform()) % 1.0
    lug = 5.0 * (phase - 0.5) - 3.0 * np.exp(-((phase - 0.8) / 0.07) ** 2)
    rise = 20.0 - 17.0 * np.exp(-t / tau_s)
    return t, rise + lug + rng.normal(0.0, 0.4, t.size)


@pytest.mark.parametrize("periods", [2.0, 3.0, 6.0, 20.0])
def test_frequency_within_two_percent_over_few_periods(periods):
    rng = np.random.default_rng(7)
    errors = []
    for _ in range(20):
        f = rng.uniform(0.1, 0.5)
        t, y = _settling_lugged_dp(rng, f, periods)
        expected = f * rng.uniform(0.85, 1.15)  # n omega/2 pi known only roughly
        errors.append(measure_frequency_hz(t, y, expected) / f - 1.0)
    assert np.max(np.abs(errors)) < 0.02, np.round(errors, 4)


def test_too_short_or_no_expectation_gives_nan():
    t = np.linspace(0, 1, 10)
    assert np.isnan(measure_frequency_hz(t, np.sin(t), 0.2))
    assert np.isnan(measure_frequency_hz(np.linspace(0, 10, 100), np.ones(100), float("nan")))
