"""Grouser passing frequency measured in the forces.

The grousers load the wheel periodically at ``n omega / 2 pi`` (Irani et al., J.
Terramechanics 48, 2011). Over a window of a few periods a plain spectrum resolves the
frequency only to ``1/duration``, so the frequency is found by least squares: the one whose
harmonic series (``harmonics`` terms, with mean and linear trend) explains most of the signal
(the maximum-likelihood frequency of a periodic signal in white noise; Quinn & Hannan 2001).
"""

from __future__ import annotations

import numpy as np
from scipy.optimize import minimize_scalar

HARMONICS = 6
SEARCH_RATIO = 0.4   # look for the frequency within +-40 % of the expected one
MAX_GRID = 2000      # grid points over the band at most (a window of ~1000 periods)
GRID_SAMPLES_PER_CYCLE = 16  # block means per cycle of the highest harmonic in the grid stage


def _design(t_s: np.ndarray, frequency_hz: float, harmonics: int) -> np.ndarray:
    phase = 2.0 * np.pi * frequency_hz * (t_s - t_s[0])[:, None] * np.arange(1, harmonics + 1)
    tc = (t_s - t_s.mean())[:, None]
    return np.hstack([np.ones_like(tc), tc, np.cos(phase), np.sin(phase)])


def harmonic_fit(t_s, y, frequency_hz: float, harmonics: int = HARMONICS) -> dict:
    """Least-squares mean + trend + harmonic series at ``frequency_hz`` (NaNs dropped)."""
    t_s, y = np.asarray(t_s, float), np.asarray(y, float)
    ok = np.isfinite(y)
    a = _design(t_s[ok], frequency_hz, harmonics)
    coef = np.linalg.solve(a.T @ a, a.T @ y[ok])   # normal equations: 2k+2 unknowns
    return {"coef": coef, "rss": float(np.sum((y[ok] - a @ coef) ** 2)), "harmonics": harmonics}


def measure_frequency_hz(t_s, y, expected_hz: float, harmonics: int = HARMONICS) -> float:
    """Frequency of the periodic load near ``expected_hz``: the least-squares frequency of a
    ``harmonics``-term series with mean and trend, searched over the whole band first.

    The residual sum of squares has one basin per ``1/(harmonics T)`` over a window of length
    ``T``; a local search started from a spectral peak can end in a side basin when the window
    holds few periods (two grouser periods of a still-settling drawbar pull gave 0.170 Hz for
    0.200 Hz). So the RSS is evaluated on a grid of step ``1/(4 harmonics T)`` over
    ``+-SEARCH_RATIO`` and the best grid point refined by bounded Brent within one step. The
    grid runs on block means of at least ``GRID_SAMPLES_PER_CYCLE`` per cycle of the highest
    harmonic (enough to place the basin; the refinement uses every sample).
    """
    t_s, y = np.asarray(t_s, float), np.asarray(y, float)
    ok = np.isfinite(y)
    if ok.sum() < 16 or not np.isfinite(expected_hz) or expected_hz <= 0:
        return float("nan")
    t_s, y = t_s[ok], y[ok]
    step = 1.0 / (4.0 * harmonics * (t_s[-1] - t_s[0]))
    lo, hi = (1.0 - SEARCH_RATIO) * expected_hz, (1.0 + SEARCH_RATIO) * expected_hz
    grid = np.linspace(lo, hi, min(MAX_GRID, int(np.ceil((hi - lo) / step)) + 1))
    samples_per_cycle = 1.0 / (hi * harmonics * float(np.median(np.diff(t_s))))
    block = max(1, int(samples_per_cycle // GRID_SAMPLES_PER_CYCLE))
    n = t_s.size // block * block
    t_grid = t_s[:n].reshape(-1, block).mean(axis=1)
    y_grid = y[:n].reshape(-1, block).mean(axis=1)
    rss = [harmonic_fit(t_grid, y_grid, f, harmonics)["rss"] for f in grid]
    best = float(grid[int(np.argmin(rss))])
    width = grid[1] - grid[0]
    result = minimize_scalar(lambda f: harmonic_fit(t_s, y, f, harmonics)["rss"],
                             bounds=(max(best - width, 1e-6), best + width), method="bounded",
                             options={"xatol": 1e-5 * expected_hz})
    return float(result.x)
