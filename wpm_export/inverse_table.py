"""The monotone inverse table of one curve: the smallest slip at which it gives a value, by
one table look-up and a linear interpolation (RUAG WPM's inverse; semantics of
:mod:`wpm_export.inverse`).

Built once per curve: the curve is cut at its turning points (real roots of the derivative)
and at the jump at zero slip of a braked branch into monotone pieces; each piece is sampled
finely enough that the chord between two samples is, read as the inverse, within
``SLIP_TOLERANCE`` of the curve's inverse (cells halved until it is, checked at three
interior points). Along slip the running maximum and minimum of the samples are kept: the
smallest slip reaching a value above the start value lies where the curve first sets a new
maximum at it, one below where it first sets a new minimum. Both records, with the points
where the curve climbs back through an earlier record, form one table of strictly increasing
values and their slips: ``numpy.interp(target, values, slips)`` is the answer, exact to the
tolerance. NumPy only.
"""

from __future__ import annotations

import bisect

import numpy as np

from fitting.polynomial import horner

SLIP_TOLERANCE = 1e-8  # inverse chord error allowed, in slip
START_CELLS = 32  # per monotone piece, before halving
MIN_CELL = 1e-12  # cells are not halved below this width (flat to rounding there)
CHECK_POINTS = np.array([0.25, 0.5, 0.75])
STATUS_OK, STATUS_ABOVE, STATUS_BELOW, STATUS_STEP = "ok", "above_max", "below_min", "at_step"


def sides(coefficients, step: float, slope: float, slip_min: float,
          slip_max: float) -> list[tuple[np.ndarray, float, float]]:
    """The curve's polynomials with their slip intervals, in slip order: braked
    (``a + (J, K)``) below zero and driven from zero where the range spans zero and there is a
    branch, else the one polynomial that holds over the range."""
    driven = np.asarray(coefficients, dtype=float)
    braked = driven.copy()
    braked[:2] += (step, slope)
    if slip_min < 0 <= slip_max and (step or slope):
        return [(braked, slip_min, 0.0), (driven, 0.0, slip_max)]
    return [(braked if slip_max < 0 else driven, slip_min, slip_max)]


def turning_points(a: np.ndarray, lo: float, hi: float) -> list[float]:
    """Slips in (lo, hi) where the derivative of ``sum a_i s**i`` changes sign, refined by
    Newton on the derivative from its complex-root estimates."""
    slope = a[1:] * np.arange(1, a.size)
    while slope.size > 1 and slope[-1] == 0:
        slope = slope[:-1]
    if slope.size < 2:
        return []
    roots = np.roots(slope[::-1])
    curvature = slope[1:] * np.arange(1, slope.size)
    out = []
    for r in roots[np.abs(roots.imag) <= 1e-6 * (1 + np.abs(roots.real))].real:
        for _ in range(3):
            d2 = horner(curvature, r)
            r = r - horner(slope, r) / d2 if d2 else r
        if lo < r < hi:
            left, right = horner(slope, r - 1e-9), horner(slope, r + 1e-9)
            if left * right < 0:
                out.append(float(r))
    return sorted(out)


def _sample_piece(a: np.ndarray, lo: float, hi: float) -> np.ndarray:
    """Slips on [lo, hi] (a monotone piece) whose chords invert the curve to the tolerance."""
    slips = np.linspace(lo, hi, START_CELLS + 1)
    while True:
        left, width = slips[:-1], np.diff(slips)
        f_left, f_right = horner(a, left), horner(a, slips[1:])
        inner = left[:, None] + width[:, None] * CHECK_POINTS
        with np.errstate(divide="ignore", invalid="ignore"):
            chord = left[:, None] + (horner(a, inner) - f_left[:, None]) \
                / (f_right - f_left)[:, None] * width[:, None]
        error = np.max(np.abs(np.nan_to_num(chord - inner, nan=np.inf)), axis=1)
        split = (error > SLIP_TOLERANCE) & (width > MIN_CELL)
        if not split.any():
            return slips
        slips = np.sort(np.concatenate([slips, left[split] + 0.5 * width[split]]))


def _records(slips: np.ndarray, values: np.ndarray, polys: list, piece: np.ndarray
             ) -> tuple[np.ndarray, np.ndarray]:
    """The points of the table above the start value: each new running maximum, and where the
    curve climbs back through the previous maximum (``numpy.nextafter`` above it, so the
    values stay strictly increasing; at slip 0 across the jump)."""
    best = np.maximum.accumulate(values)
    new = np.flatnonzero(values[1:] > best[:-1]) + 1
    keys, out_s, out_v = [0.0, *new.astype(float)], [slips[0], *slips[new]], \
        [values[0], *values[new]]
    for i in new[values[new - 1] < best[new - 1]]:  # climbing back through the old record
        level = best[i - 1]
        above = np.nextafter(level, np.inf)
        if above < values[i]:
            at = slips[i] if slips[i - 1] == slips[i] else \
                _level_crossing(polys[piece[i]], slips[i - 1], slips[i], level)
            keys.append(i - 0.5)
            out_s.append(at)
            out_v.append(above)
    order = np.argsort(keys, kind="stable")
    return np.asarray(out_s)[order], np.asarray(out_v)[order]


def _level_crossing(a: np.ndarray, lo: float, hi: float, level: float) -> float:
    """The slip in [lo, hi] (the curve monotone there, below ``level`` at lo, above at hi)
    where it equals ``level``: bisection to rounding."""
    for _ in range(80):
        mid = 0.5 * (lo + hi)
        if mid in (lo, hi):
            break
        lo, hi = (mid, hi) if horner(a, mid) < level else (lo, mid)
    return hi


class InverseTable:
    """The inverse of one curve; :meth:`solve` (one float, pure Python) and
    :meth:`solve_many` (arrays) give ``(slip, value, status)`` as :mod:`wpm_export.inverse`:
    slip 1.0 and the maximum above the curve, NaN and the minimum below it, slip 0.0 and
    the target inside the jump at zero slip; the target as value where it is reached."""

    def __init__(self, coefficients, slip_min: float, slip_max: float, step: float = 0.0,
                 slope: float = 0.0) -> None:
        polys = [a for a, _, _ in sides(coefficients, step, slope, slip_min, slip_max)]
        slips, piece = [], []
        for k, (a, lo, hi) in enumerate(sides(coefficients, step, slope, slip_min, slip_max)):
            cuts = [lo, *turning_points(a, lo, hi), hi]
            for u, v in zip(cuts[:-1], cuts[1:]):
                s = _sample_piece(a, u, v)
                if slips and slips[-1].size and slips[-1][-1] == s[0] and piece[-1] == k:
                    s = s[1:]  # the cut is already the last sample of this side
                slips.append(s)
                piece.append(k)
        piece_of = np.concatenate([np.full(s.size, k) for s, k in zip(slips, piece)])
        values = np.concatenate([horner(polys[k], s) for s, k in zip(slips, piece)])
        slips = np.concatenate(slips)
        up_s, up_v = _records(slips, values, polys, piece_of)
        down_s, down_v = _records(slips, -values, [-a for a in polys], piece_of)
        self.slips = np.concatenate([down_s[:0:-1], up_s])
        self.values = np.concatenate([-down_v[:0:-1], up_v])
        self.top, self.bottom = float(self.values[-1]), float(self.values[0])
        at_zero = np.flatnonzero((self.slips[:-1] == 0.0) & (self.slips[1:] == 0.0))
        self.step = (float(self.values[at_zero[0]]), float(self.values[at_zero[0] + 1])) \
            if at_zero.size else None
        self._values, self._slips = self.values.tolist(), self.slips.tolist()

    def solve(self, target: float) -> tuple[float, float, str]:
        """``(slip, value, status)`` of one target (Python floats)."""
        if target > self.top:
            return 1.0, self.top, STATUS_ABOVE
        if target < self.bottom:
            return float("nan"), self.bottom, STATUS_BELOW
        if self.step is not None and self.step[0] < target < self.step[1]:
            return 0.0, target, STATUS_STEP
        values, slips = self._values, self._slips
        j = bisect.bisect_left(values, target)
        if values[j] == target:
            return slips[j], target, STATUS_OK
        w = (target - values[j - 1]) / (values[j] - values[j - 1])
        return slips[j - 1] + w * (slips[j] - slips[j - 1]), target, STATUS_OK

    def solve_many(self, targets) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """``(slip, value, status)`` arrays of many targets."""
        shape = np.shape(targets)
        t = np.asarray(targets, dtype=float).reshape(-1)
        slip = np.interp(t, self.values, self.slips)
        value = np.clip(t, self.bottom, self.top)
        status = np.full(t.shape, STATUS_OK, dtype="<U9")
        above, below = t > self.top, t < self.bottom
        if above.any():
            slip[above], status[above] = 1.0, STATUS_ABOVE
        if below.any():
            slip[below], status[below] = np.nan, STATUS_BELOW
        if self.step is not None:
            jump = (t > self.step[0]) & (t < self.step[1])
            slip[jump], status[jump] = 0.0, STATUS_STEP
        return slip.reshape(shape), value.reshape(shape), status.reshape(shape)
