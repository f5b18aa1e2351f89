"""The grouser-mark period of a 1-D track profile and the mark positions along it.

The fundamental is taken from the whitened spectrum (lowest significant
sub-multiple of the strongest peak); the spacing then comes from the marks
themselves: the mean mark waveform (a harmonic series fitted over the whole
profile) is matched in every one-period window, and the sub-sample mark
positions are regressed on their index (missing marks leave index gaps, doubled
or stray ones are rejected as outliers), giving the spacing and its standard error.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.ndimage import gaussian_filter1d, maximum_filter1d, median_filter

MIN_PEAK = 8.0  # a fundamental's own peak over the local median power (noise: p = 0.4 %)
HARMONICS = 8
MIN_COMB = 3.0  # prominence of a peak between a harmonic's multiples (noise: p about 0.2)
MIN_COMB_SHARE = 0.8  # of those multiples
MIN_COMB_OF_TOP = 0.15  # nor below this share of the best candidate's own prominence
MIN_PROMINENCE = 60.0  # harmonic sum of peak-over-median ratios (noise on sand: 15-50)
MIN_CORRELATION = 0.3  # a window holds a mark when it matches the mean waveform this well
MIN_FIT_MARKS = 4  # for a fit with a residual
MIN_QUADRATIC_MARKS = 12  # fewer marks: a straight line (perspective curvature not fitted)
PAD = 4  # zero padding of the profile spectrum


@dataclass(frozen=True)
class MarkFit:
    """Mark positions against mark index (units: profile samples); spacing where the scale
    applies."""

    spacing: float
    spacing_se: float
    positions: np.ndarray  # of the marks used
    indices: np.ndarray
    windows: int  # one-period windows examined
    residual_rms: float


def prominence_spectrum(profile: np.ndarray,
                        max_period: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Frequencies (cycles/sample), power of the high-passed (Gaussian of ``max_period``,
    which keeps every period in range) and Hann-windowed profile, and power over its
    running median across 24 bins (noise: the ratio exceeds r with probability
    exp(-r ln 2))."""
    x = profile - gaussian_filter1d(profile, max_period, mode="reflect")
    x *= np.hanning(profile.size)
    freq = np.fft.rfftfreq(PAD * profile.size)
    power = np.abs(np.fft.rfft(x, PAD * profile.size)) ** 2
    background = median_filter(power, 24 * PAD + 1, mode="nearest")
    return freq, power, power / (background + 1e-12 * power.max() + 1e-300)


def fundamental(profile: np.ndarray, min_period: float, max_period: float) -> tuple[float, float]:
    """Fundamental frequency (cycles/sample) of the marks and its harmonic-sum prominence.

    Every spectral peak in range at least ``MIN_PEAK`` times its background is a candidate;
    it scores the prominences of the peaks found at its first ``HARMONICS`` multiples
    (within half a bin plus a tenth of a bin per order). Sharp marks have strong harmonics,
    so the best candidate may be a harmonic; its lowest sub-multiple ``f/m`` is the
    fundamental when either it is itself a candidate scoring at least half as much
    (``m`` up to 3), or peaks of at least ``MIN_COMB`` times their background (and
    ``MIN_COMB_OF_TOP`` of the best candidate's) stand at ``MIN_COMB_SHARE`` of the
    multiples ``j f/m`` between (``j < max(2m, 8)``, not multiples of ``m``):
    narrow grooves put more power in their 4th or 5th harmonic than in the fundamental,
    while a sub-harmonic of the marks has noise there.
    """
    freq, power, ratio = prominence_spectrum(profile, max_period)
    peaks = np.flatnonzero((ratio == maximum_filter1d(ratio, 2 * PAD + 1)) & (ratio > 1))
    in_range = (freq[peaks] >= 1 / max_period) & (freq[peaks] <= 1 / min_period)
    candidates = peaks[in_range & (ratio[peaks] >= MIN_PEAK)]
    if candidates.size == 0:
        return 0.0, 0.0
    order = np.arange(1, HARMONICS + 1)

    def comb(bin_: float, orders: np.ndarray, tolerance: np.ndarray) -> np.ndarray:
        """Prominence of the nearest peak at each multiple, 0 where none is that close."""
        target = bin_ * orders  # in padded bins
        at = np.clip(np.searchsorted(peaks, target), 0, peaks.size - 1)
        before = peaks[np.maximum(at - 1, 0)]
        nearest = np.where(np.abs(peaks[at] - target) < np.abs(before - target),
                           peaks[at], before)
        return np.where(np.abs(nearest - target) <= tolerance, ratio[nearest], 0.0)

    score = np.array([comb(c, order, PAD * (0.5 + 0.1 * order)).sum() for c in candidates])
    best = int(np.argmax(score))
    top = candidates[best]
    chosen, chosen_score = float(top), score[best]
    for m in range(int(freq[top] * max_period), 1, -1):
        sub = np.flatnonzero(np.abs(candidates - top / m) <= PAD * 0.5)
        if m <= 3 and sub.size and score[sub].max() >= 0.5 * score[best]:
            j = sub[np.argmax(score[sub])]
            chosen, chosen_score = float(candidates[j]), score[j]
            break
        between = np.array([j for j in range(1, max(2 * m, HARMONICS)) if j % m])
        floor = max(MIN_COMB, MIN_COMB_OF_TOP * ratio[top])
        if np.mean(comb(top / m, between, PAD * 0.75) >= floor) >= MIN_COMB_SHARE:
            chosen = top / m
            chosen_score = comb(chosen, order, PAD * (0.5 + 0.1 * order)).sum()
            break
    i = int(np.clip(round(chosen), 1, power.size - 2))
    lo, mid, hi = np.log(power[i - 1:i + 2])
    shift = 0.5 * (lo - hi) / (lo - 2 * mid + hi) if lo - 2 * mid + hi < 0 else 0.0
    return float(freq[i] + shift * freq[1]), float(chosen_score)


def _harmonics(profile: np.ndarray, period: float, count: int) -> np.ndarray:
    """Complex coefficients c_h of ``sum_h Re(c_h exp(2 pi i h a / P))`` fitted to the profile."""
    a = np.arange(profile.size)
    h = np.arange(1, count + 1)
    arg = 2 * np.pi * np.outer(a, h) / period
    design = np.hstack([np.cos(arg), np.sin(arg), np.ones((a.size, 1))])
    coef = np.linalg.solve(design.T @ design, design.T @ profile)
    return coef[:count] - 1j * coef[count:2 * count]


def _robust_fit(k: np.ndarray, x: np.ndarray, floor: float) -> np.ndarray:
    """Inlier mask of ``x(k)`` after iterated rejection beyond 3 sigma (MAD), never tighter
    than ``floor``. It starts from a Theil-Sen line (Sen 1968, J. Am. Stat. Assoc. 63), so a
    stray mark at an end of the track cannot pull the first fit, and refits with the degree
    of the final fit (a quadratic from ``MIN_QUADRATIC_MARKS`` marks)."""
    i, j = np.triu_indices(k.size, 1)
    slope = np.median((x[j] - x[i]) / (k[j] - k[i]))
    res = x - slope * k - np.median(x - slope * k)
    keep = np.ones(k.size, bool)
    for _ in range(5):
        sigma = 1.4826 * np.median(np.abs(res[keep] - np.median(res[keep])))
        new = np.abs(res) <= max(3 * sigma, floor)
        if np.array_equal(new, keep) or new.sum() < MIN_FIT_MARKS:
            break
        keep = new
        degree = 2 if keep.sum() >= MIN_QUADRATIC_MARKS else 1
        res = x - np.polyval(np.polyfit(k[keep], x[keep], degree), k)
    return keep


def _mark_positions(hp: np.ndarray, period: float) -> tuple[np.ndarray, np.ndarray, int]:
    """Index and sub-sample position of every one-period window matching the mean mark
    waveform (normalised correlation >= MIN_CORRELATION), and the number of windows."""
    count = int(np.clip(period / 6, 1, 8))  # harmonics of the mean waveform
    c = _harmonics(hp, period, count)
    h = np.arange(1, count + 1)
    phase = np.linspace(0, 1, 512, endpoint=False)
    wave = np.real(np.exp(2j * np.pi * np.outer(phase, h)) @ c)
    origin = phase[np.argmax(np.abs(wave))] * period  # the most salient feature
    k = np.arange(np.ceil((period / 2 - origin) / period),
                  np.floor((hp.size - period / 2 - origin) / period))
    width = int(np.floor(period))
    a = np.round(origin + k * period - width / 2).astype(int)[:, None] + np.arange(width)
    win = hp[a] - hp[a].mean(axis=1, keepdims=True)
    z = np.einsum("kj,kjh->kh", win, np.exp(2j * np.pi * a[:, :, None] * h / period))
    taus = np.linspace(-0.5, 0.5, 256, endpoint=False) * period
    corr = np.real((z * c) @ np.exp(-2j * np.pi * np.outer(h, taus) / period))
    corr /= np.maximum(np.linalg.norm(win, axis=1)[:, None]
                       * np.sqrt(width / 2 * np.sum(np.abs(c) ** 2)), 1e-12)
    j = np.argmax(corr, axis=1)
    y0, y1, y2 = (corr[np.arange(j.size), (j + d) % taus.size] for d in (-1, 0, 1))
    curvature = y0 - 2 * y1 + y2
    frac = np.where(curvature < 0, 0.5 * (y0 - y2) / np.where(curvature < 0, curvature, -1), 0)
    found = y1 >= MIN_CORRELATION
    x = origin + k * period + taus[j] + frac * (taus[1] - taus[0])
    return k[found], x[found], k.size


def fit_marks(profile: np.ndarray, period: float, reference: float,
              iterations: int = 3) -> MarkFit:
    """Mark spacing (samples) at profile position ``reference`` from the mark positions.

    Positions are fitted by a quadratic in the mark index (a mild perspective makes the
    spacing drift along the track); the spacing is its slope at the mark nearest the
    reference, where the image scale applies, with the standard error from the fit.
    """
    hp = profile - gaussian_filter1d(profile, 2 * period, mode="reflect")
    for _ in range(iterations):
        k, x, windows = _mark_positions(hp, period)
        if k.size >= MIN_FIT_MARKS:
            keep = _robust_fit(k, x, 0.04 * period)
            k, x = k[keep], x[keep]
        if k.size < MIN_FIT_MARKS:
            return MarkFit(period, np.inf, x, k, windows, np.inf)
        kc = k - k.mean()
        degree = 2 if k.size >= MIN_QUADRATIC_MARKS else 1
        coef, cov = np.polyfit(kc, x, degree, cov="unscaled")
        if degree == 1:  # as a quadratic with no curvature
            coef, cov = np.r_[0.0, coef], np.pad(cov, ((1, 0), (1, 0)))
        res = x - np.polyval(coef, kc)
        k_ref = np.clip((reference - coef[2]) / coef[1], kc.min(), kc.max())
        grad = np.array([2 * k_ref, 1.0, 0.0])
        spacing = float(coef[1] + 2 * coef[0] * k_ref)
        se = float(np.sqrt(np.sum(res**2) / max(k.size - degree - 1, 1) * grad @ cov @ grad))
        period = float(coef[1])
    return MarkFit(spacing, se, x, k, windows, float(np.sqrt(np.mean(res**2))))
