"""Order statistics at the cost of one partition."""

from __future__ import annotations

import numpy as np


def median(x: np.ndarray) -> float:
    """``np.median`` of a 1-D float array, the same number (NaN if a sample is, or none is),
    from one partition at the upper middle and the largest sample below it: np.median
    partitions at both middles and at the end (for NaN), several times slower on long
    arrays."""
    if x.size == 0 or np.isnan(x).any():
        return float("nan")
    half = x.size // 2
    part = np.partition(x, half)
    if x.size % 2:
        return float(part[half])
    return float((part[:half].max() + part[half]) / 2)
