"""Statistical inefficiency of a correlated series: the factor by which it inflates var(mean).

``g = 1 + 2 sum_k rho_k`` (integrated autocorrelation time in samples, Sokal 1997,
"Monte Carlo methods in statistical mechanics"), summed with Geyer's (1992, Stat. Sci. 7,
473) initial positive sequence: pairs ``rho_2m + rho_2m+1`` are added while positive,
made monotone non-increasing. The standard error of the mean is ``s sqrt(g/n)``, and
``n_eff = n/g`` (Flyvbjerg & Petersen 1989 give the equivalent blocking estimate).
"""

from __future__ import annotations

import numpy as np
from scipy import fft


def autocorrelation(x: np.ndarray) -> np.ndarray:
    """Normalised autocorrelation ``rho_k`` for k = 0..n-1 (FFT, biased estimator)."""
    x = np.asarray(x, float) - np.mean(x)
    n = x.size
    size = fft.next_fast_len(2 * n, real=True)  # zero padding >= n: no circular wrap
    spectrum = fft.rfft(x, size)
    acov = fft.irfft(spectrum * np.conj(spectrum), size)[:n]
    return acov / acov[0] if acov[0] > 0 else np.zeros(n)


#: lags summed directly (one dot product each) before the FFT of all lags is needed: the
#: initial positive sequence of most window residuals ends within them
DIRECT_LAGS = 16


def _initial_sequence(rho: np.ndarray, every_lag: bool) -> np.ndarray | None:
    """Geyer's pairs ``rho_2m + rho_2m+1`` before the first non-positive one, made monotone;
    where none is non-positive: all pairs if ``rho`` has ``every_lag``, else None."""
    pairs = rho[: 2 * (rho.size // 2)].reshape(-1, 2).sum(axis=1)
    stop = np.flatnonzero(pairs <= 0)
    if not stop.size and not every_lag:
        return None
    return np.minimum.accumulate(pairs[: stop[0] if stop.size else pairs.size])


def statistical_inefficiency(x) -> float:
    """``g`` >= 1/n by Geyer's initial monotone positive sequence (NaNs dropped). The first
    ``DIRECT_LAGS`` autocorrelations are summed directly; all lags by FFT only when the
    sequence runs past them (same ``rho`` to rounding)."""
    x = np.asarray(x, float)
    x = x[np.isfinite(x)]
    if x.size < 4:
        return 1.0
    pairs = None
    centred = x - np.mean(x)
    if x.size > 2 * DIRECT_LAGS:
        acov = np.array([centred[:x.size - k] @ centred[k:] for k in range(DIRECT_LAGS)])
        if acov[0] > 0:
            pairs = _initial_sequence(acov / acov[0], every_lag=False)
    if pairs is None:
        pairs = _initial_sequence(autocorrelation(x), every_lag=True)
    g = -1.0 + 2.0 * pairs.sum()
    return float(max(g, 1.0 / x.size))


def standard_error(x) -> tuple[float, float, int, float]:
    """``(se, std, n, n_eff)`` of the mean of ``x`` corrected for autocorrelation."""
    x = np.asarray(x, float)
    x = x[np.isfinite(x)]
    n = x.size
    if n < 2:
        return float("nan"), float("nan"), n, float(n)
    std = float(np.std(x, ddof=1))
    g = statistical_inefficiency(x)
    return std * np.sqrt(g / n), std, n, n / g
