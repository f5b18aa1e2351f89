"""Two-sided MSER on batch means (White 1997; Franklin & White 2008, "MSER-2-sided").

MSER picks the truncation that minimises the squared standard error of the kept
mean, ``sum (Y_i - mean)^2 / n^2`` over the kept batch means. Batches here are means over
one grouser period (so the periodic grouser load does not count as variance), taken every
``batch_s``; the two-sided form cuts the start and the end at once.
"""

from __future__ import annotations

import numpy as np

from stable_phase.registry import Cut, register
from stable_phase.signals import moving_average
from swtlab_base.order_stats import median


def batch_means(t_s: np.ndarray, y: np.ndarray, period_s: float | None,
                batch_s: float) -> tuple[np.ndarray, np.ndarray]:
    """Period-long moving means sampled every ``batch_s``: (batch centre indices, means)."""
    dt = float(median(np.diff(t_s)))
    width = max(int(round((period_s or batch_s) / dt)), 1)
    step = max(int(round(batch_s / dt)), 1)
    centres = np.arange(0, t_s.size, step)
    return centres, moving_average(y, width, full_only=True, at=centres)


def mser_two_sided(means: np.ndarray, max_cut_fraction: float,
                   fixed_start: int | None = None) -> tuple[int, int, float]:
    """``(d_start, d_end, statistic)``: batches to drop at each end minimising MSER.

    Together the cuts drop at most ``max_cut_fraction`` of the batches; with ``fixed_start``
    only the end is searched, over at most that fraction of the batches left.
    """
    y = np.where(np.isfinite(means), means, np.nanmean(means))
    m = y.size
    s1 = np.concatenate([[0.0], np.cumsum(y)])
    s2 = np.concatenate([[0.0], np.cumsum(y * y)])
    if fixed_start is None:
        limit = int(max_cut_fraction * m)
        d1, d2 = np.meshgrid(np.arange(limit + 1), np.arange(limit + 1), indexing="ij")
        allowed = d1 + d2 <= limit
    else:
        limit = int(max_cut_fraction * (m - fixed_start))
        d1, d2 = np.meshgrid([fixed_start], np.arange(limit + 1), indexing="ij")
        allowed = np.ones(d1.shape, bool)
    n = m - d1 - d2
    valid = allowed & (n >= 2)
    lo, hi = d1, np.clip(m - d2, 0, m)
    with np.errstate(invalid="ignore", divide="ignore"):
        ss = (s2[hi] - s2[lo]) - (s1[hi] - s1[lo]) ** 2 / n
        stat = np.where(valid, ss / n.astype(float) ** 2, np.inf)
    i, j = np.unravel_index(int(np.argmin(stat)), stat.shape)
    return int(d1[i, j]), int(d2[i, j]), float(stat[i, j])


@register
class MserDetector:
    """Two-sided MSER on each signal's batch means; the latest start and earliest end win."""

    name = "mser"
    description = "two-sided MSER on grouser-period batch means"

    def locate(self, t_s, signals, period_s, params, gate_start) -> Cut:
        start, stop, per_signal = gate_start, t_s.size, {}
        for name, y in signals.items():
            centres, means = batch_means(t_s[gate_start:], y[gate_start:], period_s,
                                         params.batch_s)
            d1, d2, stat = mser_two_sided(means, params.mser_max_cut_fraction)
            first = gate_start + int(centres[d1])
            last = gate_start + int(centres[centres.size - 1 - d2]) + 1
            per_signal[name] = {"start_s": float(t_s[first]), "end_s": float(t_s[last - 1]),
                                "batches": int(centres.size), "statistic": stat}
            start, stop = max(start, first), min(stop, last)
        return Cut(start, max(stop, start), {"mser": per_signal})
