"""Decimated traces of a run's quantities against time, kept at processing time for plots
(the report's time series) so that nothing downstream has to read the raw file again: drawbar
pull, torque, sinkage and slip as ``process_run`` averages them (sinkage after the rig
correction, when one is given).

Min/max decimation: the samples are cut into equal blocks and each block keeps its smallest
and its largest sample, at their own times and in time order ("MinMax" aggregation, Jugel
et al. 2014, "M4: a visualization-oriented time series data aggregation", Proc. VLDB
Endowment 7(10)). A line through these points has the envelope the full line would have at
screen resolution: spikes and the grouser-passing oscillation keep their amplitude, where
block means would shrink them. A run of at most :data:`MAX_TRACE_POINTS` samples is kept
whole.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

#: quantities of the stored traces (``process_run``'s per-sample series, after corrections)
TRACE_QUANTITIES = ("dp_n", "torque_nm", "sinkage_m", "slip")
#: most points kept per channel (two per block)
MAX_TRACE_POINTS = 2000


@dataclass(frozen=True)
class Trace:
    """One quantity against time, decimated from ``samples`` raw samples (``block`` per pair
    of min/max points; 1: kept whole). NaN values mark blocks with no finite sample."""

    t_s: np.ndarray
    values: np.ndarray
    unit: str
    samples: int
    block: int


def decimate_minmax(t_s, values, max_points: int = MAX_TRACE_POINTS
                    ) -> tuple[np.ndarray, np.ndarray, int]:
    """``(t_s, values, block)``: per block of ``block`` samples its min and max sample in time
    order (a block with no finite sample: one NaN point at its first time, kept twice), at
    most ``max_points`` points; fewer samples than that are returned whole with block 1."""
    t, x = np.asarray(t_s, float), np.asarray(values, float)
    if t.shape != x.shape or t.ndim != 1:
        raise ValueError(f"times {t.shape} and values {x.shape} must be 1-D of one length")
    if max_points < 2:
        raise ValueError(f"max_points {max_points} must be at least 2")
    if t.size <= max_points:
        return t.copy(), x.copy(), 1
    block = math.ceil(t.size / (max_points // 2))
    blocks = math.ceil(t.size / block)
    index = np.minimum(np.arange(blocks * block), t.size - 1).reshape(blocks, block)
    padded = x[index]
    padded[np.arange(blocks * block).reshape(blocks, block) >= t.size] = np.nan
    finite = np.isfinite(padded)
    low = np.argmin(np.where(finite, padded, np.inf), axis=1)
    high = np.argmax(np.where(finite, padded, -np.inf), axis=1)
    first, second = np.minimum(low, high), np.maximum(low, high)
    rows = np.arange(blocks)
    picked = np.stack([index[rows, first], index[rows, second]], axis=1).ravel()
    out = x[picked]
    empty = np.repeat(~finite.any(axis=1), 2)
    out[empty] = np.nan
    return t[picked], out, block


def run_traces(t_s, series: dict[str, tuple[np.ndarray, str]]) -> dict[str, Trace]:
    """The :data:`TRACE_QUANTITIES` of ``series`` (quantity -> (per-sample values, unit), as
    ``process_run`` builds them) decimated by :func:`decimate_minmax`; a quantity with no
    finite sample is left out."""
    t = np.asarray(t_s, float)
    out = {}
    for name in TRACE_QUANTITIES:
        if name not in series or not np.isfinite(series[name][0]).any():
            continue
        values, unit = series[name]
        td, xd, block = decimate_minmax(t, values)
        out[name] = Trace(t_s=td, values=xd.astype(np.float32), unit=unit, samples=int(t.size),
                          block=block)
    return out
