"""Does a fitted polynomial oscillate between its points?

Between two adjacent data slips a curve that follows its points stays within the band of its
own values at those two points (up to a small overshoot where a real extremum lies in the
gap) and turns at most once. A polynomial of high degree through few points (what the RUAG
WPAT paper avoids with degrees 3-7) swings out of that band or turns twice in one gap.
"""

from __future__ import annotations

import numpy as np

from fitting.polynomial import horner

DEPARTURE_RMSE_FACTOR = 3.0  # tolerance: k x RMSE ...
DEPARTURE_RANGE_FRACTION = 0.05  # ... but at least this fraction of the curve's range
SAMPLES_PER_GAP = 64


def check_oscillation(coefficients, slips, rmse: float) -> tuple[bool, float]:
    """``(oscillates, max_departure)``: the largest excursion of the curve beyond the band of
    its values at the two points around each gap between the distinct ``slips``; oscillates
    when that exceeds ``max(3 x rmse, 5 % of the range of the curve at the points)`` or the
    curve turns more than once inside one gap."""
    knots = np.unique(np.asarray(slips, dtype=float))
    at_knots = horner(coefficients, knots)
    t = np.arange(SAMPLES_PER_GAP + 1) / SAMPLES_PER_GAP
    gaps = knots[:-1, None] + np.diff(knots)[:, None] * t  # (gaps, samples), ends included
    values = horner(coefficients, gaps)
    low = np.minimum(at_knots[:-1], at_knots[1:])[:, None]
    high = np.maximum(at_knots[:-1], at_knots[1:])[:, None]
    departure = float(np.max(np.maximum(values - high, low - values)))
    tolerance = max(DEPARTURE_RMSE_FACTOR * rmse,
                    DEPARTURE_RANGE_FRACTION * float(np.ptp(at_knots)))
    slope = np.arange(1, len(coefficients)) * np.asarray(coefficients, dtype=float)[1:]
    slope_sign = np.sign(horner(slope, gaps))
    turns = np.sum(slope_sign[:, 1:] * slope_sign[:, :-1] < 0, axis=1)
    return bool(departure > tolerance or np.any(turns > 1)), max(departure, 0.0)
