"""Does a fitted polynomial oscillate between its points?

Between two adjacent data slips a curve that follows its points stays within the band of its
own values at those two points (up to a small overshoot where a real extremum lies in the
gap) and turns at most once. A polynomial of high degree through few points (what the RUAG
WPAT paper avoids with degrees 3-7) swings out of that band or turns twice in one gap. A
curve with a braked branch (step and slope below zero slip) is checked on each side, zero
slip closing the braked side with that branch's limit there.
"""

from __future__ import annotations

import numpy as np

from fitting.polynomial import curve_value, horner

DEPARTURE_RMSE_FACTOR = 3.0  # tolerance: k x RMSE ...
DEPARTURE_RANGE_FRACTION = 0.05  # ... but at least this fraction of the curve's range
SAMPLES_PER_GAP = 64


def check_oscillation(coefficients, slips, rmse: float, step_below_zero: float = 0.0,
                      slope_below_zero: float = 0.0) -> tuple[bool, float]:
    """``(oscillates, max_departure)``: the largest excursion of the curve beyond the band of
    its values at the two points around each gap between the distinct ``slips``; oscillates
    when that exceeds ``max(3 x rmse, 5 % of the range of the curve at the points)`` or the
    curve turns more than once inside one gap. A braked branch (step ``J``, slope ``K``) is
    checked on its side with zero slip as its last knot."""
    knots = np.unique(np.asarray(slips, dtype=float))
    tolerance = max(DEPARTURE_RMSE_FACTOR * rmse, DEPARTURE_RANGE_FRACTION
                    * float(np.ptp(curve_value(coefficients, knots, step_below_zero,
                                               slope_below_zero))))
    pieces = [(np.asarray(coefficients, dtype=float), knots)]
    if step_below_zero or slope_below_zero:
        braked = np.array(coefficients, dtype=float)
        braked[:2] += (step_below_zero, slope_below_zero)
        pieces = [(braked, np.append(knots[knots < 0], 0.0)), (pieces[0][0], knots[knots >= 0])]
    worst, turns_twice = 0.0, False
    for a, side in pieces:
        if side.size > 1:
            departure, turns = _departure(a, side)
            worst, turns_twice = max(worst, departure), turns_twice or turns
    return bool(worst > tolerance or turns_twice), worst


def _departure(coefficients: np.ndarray, knots: np.ndarray) -> tuple[float, bool]:
    """Largest excursion of one polynomial beyond its band in a gap between ``knots`` (2+),
    and whether it turns more than once in one gap."""
    at_knots = horner(coefficients, knots)
    t = np.arange(SAMPLES_PER_GAP + 1) / SAMPLES_PER_GAP
    gaps = knots[:-1, None] + np.diff(knots)[:, None] * t  # (gaps, samples), ends included
    values = horner(coefficients, gaps)
    low = np.minimum(at_knots[:-1], at_knots[1:])[:, None]
    high = np.maximum(at_knots[:-1], at_knots[1:])[:, None]
    departure = float(np.max(np.maximum(values - high, low - values)))
    slope = np.arange(1, len(coefficients)) * coefficients[1:]
    slope_sign = np.sign(horner(slope, gaps))
    turns = np.sum(slope_sign[:, 1:] * slope_sign[:, :-1] < 0, axis=1)
    return max(departure, 0.0), bool(np.any(turns > 1))
