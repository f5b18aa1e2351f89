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

from swtlab_base.order_stats import median

HARMONICS = 6
SEARCH_RATIO = 0.4   # look for the frequency within +-40 % of the expected one
MAX_GRID = 2000      # grid points over the band at most (a window of ~1000 periods)
GRID_SAMPLES_PER_CYCLE = 16  # block means per cycle of the highest harmonic in the grid stage


def _rotations(t_s: np.ndarray, frequency_hz: np.ndarray, evenly_spaced: bool) -> np.ndarray:
    """``exp(2 pi i f (t - t_0))``, one row per frequency. Evenly spaced frequencies: the
    first row and the step's factor by ``exp``, the other rows as running products of them
    (a complex exponential costs ~15 products; the rounding grows ~1e-16 a row)."""
    u = t_s - t_s[0]
    f = np.asarray(frequency_hz, float)
    if not evenly_spaced or f.size < 3:
        return np.exp(2j * np.pi * f[:, None] * u)
    rows = np.empty((f.size, u.size), complex)
    rows[0] = np.exp(2j * np.pi * f[0] * u)
    rows[1:] = np.exp(2j * np.pi * ((f[-1] - f[0]) / (f.size - 1)) * u)
    return np.cumprod(rows, axis=0, out=rows)


def _normal_equations(t_s: np.ndarray, y: np.ndarray, rotation: np.ndarray,
                      harmonics: int) -> tuple[np.ndarray, np.ndarray]:
    """Normal equations ``(A A^T, A y)`` of the regressors ``[1, t - mean, cos k phi,
    sin k phi]`` (k = 1..harmonics), one set per row of ``rotation`` (``exp(i phi)``): shapes
    (frequencies, 2 harmonics + 2, 2 harmonics + 2) and (frequencies, 2 harmonics + 2),
    without forming ``A``.

    Every product of two harmonics is a sum of ``S_m = sum exp(i m phi)``, m = 0..2
    harmonics (``cos j cos k = (cos(j-k) + cos(j+k))/2`` and its kin), so one complex power
    per sample, frequency and m replaces the design's ``(2 harmonics + 2)^2`` products."""
    h = harmonics
    t_c = t_s - t_s.mean()
    sums = np.empty((rotation.shape[0], 2 * h + 1), complex)      # S_m, m = 0..2h
    moments = np.empty((rotation.shape[0], h, 2), complex)       # sum (t - mean, y) e^{ikphi}
    sums[:, 0] = t_s.size
    columns = np.stack([t_c, y], axis=1).astype(complex)
    power = rotation
    for m in range(1, 2 * h + 1):
        if m > 1:
            power = power * rotation
        sums[:, m] = power.sum(axis=1)
        if m <= h:
            moments[:, m - 1] = power @ columns
    j, k = np.meshgrid(np.arange(1, h + 1), np.arange(1, h + 1), indexing="ij")
    diff, total = sums[:, np.abs(j - k)], sums[:, j + k]
    diff_imag = np.sign(k - j) * diff.imag                       # Im S_{k-j}, S_{-m} = conj S_m
    gram = np.empty((rotation.shape[0], 2 * h + 2, 2 * h + 2))
    gram[:, 0, 0], gram[:, 0, 1], gram[:, 1, 1] = t_s.size, t_c.sum(), t_c @ t_c
    gram[:, 0, 2:2 + h], gram[:, 0, 2 + h:] = sums[:, 1:h + 1].real, sums[:, 1:h + 1].imag
    gram[:, 1, 2:2 + h], gram[:, 1, 2 + h:] = moments[:, :, 0].real, moments[:, :, 0].imag
    gram[:, 2:2 + h, 2:2 + h] = 0.5 * (diff.real + total.real)   # cos j cos k
    gram[:, 2 + h:, 2 + h:] = 0.5 * (diff.real - total.real)     # sin j sin k
    gram[:, 2:2 + h, 2 + h:] = 0.5 * (total.imag + diff_imag)    # cos j sin k
    upper = np.triu_indices(2 * h + 2, 1)
    gram[:, upper[1], upper[0]] = gram[:, upper[0], upper[1]]
    rhs = np.empty((rotation.shape[0], 2 * h + 2))
    rhs[:, 0], rhs[:, 1] = y.sum(), t_c @ y
    rhs[:, 2:2 + h], rhs[:, 2 + h:] = moments[:, :, 1].real, moments[:, :, 1].imag
    return gram, rhs


def _fits(t_s: np.ndarray, y: np.ndarray, frequency_hz: np.ndarray, harmonics: int,
          evenly_spaced: bool = False) -> tuple[np.ndarray, np.ndarray]:
    """Coefficients (frequencies, 2 harmonics + 2) and residual sums of squares of the
    least-squares series at each frequency (normal equations: 2k+2 unknowns; the RSS as
    ``|y - mean|^2 - b^T coef`` of the mean-free ``y``, which the constant absorbs)."""
    mean = float(np.mean(y))
    gram, rhs = _normal_equations(t_s, y - mean,
                                  _rotations(t_s, frequency_hz, evenly_spaced), harmonics)
    coef = np.linalg.solve(gram, rhs[:, :, None])[:, :, 0]
    rss = np.sum((y - mean) ** 2) - np.sum(rhs * coef, axis=1)
    coef[:, 0] += mean
    return coef, rss


def harmonic_fit(t_s, y, frequency_hz: float, harmonics: int = HARMONICS) -> dict:
    """Least-squares mean + trend + harmonic series at ``frequency_hz`` (NaNs dropped)."""
    t_s, y = np.asarray(t_s, float), np.asarray(y, float)
    ok = np.isfinite(y)
    coef, rss = _fits(t_s[ok], y[ok], np.array([frequency_hz]), harmonics)
    return {"coef": coef[0], "rss": float(rss[0]), "harmonics": harmonics}


#: design-matrix elements per batch of grid frequencies (bounds the grid stage's memory)
BATCH_ELEMENTS = 2_000_000


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
    samples_per_cycle = 1.0 / (hi * harmonics * float(median(np.diff(t_s))))
    block = max(1, int(samples_per_cycle // GRID_SAMPLES_PER_CYCLE))
    n = t_s.size // block * block
    t_grid = t_s[:n].reshape(-1, block).mean(axis=1)
    y_grid = y[:n].reshape(-1, block).mean(axis=1)
    per_batch = max(1, BATCH_ELEMENTS // (t_grid.size * (2 * harmonics + 2)))
    rss = np.concatenate([_fits(t_grid, y_grid, grid[i:i + per_batch], harmonics, True)[1]
                          for i in range(0, grid.size, per_batch)])
    best = float(grid[int(np.argmin(rss))])
    width = grid[1] - grid[0]
    result = minimize_scalar(lambda f: harmonic_fit(t_s, y, f, harmonics)["rss"],
                             bounds=(max(best - width, 1e-6), best + width), method="bounded",
                             options={"xatol": 1e-5 * expected_hz})
    return float(result.x)
