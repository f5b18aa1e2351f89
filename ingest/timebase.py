"""Native stream timing (rate, gaps, dropped samples) and the common uniform time base."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from swtlab_base.order_stats import median as _median

#: an interval longer than GAP_FACTOR median intervals is a gap (no interpolation across it)
GAP_FACTOR = 5.0
#: intervals between DROP_FACTOR and GAP_FACTOR median intervals are dropped samples
DROP_FACTOR = 1.5
#: common time base rate cap (Hz)
MAX_RATE_HZ = 1000.0
#: jitter (std of intervals / median interval) above which the clock is reported irregular
JITTER_LIMIT = 0.5


@dataclass(frozen=True)
class StreamTiming:
    """How one stream was sampled on its native time stamps."""

    n: int
    t0_s: float
    t1_s: float
    median_dt_s: float
    gaps: tuple[tuple[float, float], ...]
    dropped: int
    jitter: float

    @property
    def rate_hz(self) -> float:
        return 1.0 / self.median_dt_s if self.median_dt_s > 0 else float("nan")

    @property
    def gap_threshold_s(self) -> float:
        return GAP_FACTOR * self.median_dt_s

    def to_dict(self) -> dict:
        return {"samples": self.n, "rate_hz": self.rate_hz, "t0_s": self.t0_s, "t1_s": self.t1_s,
                "gaps": [list(g) for g in self.gaps], "dropped_samples": self.dropped,
                "jitter": self.jitter}


def stream_timing(t_s: np.ndarray) -> StreamTiming:
    """Median interval, gaps, estimated dropped samples and jitter of strictly increasing times."""
    if len(t_s) < 2:
        return StreamTiming(len(t_s), float(t_s[0]), float(t_s[-1]), float("nan"), (), 0, 0.0)
    dt = np.diff(t_s)
    median = _median(dt)
    ratio = dt / median
    gap_idx = np.flatnonzero(ratio > GAP_FACTOR)
    drop = ratio[(ratio > DROP_FACTOR) & (ratio <= GAP_FACTOR)]
    regular = dt[ratio <= GAP_FACTOR]
    return StreamTiming(
        n=len(t_s), t0_s=float(t_s[0]), t1_s=float(t_s[-1]), median_dt_s=median,
        gaps=tuple((float(t_s[i]), float(t_s[i + 1])) for i in gap_idx),
        dropped=int(np.rint(drop).sum() - len(drop)),
        jitter=float(np.std(regular) / median) if len(regular) else 0.0)


def grid_size(timings: list[StreamTiming]) -> tuple[int, float]:
    """Samples and rate of the uniform time base: the union of the streams' spans at the
    fastest median rate, capped at ``MAX_RATE_HZ``."""
    rates = [s.rate_hz for s in timings if np.isfinite(s.rate_hz)]
    rate = min(max(rates), MAX_RATE_HZ) if rates else 1.0
    t0 = min(s.t0_s for s in timings)
    t1 = max(s.t1_s for s in timings)
    return int(np.floor((t1 - t0) * rate + 1e-9)) + 1, rate


def common_grid(timings: list[StreamTiming]) -> tuple[np.ndarray, float]:
    """Uniform time base (:func:`grid_size`) from the earliest time stamp."""
    n, rate = grid_size(timings)
    return min(s.t0_s for s in timings) + np.arange(n) / rate, rate


def grid_mask(t_s: np.ndarray, timing: StreamTiming, grid: np.ndarray) -> np.ndarray:
    """True where the grid (ascending) lies inside the stream's span and not inside one of its
    gaps."""
    tol = 1e-6 * timing.median_dt_s if np.isfinite(timing.median_dt_s) else 1e-9
    inside = (grid >= t_s[0] - tol) & (grid <= t_s[-1] + tol)
    if len(t_s) < 2:
        return inside & np.isclose(grid, t_s[0])
    # a grid point belongs to the interval t_s[i] <= t < t_s[i + 1] (before the first time
    # stamp: the first interval; from the last but one on: the last); the ascending grid
    # points of a gap's interval are one slice of it
    gaps = np.flatnonzero(~(np.diff(t_s) <= timing.gap_threshold_s))
    last = len(t_s) - 2
    for i in gaps:
        lo = t_s[i] if i > 0 else -np.inf
        hi = t_s[i + 1] if i < last else np.inf
        inside[np.searchsorted(grid, lo):np.searchsorted(grid, hi)] = False
    return inside


def to_grid(t_s: np.ndarray, values: np.ndarray, grid: np.ndarray, mask: np.ndarray) -> np.ndarray:
    """Linear interpolation onto the grid, NaN outside the span and inside gaps."""
    out = np.interp(grid, t_s, values)
    out[~mask] = np.nan
    return out
