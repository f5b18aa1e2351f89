"""Curves in the WPM form ``y = sum_i a_i slip**i + [slip < 0] (J + K slip)`` on
[slip_min, slip_max] (``J``, ``K`` the braked branch's step and slope change at zero slip,
docs/fitting.md), and the fit record that carries one with its diagnostics."""

from __future__ import annotations

import warnings
from dataclasses import asdict, dataclass, field

import numpy as np

from fitting.errors import OutsideSlipRangeWarning
from fitting.polynomial import curve_value

#: quantity name -> unit, the WPM CSV's set (docs/wpm-csv.md)
QUANTITY_UNITS = {"dp_n": "N", "torque_nm": "N*m", "sinkage_m": "m", "resistance_n": "N",
                  "dp_over_w": "1"}

DEGREES = range(3, 8)  # RUAG WPAT: "polynomials of degrees n = 3 ... 7 provide adequate results"


@dataclass(frozen=True)
class PowerCurve:
    """``sum_i a_i slip**i + [slip < 0] (J + K slip)`` (``coefficients[i] = a_i``, ``J`` =
    ``step_below_zero``, ``K`` = ``slope_below_zero``, both 0 for a plain polynomial) valid
    on [slip_min, slip_max]. Its uncertainty (docs/fitting.md, "Bands"; None / NaN where
    unknown): ``covariance`` of the parameters ``(a_0 ... a_n, J, K)`` (rows), ``scatter_sd``
    the run-to-run standard deviation of one run's mean about the curve, ``k95`` the factor
    of the 95 % half-widths (:func:`fitting.band.band`)."""

    coefficients: tuple[float, ...]
    slip_min: float
    slip_max: float
    step_below_zero: float = field(default=0.0, kw_only=True)
    slope_below_zero: float = field(default=0.0, kw_only=True)
    covariance: tuple[tuple[float, ...], ...] | None = field(default=None, kw_only=True)
    scatter_sd: float = field(default=float("nan"), kw_only=True)
    k95: float = field(default=float("nan"), kw_only=True)

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
        return curve_value(self.coefficients, slip, self.step_below_zero,
                           self.slope_below_zero)


@dataclass(frozen=True)
class CurveFit(PowerCurve):
    """A fitted curve of one quantity of one (wheel, soil, multipass, load) group.

    ``rmse`` and ``loo_rmse`` are unweighted, in the quantity's unit; ``r2`` is the weighted
    coefficient of determination; ``condition_number`` is that of the weighted Chebyshev
    design matrix solved. ``degree_choice`` is ``"user"``, ``"loo"`` or ``"aicc"`` and
    ``degree_scores`` the criterion per candidate degree without a braked branch (empty for
    ``"user"``). ``branch_choice`` is ``"user"``, ``"loo"`` or ``"aicc"`` and
    ``branch_scores`` ``(degree, branch terms, score)`` per candidate with a branch (empty
    where none was a candidate). ``step_se``, ``slope_se``: standard errors of
    ``step_below_zero`` and ``slope_below_zero`` (from the SEs of the points; scaled by the
    residual variance when they had none; NaN for a term not fitted).
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
    branch_choice: str = field(default="user", kw_only=True)
    branch_scores: tuple[tuple[int, int, float], ...] = field(default=(), kw_only=True)
    step_se: float = field(default=float("nan"), kw_only=True)
    slope_se: float = field(default=float("nan"), kw_only=True)

    def to_dict(self) -> dict:
        out = asdict(self)
        out["coefficients"] = list(self.coefficients)
        out["covariance"] = None if self.covariance is None else [list(r) for r in
                                                                  self.covariance]
        out["degree"] = self.degree
        out["degree_scores"] = {str(d): s for d, s in self.degree_scores}
        out["branch_scores"] = {f"{d}+{b}": s for d, b, s in self.branch_scores}
        return out
