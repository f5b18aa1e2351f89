"""Small vectorised signal helpers shared by the detectors and checks."""

from __future__ import annotations

import numpy as np

from swtlab_base.order_stats import median


def moving_average(x, width: int, full_only: bool = False, at=None) -> np.ndarray:
    """Centred NaN-aware moving average over ``width`` samples (NaN where no sample is finite;
    with ``full_only`` also NaN near the ends, where the window would be cut short); at the
    sample indices ``at`` only when given (the same values as the whole average's there)."""
    x = np.asarray(x, float)
    width = max(int(width), 1)
    ok = np.isfinite(x)
    pad = np.concatenate([[0.0], np.cumsum(np.where(ok, x, 0.0))])
    cnt = np.concatenate([[0], np.cumsum(ok)])
    lo_raw = (np.arange(x.size) if at is None else np.asarray(at, int)) - width // 2
    lo, hi = np.clip(lo_raw, 0, x.size), np.clip(lo_raw + width, 0, x.size)
    n = cnt[hi] - cnt[lo]
    if full_only:
        n = np.where((lo_raw >= 0) & (lo_raw + width <= x.size), n, 0)
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.where(n > 0, (pad[hi] - pad[lo]) / n, np.nan)


def longest_true_run(mask) -> tuple[int, int] | None:
    """``(start, stop)`` indices of the longest run of True (stop exclusive), or None."""
    mask = np.asarray(mask, bool)
    if not mask.any():
        return None
    edges = np.diff(np.concatenate([[0], mask.astype(np.int8), [0]]))
    starts, stops = np.flatnonzero(edges == 1), np.flatnonzero(edges == -1)
    best = int(np.argmax(stops - starts))
    return int(starts[best]), int(stops[best])


def grouser_period_s(grouser_count: int, omega_radps: float) -> float | None:
    """Grouser passing period ``2 pi / (n omega)``; None for a wheel without grousers."""
    if grouser_count <= 0 or not np.isfinite(omega_radps) or abs(omega_radps) <= 0:
        return None
    return float(2.0 * np.pi / (grouser_count * abs(omega_radps)))


def robust_sigma(x) -> float:
    """1.4826 * median absolute deviation from the median (a Gaussian's sigma)."""
    x = np.asarray(x, float)
    x = x[np.isfinite(x)]
    if x.size == 0:
        return float("nan")
    return float(1.4826 * median(np.abs(x - median(x))))


def decimate_mean(t, x, max_points: int) -> tuple[np.ndarray, np.ndarray]:
    """Block means so that at most ``max_points`` remain (NaN-aware), for plotting traces."""
    t, x = np.asarray(t, float), np.asarray(x, float)
    block = max(1, int(np.ceil(t.size / max_points)))
    n = (t.size // block) * block
    tb = t[:n].reshape(-1, block).mean(axis=1)
    blocks = x[:n].reshape(-1, block)
    counts = np.isfinite(blocks).sum(axis=1)
    with np.errstate(invalid="ignore", divide="ignore"):
        xb = np.where(counts > 0, np.nansum(blocks, axis=1) / counts, np.nan)
    return tb, xb
