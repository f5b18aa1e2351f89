"""The curve at any load from the curves at the tested loads.

RUAG WPAT: "an interpolation for various wheel loads is also implemented allowing reducing
the test campaign to the minimum, nominal and maximum load case only". Done on curve values,
never on raw high-order coefficients: each tested curve is evaluated on a common slip grid
(Chebyshev-Lobatto points on the slip range the loads share), the values are interpolated
across load at each slip, and a polynomial is fitted to the interpolated values -- plus the
braked branch (``[slip < 0] (J + K slip)``, docs/fitting.md) with as many terms as the tested
curve that has most, where the shared slip range reaches below zero: the values on each side
carry their curve's branch, so the step and the slope change are interpolated across load
with the values and fitted back as coefficients.

Across load: ``"pchip"`` (monotone piecewise-cubic Hermite, Fritsch & Carlson 1980) with 3
or more tested loads, ``"linear"`` otherwise (``"auto"`` picks so). Outside the tested loads
only with ``allow_extrapolation=True``, then linearly from the two nearest loads, with a
:class:`LoadExtrapolationWarning`.

The interpolated curve's covariance holds the tested curves' (propagated) and, with 3 or
more tested loads, the error of interpolating across load: estimated by the difference
``d(s)`` between the PCHIP and the linear interpolant at the load (the a-posteriori estimate
of an embedded pair of interpolants of two orders, as in Fehlberg's step-size control:
Hairer, Norsett & Wanner 1993, Solving ODEs I, sec. II.4), taken as the bound of a
rectangular error fully correlated along slip: ``+ v v^T / 3`` with ``v`` the curve
parameters of ``d``. Zero at the tested loads; with two tested loads there is no second
interpolant and the band holds the tested curves' uncertainty only.
"""

from __future__ import annotations

import functools
import warnings
from collections.abc import Mapping
from dataclasses import asdict, dataclass

import numpy as np
from scipy.interpolate import PchipInterpolator

from fitting.curve import DEGREES, PowerCurve
from fitting.errors import DegreeError, LoadExtrapolationWarning, LoadRangeError
from fitting.polynomial import (branch_design, branch_from_solution, curve_value, lobatto_grid,
                                parameter_gradient, solution_to_parameters)

GRID_POINTS = 101
METHODS = ("auto", "linear", "pchip")


@dataclass(frozen=True)
class InterpolatedCurve(PowerCurve):
    """The curve at ``load_n``; ``fit_rmse`` is the RMS misfit of its polynomial to the
    interpolated grid values (0 to rounding for linear interpolation: a weighted sum of
    polynomials is one). Its covariance is the tested curves' propagated through the
    interpolation, its ``scatter_sd`` and ``k95`` linear across load between theirs."""

    load_n: float
    method: str
    tested_loads_n: tuple[float, ...]
    extrapolated: bool
    fit_rmse: float

    def to_dict(self) -> dict:
        return {**asdict(self), "coefficients": list(self.coefficients), "degree": self.degree}


@dataclass(frozen=True)
class LoadCurves:
    """Curves at many loads at once: row ``i`` of ``coefficients`` and of ``below_zero``
    (braked branch J, K) are the curve at ``loads_n[i]``; all share [slip_min, slip_max]."""

    loads_n: np.ndarray
    coefficients: np.ndarray
    below_zero: np.ndarray
    slip_min: float
    slip_max: float
    method: str
    tested_loads_n: tuple[float, ...]
    extrapolated: np.ndarray
    fit_rmse: np.ndarray
    covariance: np.ndarray | None = None
    scatter_sd: np.ndarray | None = None
    k95: np.ndarray | None = None

    def curve(self, i: int) -> InterpolatedCurve:
        return InterpolatedCurve(
            coefficients=tuple(float(a) for a in self.coefficients[i]), slip_min=self.slip_min,
            slip_max=self.slip_max, step_below_zero=float(self.below_zero[i, 0]),
            slope_below_zero=float(self.below_zero[i, 1]), load_n=float(self.loads_n[i]),
            method=self.method,
            tested_loads_n=self.tested_loads_n, extrapolated=bool(self.extrapolated[i]),
            fit_rmse=float(self.fit_rmse[i]),
            covariance=None if self.covariance is None
            else tuple(tuple(float(v) for v in row) for row in self.covariance[i]),
            scatter_sd=float("nan") if self.scatter_sd is None else float(self.scatter_sd[i]),
            k95=float("nan") if self.k95 is None else float(self.k95[i]))


def _check_loads(tested: np.ndarray, query: np.ndarray, allow_extrapolation: bool) -> np.ndarray:
    """Mask of queries outside the tested loads; raise where that is not allowed."""
    if tested.size == 0:
        raise LoadRangeError("no tested loads to interpolate from")
    if not np.all(np.isfinite(query)) or np.any(query <= 0):
        raise LoadRangeError(f"loads must be finite and > 0 N, got {query[~(query > 0)][:3]}")
    outside = (query < tested[0]) | (query > tested[-1])
    span = f"{tested[0]:g}-{tested[-1]:g} N" if tested.size > 1 else f"{tested[0]:g} N only"
    if np.any(outside):
        bad = query[outside][0]
        if tested.size < 2:
            raise LoadRangeError(f"load {bad:g} N: one tested load ({span}), nothing to "
                                 "interpolate from")
        if not allow_extrapolation:
            raise LoadRangeError(f"load {bad:g} N outside the tested loads ({span}); pass "
                                 "allow_extrapolation to extrapolate linearly from the two "
                                 "nearest loads")
        warnings.warn(f"{int(outside.sum())} load(s) outside the tested loads ({span}), e.g. "
                      f"{bad:g} N: extrapolated linearly", LoadExtrapolationWarning, stacklevel=3)
    return outside


def _across_load(tested: np.ndarray, values: np.ndarray, query: np.ndarray,
                 method: str, outside: np.ndarray) -> np.ndarray:
    """Grid values (tested loads x slips) interpolated to the query loads (queries x slips)."""
    if tested.size == 1:
        return np.repeat(values, query.size, axis=0)
    hi = np.clip(np.searchsorted(tested, query), 1, tested.size - 1)
    t = ((query - tested[hi - 1]) / (tested[hi] - tested[hi - 1]))[:, None]
    out = (1.0 - t) * values[hi - 1] + t * values[hi]  # linear, also the extrapolation
    if method == "pchip" and np.any(~outside):
        out[~outside] = PchipInterpolator(tested, values, axis=0)(query[~outside])
    return out


@functools.lru_cache(maxsize=64)
def _projection(slip_min: float, slip_max: float, degree: int, grid_points: int,
                branch: int) -> tuple[np.ndarray, np.ndarray]:
    """Slip grid and the matrix taking values on it to the least-squares solution (Chebyshev
    coefficients, then ``branch`` braked-branch terms) of :func:`branch_design` there."""
    grid = lobatto_grid(slip_min, slip_max, grid_points)
    return grid, np.linalg.pinv(branch_design(grid, slip_min, slip_max, degree, branch)).T


def branch_terms(curve: PowerCurve) -> int:
    """Braked-branch terms a curve uses: 2 with a slope, 1 with a step only, else 0."""
    return 2 if curve.slope_below_zero else 1 if curve.step_below_zero else 0


@dataclass(frozen=True)
class _Setup:
    """What an interpolation across load of one quantity's tested curves needs: the curves
    by load, the shared slip range, the result's degree, the method, the slip grid, the
    projection (grid values -> solution) and the tested curves' values on the grid."""

    tested: np.ndarray
    ordered: list
    slip_min: float
    slip_max: float
    degree: int
    method: str
    grid: np.ndarray
    projection: np.ndarray
    values: np.ndarray

    @classmethod
    def of(cls, curves: Mapping[float, PowerCurve], method: str, degree: int | None,
           grid_points: int) -> _Setup:
        if method not in METHODS:
            raise ValueError(f"method {method!r}: one of {METHODS}")
        tested = np.array(sorted(float(k) for k in curves))
        if tested.size == 0:
            raise LoadRangeError("no tested loads to interpolate from")
        ordered = [curves[k] for k in sorted(curves, key=float)]
        lo, hi = max(c.slip_min for c in ordered), min(c.slip_max for c in ordered)
        if lo >= hi:
            raise LoadRangeError(f"the tested loads {tested.tolist()} share no slip range")
        degree = max(c.degree for c in ordered) if degree is None else degree
        if degree not in DEGREES:
            raise DegreeError(f"degree {degree!r} outside 3-7")
        method = ("pchip" if tested.size >= 3 else "linear") if method == "auto" else method
        branch = max(branch_terms(c) for c in ordered) if lo < 0 else 0
        grid, projection = _projection(lo, hi, degree, grid_points, branch)
        values = np.array([curve_value(c.coefficients, grid, c.step_below_zero,
                                       c.slope_below_zero) for c in ordered])
        return cls(tested, ordered, lo, hi, degree, method, grid, projection, values)


class LoadPolynomial:
    """The interpolated curves' parameters ``(a_0 ... a_n, J, K)`` as an exact polynomial of
    load per interval between tested loads: across load the grid values are PCHIP (or linear)
    pieces, cubic in load at each slip, and the refit is linear, so each piece's four
    coefficient vectors are projected once (the same curves as :func:`interpolate_loads`,
    to rounding, at any number of loads for a few multiply-adds each). Extrapolation:
    linear from the two nearest tested loads, as there."""

    def __init__(self, curves: Mapping[float, PowerCurve], method: str = "auto",
                 degree: int | None = None, grid_points: int = GRID_POINTS) -> None:
        setup = _Setup.of(curves, method, degree, grid_points)
        self.tested, self.method, self.degree = setup.tested, setup.method, setup.degree
        self.slip_min, self.slip_max = setup.slip_min, setup.slip_max
        to_theta = setup.projection @ solution_to_parameters(
            setup.slip_min, setup.slip_max, setup.degree, setup.projection.shape[1])
        self._setup, self._to_theta = setup, to_theta
        self._at_tested = setup.values @ to_theta  # tested loads x p
        if setup.tested.size >= 2 and setup.method == "pchip":
            pieces = PchipInterpolator(setup.tested, setup.values, axis=0).c  # 4 x L-1 x grid
            self._pieces = pieces @ to_theta  # 4 x L-1 x p: cubic in (load - tested[k])
        else:
            self._pieces = None

    @property
    def at_tested(self) -> np.ndarray:
        """Parameters at the tested loads (tested loads x p)."""
        return self._at_tested

    @property
    def pieces(self) -> np.ndarray | None:
        """PCHIP pieces of the parameters (4 x L-1 x p; row 0 the cubic term, in
        ``load - tested[k]``), None for linear interpolation."""
        return self._pieces

    def spread_at_tested(self) -> np.ndarray:
        """``(scatter_sd, k95)`` of each tested curve (tested loads x 2; linear across load
        as in :func:`interpolate_loads`)."""
        return np.array([[c.scatter_sd, c.k95] for c in self._setup.ordered])

    def covariance_pieces(self) -> tuple[np.ndarray, np.ndarray] | None:
        """The covariance of :func:`interpolate_loads` (``uncertainty=True``) as a polynomial
        of load: ``(inside, ends)``. ``inside`` (L-1 x 7 x p x p) holds the coefficients of
        ``t**r`` (r = 0..6, ``t = (load - tested[k]) / (tested[k+1] - tested[k])``) between
        tested loads ``k`` and ``k+1``: the propagated tested covariances
        (:func:`_propagate`: its forward-difference sensitivities are cubic in load, their
        products sextic) plus the interpolation error (:func:`_interpolation_error`). ``ends``
        (L x p x p): each tested curve's covariance mapped to the parameters, ``D_k``;
        outside the tested loads (linear extrapolation from ``k``, ``k+1``) the covariance is
        ``(1 - t)**2 D_k + t**2 D_k+1``. None when a tested curve carries no covariance."""
        setup, to_theta = self._setup, self._to_theta
        if not all(c.covariance is not None for c in setup.ordered):
            return None
        tested, values, p = setup.tested, setup.values, to_theta.shape[1]
        mapped = [parameter_gradient(setup.grid, c.degree).T for c in setup.ordered]
        ends = np.array([(m @ to_theta).T @ np.asarray(c.covariance) @ (m @ to_theta)
                         for m, c in zip(mapped, setup.ordered)])
        inside = np.zeros((max(tested.size - 1, 0), 7, p, p))
        if tested.size < 2:
            return inside, ends
        width = np.diff(tested)[:, None]  # dx = t * width
        powers = width ** np.arange(4)[::-1, None, None]  # c[m] dx**(3-m): w**(3-m) t**(3-m)
        linear = _linear_pieces(tested, values)
        base = PchipInterpolator(tested, values, axis=0).c if setup.method == "pchip" else linear
        delta = _bump(values)
        for k, c in enumerate(setup.ordered):
            bumped = values.copy()
            bumped[k] += delta
            again = (PchipInterpolator(tested, bumped, axis=0).c if setup.method == "pchip"
                     else _linear_pieces(tested, bumped))
            sensitivity = ((again - base) / delta * powers)[::-1]  # t**0 ... t**3 x L-1 x grid
            a = np.einsum("ig,jkg,gb->kjib", mapped[k], sensitivity, to_theta)  # L-1 x 4 x pk x p
            cov = np.asarray(c.covariance)
            for j in range(4):
                for jj in range(4):
                    inside[:, j + jj] += np.einsum("kia,ij,kjb->kab", a[:, j], cov, a[:, jj])
        if tested.size >= 3:  # interpolation error: v v^T / 3, v = (PCHIP - linear) -> theta
            pchip = PchipInterpolator(tested, values, axis=0).c
            v = np.einsum("jkg,gb->kjb", ((pchip - linear) * powers)[::-1], to_theta)
            for j in range(4):
                for jj in range(4):
                    inside[:, j + jj] += np.einsum("ka,kb->kab", v[:, j], v[:, jj]) / 3.0
        return inside, ends

    def parameters(self, loads_n, allow_extrapolation: bool = False
                   ) -> tuple[np.ndarray, np.ndarray]:
        """(parameters, loads x p; extrapolated mask) at ``loads_n`` (raises
        :class:`LoadRangeError` as :func:`interpolate_loads`)."""
        query = np.atleast_1d(np.asarray(loads_n, dtype=float)).ravel()
        outside = _check_loads(self.tested, query, allow_extrapolation)
        tested, at = self.tested, self._at_tested
        if tested.size == 1:
            return np.repeat(at, query.size, axis=0), outside
        hi = np.clip(np.searchsorted(tested, query), 1, tested.size - 1)
        t = ((query - tested[hi - 1]) / (tested[hi] - tested[hi - 1]))[:, None]
        out = (1.0 - t) * at[hi - 1] + t * at[hi]
        if self._pieces is not None and np.any(~outside):
            k = hi[~outside] - 1
            dx = (query[~outside] - tested[k])[:, None]
            c = self._pieces[:, k]
            out[~outside] = ((c[0] * dx + c[1]) * dx + c[2]) * dx + c[3]
        return out, outside


def interpolate_loads(curves: Mapping[float, PowerCurve], loads_n, *, method: str = "auto",
                      degree: int | None = None, allow_extrapolation: bool = False,
                      grid_points: int = GRID_POINTS, uncertainty: bool = True) -> LoadCurves:
    """Curves at every load of ``loads_n`` from ``curves`` (tested load in N -> curve of one
    quantity). ``degree``: of the fitted result, default the highest tested degree.
    ``uncertainty``: carry the tested curves' covariance through (:func:`_propagate`) when
    every one has it.
    Raises :class:`LoadRangeError` (load outside the tested ones without
    ``allow_extrapolation``, no common slip range) or :class:`DegreeError`."""
    query = np.atleast_1d(np.asarray(loads_n, dtype=float)).ravel()
    setup = _Setup.of(curves, method, degree, grid_points)
    tested, ordered, lo, hi, degree, method = (setup.tested, setup.ordered, setup.slip_min,
                                               setup.slip_max, setup.degree, setup.method)
    outside = _check_loads(tested, query, allow_extrapolation)
    grid, projection = setup.grid, setup.projection
    values = _across_load(tested, setup.values, query, method, outside)
    coefficients, below = branch_from_solution(values @ projection, lo, hi, degree)
    misfit = curve_value(coefficients[:, None, :], grid, below[:, :1], below[:, 1:]) - values
    known = uncertainty and all(c.covariance is not None for c in ordered)
    to_theta = projection @ solution_to_parameters(lo, hi, degree, projection.shape[1])
    covariance = (_propagate(ordered, tested, query, method, outside, grid, to_theta)
                  + _interpolation_error(tested, setup.values, query, outside, to_theta)
                  if known else None)
    return LoadCurves(loads_n=query, coefficients=coefficients, below_zero=below,
                      slip_min=lo, slip_max=hi,
                      method=method, tested_loads_n=tuple(tested.tolist()), extrapolated=outside,
                      fit_rmse=np.sqrt(np.mean(misfit ** 2, axis=1)), covariance=covariance,
                      **(_linear_in_load(ordered, tested, query, outside) if known else {}))


def _linear_in_load(ordered: list[PowerCurve], tested: np.ndarray, query: np.ndarray,
                    outside: np.ndarray) -> dict[str, np.ndarray]:
    """``scatter_sd`` and ``k95`` at the query loads: linear across load between the tested
    curves' (a property of the rig at that load, not of one curve)."""
    both = np.array([[c.scatter_sd, c.k95] for c in ordered])
    out = _across_load(tested, both, query, "linear", outside)
    return {"scatter_sd": np.maximum(out[:, 0], 0.0), "k95": np.maximum(out[:, 1], 0.0)}


def _interpolation_error(tested: np.ndarray, values: np.ndarray, query: np.ndarray,
                         outside: np.ndarray, to_theta: np.ndarray) -> np.ndarray | float:
    """Covariance (queries x p x p) of the across-load interpolation error (module doc):
    ``v v^T / 3``, ``v`` the parameters of PCHIP less linear on the grid; 0 with fewer than
    three tested loads or outside them (extrapolation is linear: no second estimate)."""
    if tested.size < 3:
        return 0.0
    difference = (_across_load(tested, values, query, "pchip", outside)
                  - _across_load(tested, values, query, "linear", outside))
    v = difference @ to_theta  # queries x p
    return np.einsum("qa,qb->qab", v, v) / 3.0


def _bump(values: np.ndarray) -> float:
    """The forward-difference step of :func:`_propagate`: 1e-6 of the values' scale."""
    return 1e-6 * max(float(np.ptp(values)), float(np.max(np.abs(values))), 1e-300)


def _linear_pieces(tested: np.ndarray, values: np.ndarray) -> np.ndarray:
    """Linear interpolation across load as PCHIP's ``.c`` (4 x L-1 x grid, cubic first)."""
    out = np.zeros((4,) + values[:-1].shape)
    out[2], out[3] = np.diff(values, axis=0) / np.diff(tested)[:, None], values[:-1]
    return out


def _propagate(ordered: list[PowerCurve], tested: np.ndarray, query: np.ndarray, method: str,
               outside: np.ndarray, grid: np.ndarray, to_theta: np.ndarray) -> np.ndarray:
    """Covariance (queries x p x p) of the interpolated curves' parameters: the tested curves
    are independent (different runs), the across-load step is linearised (its sensitivity
    to each tested curve's grid values by a forward difference: PCHIP's slopes depend on the
    values; exact for linear), the refit is linear (``to_theta``: grid values -> theta)."""
    values = np.array([curve_value(c.coefficients, grid, c.step_below_zero, c.slope_below_zero)
                       for c in ordered])
    base = _across_load(tested, values, query, method, outside)
    delta = _bump(values)
    out = 0.0
    for k, c in enumerate(ordered):
        bumped = values.copy()
        bumped[k] += delta
        sensitivity = (_across_load(tested, bumped, query, method, outside) - base) / delta
        design = parameter_gradient(grid, c.degree)  # grid x p_k
        mapped = np.einsum("qg,gi,gj->qij", sensitivity, design, to_theta)  # q x p_k x p
        out = out + np.einsum("qia,ij,qjb->qab", mapped, np.asarray(c.covariance), mapped)
    return out


def interpolate_load(curves: Mapping[float, PowerCurve], load_n: float,
                     **options) -> InterpolatedCurve:
    """The curve at one load; options as :func:`interpolate_loads`."""
    return interpolate_loads(curves, [load_n], **options).curve(0)
