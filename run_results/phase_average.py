"""Phase (synchronous) averaging at the grouser passing frequency.

The grouser load is periodic but sharp-edged (it builds up, then drops as a grouser leaves
the soil), which a short harmonic series follows badly. Sorting the samples by their phase
``frac(f t)`` into bins and averaging each bin gives the waveform at any sharpness (time-
synchronous averaging; Braun, Acustica 32, 1975; McFadden, Mech. Syst. Signal Process. 1,
1987). The mean of the bin means weights every phase equally, so samples missing from a gap
do not bias it; the residual ``y - waveform(phase)`` is what is left for the SE.
"""

from __future__ import annotations

import numpy as np

from swtlab_base.order_stats import median

MIN_BINS, MAX_BINS = 4, 256


def bin_count(samples_per_period: float) -> int:
    """About two samples per bin and period, within ``MIN_BINS..MAX_BINS``."""
    return int(np.clip(np.floor(samples_per_period / 2.0), MIN_BINS, MAX_BINS))


def phase_bins(t_s, frequency_hz: float) -> tuple[np.ndarray, int]:
    """``(bin of each sample, bins)``: the phase ``frac(f (t - t_0))`` of each sample in
    :func:`bin_count` bins (one computation for every series on the same time stamps)."""
    t_s = np.asarray(t_s, float)
    dt = median(np.diff(t_s)) if t_s.size > 1 else 1.0
    bins = bin_count(1.0 / (frequency_hz * dt))
    index = np.minimum((np.mod(frequency_hz * (t_s - t_s[0]), 1.0) * bins).astype(int), bins - 1)
    return index, bins


def phase_average(t_s, y, frequency_hz: float,
                  phase: tuple[np.ndarray, int] | None = None) -> dict:
    """``mean`` (of the bin means), ``periodic`` (waveform minus mean at each sample, NaN where
    ``y`` is), ``waveform`` (bin means, NaN for empty bins), ``counts`` (samples per bin) and
    ``bins``; ``phase``: :func:`phase_bins` of these ``t_s`` and ``frequency_hz`` if known."""
    y = np.asarray(y, float)
    ok = np.isfinite(y)
    index, bins = phase if phase is not None else phase_bins(t_s, frequency_hz)
    sums = np.bincount(index[ok], y[ok], minlength=bins)
    counts = np.bincount(index[ok], minlength=bins)
    with np.errstate(invalid="ignore", divide="ignore"):
        waveform = np.where(counts > 0, sums / counts, np.nan)
    mean = float(np.nanmean(waveform)) if counts.any() else float("nan")
    periodic = np.where(ok, waveform[index] - mean, np.nan)
    return {"mean": mean, "periodic": periodic, "waveform": waveform, "counts": counts,
            "bins": bins}
