"""Grouser passing frequency measured in the forces.

The grousers load the wheel periodically at ``n omega / 2 pi`` (Irani et al., J.
Terramechanics 48, 2011). Over a window of a few periods a plain spectrum resolves the
frequency only to ``1/duration``, so the peak of a zero-padded Hann-windowed FFT near the
expected frequency is refined by least squares: the frequency whose harmonic series
(``harmonics`` terms, with mean and linear trend) explains most of the signal (the
maximum-likelihood frequency of a periodic signal in white noise; Quinn & Hannan 2001).
"""

from __future__ import annotations

import numpy as np
from scipy.optimize import minimize_scalar

HARMONICS = 6
SEARCH_RATIO = 0.4   # look for the peak within +-40 % of the expected frequency


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
    """Frequency of the periodic load near ``expected_hz`` (FFT peak refined by least squares)."""
    t_s, y = np.asarray(t_s, float), np.asarray(y, float)
    ok = np.isfinite(y)
    if ok.sum() < 16 or not np.isfinite(expected_hz) or expected_hz <= 0:
        return float("nan")
    dt = float(np.median(np.diff(t_s)))
    x = np.interp(t_s, t_s[ok], y[ok])
    x = (x - np.polyval(np.polyfit(t_s, x, 1), t_s)) * np.hanning(x.size)
    nfft = 1 << int(np.ceil(np.log2(16 * x.size)))
    power = np.abs(np.fft.rfft(x, nfft)) ** 2
    freq = np.fft.rfftfreq(nfft, dt)
    band = np.abs(freq - expected_hz) <= SEARCH_RATIO * expected_hz
    if not band.any():
        return float("nan")
    coarse = float(freq[band][np.argmax(power[band])])
    width = 1.0 / (t_s[-1] - t_s[0])
    result = minimize_scalar(lambda f: harmonic_fit(t_s, y, f, harmonics)["rss"],
                             bounds=(max(coarse - width, 1e-6), coarse + width), method="bounded",
                             options={"xatol": 1e-5 * expected_hz})
    return float(result.x)
