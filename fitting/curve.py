"""Curves in the WPM form ``y = sum_i a_i slip**i`` on [slip_min, slip_max], and the fit
record that carries one with its diagnostics."""

from __future__ import annotations

import warnings
from dataclasses import asdict, dataclass

import numpy as np

from fitting.errors import OutsideSlipRangeWarning
from fitting.polynomial import horner

#: quantity name -> unit, the WPM CSV's set (docs/wpm-csv.md)
QUANTITY_UNITS = {"dp_n": "N", "torque_nm": "N*m", "sinkage_m": "m", "resistance_n": "N",
                  "dp_over_w": "1"}

DEGREES = range(3, 8)  # RUAG WPAT: "polynomials of degrees n = 3 ... 7 provide adequate results"


@dataclass(frozen=True)
class PowerCurve:
    """``sum_i a_i slip**i`` (``coefficients[i] = a_i``) valid on [slip_min, slip_max]."""

    coefficients: tuple[float, ...]
    slip_min: float
    slip_max: float

    @property
    def degree(self) -> int:
        return len(self.coefficients) - 1

    def outside_range(self, slip) -> np.ndarray:
        """True where ``slip`` lies outside [slip_min, slip_max]."""
        s = np.asarray(slip, dtype=float)
        return (s < self.slip_min) | (s > self.slip_max)

    def evaluate(self, slip) -> np.ndarray:
        """The curve at ``slip`` (any shape); warns with :class:`OutsideSlipRangeWarning`
        when a slip lies outside the fitted range (the value is still returned)."""
        outside = self.outside_range(slip)
        if np.any(outside):
            bad = np.asarray(slip, dtype=float)[outside]
            warnings.warn(f"{int(outside.sum())} slip(s) outside the fitted range "
                          f"[{self.slip_min:g}, {self.slip_max:g}] (e.g. {bad.flat[0]:g}): "
                          "extrapolated", OutsideSlipRangeWarning, stacklevel=2)
        return horner(self.coefficients, slip)


@dataclass(frozen=True)
class CurveFit(PowerCurve):
    """A fitted curve of one quantity of one (wheel, soil, multipass, load) group.

    ``rmse`` and ``loo_rmse`` are unweighted, in the quantity's unit; ``r2`` is the weighted
    coefficient of determination; ``condition_number`` is that of the weighted Chebyshev
    design matrix solved. ``degree_choice`` is ``"user"``, ``"loo"`` or ``"aicc"`` and
    ``degree_scores`` the criterion per candidate degree (empty for ``"user"``).
    ``oscillates`` flags a curve that, between two adjacent data slips, leaves the band of its
    own values there by more than the tolerance or turns twice (:mod:`fitting.oscillation`);
    ``max_departure`` is its largest excursion beyond the band, in the unit.
    """

    quantity: str
    unit: str
    wheel: str
    soil: str
    multipass: int
    load_n: float
    n_points: int
    rmse: float
    r2: float
    loo_rmse: float
    condition_number: float
    degree_choice: str
    degree_scores: tuple[tuple[int, float], ...]
    weighting: str
    oscillates: bool
    max_departure: float

    def to_dict(self) -> dict:
        out = asdict(self)
        out["coefficients"] = list(self.coefficients)
        out["degree"] = self.degree
        out["degree_scores"] = {str(d): s for d, s in self.degree_scores}
        return out
