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


def statistical_inefficiency(x) -> float:
    """``g`` >= 1/n by Geyer's initial monotone positive sequence (NaNs dropped)."""
    x = np.asarray(x, float)
    x = x[np.isfinite(x)]
    if x.size < 4:
        return 1.0
    rho = autocorrelation(x)
    pairs = rho[: 2 * (rho.size // 2)].reshape(-1, 2).sum(axis=1)
    positive = np.flatnonzero(pairs <= 0)
    pairs = pairs[: positive[0] if positive.size else pairs.size]
    pairs = np.minimum.accumulate(pairs)
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
