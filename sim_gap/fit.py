"""Bounded robust least squares of a candidate on standardised residuals
(``scipy.optimize.least_squares``, trust-region reflective, soft-L1 loss beyond 3 sigma;
Huber 1981, Robust Statistics)."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
import pandas as pd
from scipy.optimize import least_squares

from sim_gap.candidates import Candidate
from sim_gap.simulated import Simulated
from sim_gap.vocabulary import QUANTITIES, model_error_floor

#: a held-out standardised residual is clipped here (one wild point must not decide a score)
RESIDUAL_CLIP = 30.0
#: robust fitting: soft-L1 loss beyond this many sigmas (keeps a gradient far from the data)
SOFT_L1_SCALE_SIGMA = 3.0


def quantities_of(points: pd.DataFrame) -> list[str]:
    return [q for q in QUANTITIES if q in points]


#: a quantity computed from others of the same run: ``R = T/r - DP``
DERIVED = {"resistance_n": ("dp_n", "torque_nm")}


def independent_quantities(quantities: list[str]) -> list[str]:
    """``quantities`` without those computed from others among them (:data:`DERIVED`)."""
    return [q for q in quantities if not (q in DERIVED and set(DERIVED[q]) <= set(quantities))]


def independent_entries(points: pd.DataFrame) -> np.ndarray:
    """Mask (points x :func:`quantities_of`) of the measured entries that carry information
    of their own: every finite value, except a motion resistance measured beside both the
    drawbar pull and the torque of its point, since ``R = T/r - DP`` is computed from them
    (counting it again would weigh those two twice, and their errors with them)."""
    quantities = quantities_of(points)
    where = np.isfinite(points[quantities].to_numpy(float))
    i = quantities.index
    for q in set(quantities) - set(independent_quantities(quantities)):
        where[:, i(q)] &= ~np.logical_and.reduce([where[:, i(s)] for s in DERIVED[q]])
    return where


def sigmas(points: pd.DataFrame, radius_m: float) -> dict[str, np.ndarray]:
    """Per-point uncertainty of each quantity for fitting. Where the point's source measured
    its run-to-run repeatability (``<q>_repeat_sd``: replicate runs, or the spread of a
    points CSV row's repeats), the larger of the point's own uncertainty ``<q>_se`` (its
    GUM budget, or SE) and that repeatability; elsewhere ``<q>_se`` and the assumed
    repeatability :func:`~sim_gap.vocabulary.model_error_floor` in quadrature."""
    load = points["wheel_load_n"].to_numpy(float)
    out = {}
    for q in quantities_of(points):
        se = points[f"{q}_se"].to_numpy(float)
        repeat = (points[f"{q}_repeat_sd"].to_numpy(float) if f"{q}_repeat_sd" in points
                  else np.full(se.shape, np.nan))
        assumed = np.hypot(se, model_error_floor(q, load, radius_m))
        out[q] = np.where(np.isfinite(repeat), np.fmax(se, repeat), assumed)
    return out


def standardised_residuals(points: pd.DataFrame, predicted: dict[str, np.ndarray],
                           sigma: dict[str, np.ndarray], clip: float = RESIDUAL_CLIP
                           ) -> np.ndarray:
    """``(measured - predicted)/sigma`` clipped to ``+-clip``, shape (points, quantities);
    NaN where not measured. A relative sinkage (``attrs['sinkage_relative']``) has its mean
    removed."""
    return standardiser(points)(predicted, sigma, clip)


def standardiser(points: pd.DataFrame) -> Callable[..., np.ndarray]:
    """:func:`standardised_residuals` at fixed ``points``, their columns read once: a fit
    calls it hundreds of times, and each column read costs pandas a deep copy of the
    points' ``attrs``."""
    quantities = quantities_of(points)
    measured = points[quantities].to_numpy(float)
    relative = bool(points.attrs.get("sinkage_relative"))

    def standardised(predicted: dict[str, np.ndarray], sigma: dict[str, np.ndarray],
                     clip: float = RESIDUAL_CLIP) -> np.ndarray:
        return _standardised(measured, quantities, predicted, sigma, relative, clip)

    return standardised


def _standardised(measured: np.ndarray, quantities: list[str],
                  predicted: dict[str, np.ndarray], sigma: dict[str, np.ndarray],
                  sinkage_relative: bool, clip: float) -> np.ndarray:
    cols = []
    for i, q in enumerate(quantities):
        r = (measured[:, i] - predicted[q]) / sigma[q]
        if q == "sinkage_m" and sinkage_relative:
            r = r - np.nanmean(r)
        cols.append(np.clip(r, -clip, clip))
    return np.column_stack(cols)


def residual_function(sim: Simulated, points: pd.DataFrame, sigma: dict[str, np.ndarray]
                      ) -> Callable[[dict[str, float | str]], np.ndarray]:
    """Model values -> the unclipped standardised residuals of the measured entries (flat),
    with the points' columns read once: a fit evaluates it hundreds of times."""
    where = independent_entries(points)
    predict, standardised = sim.predictor(points), standardiser(points)
    return lambda values: standardised(predict(values), sigma, np.inf)[where]


def to_values(c: Candidate, u: np.ndarray) -> dict[str, float | str]:
    """The model values of ``c`` at internal ``u``: its laws first, then the parameters."""
    return {**c.law_values(),
            **{p.name: float(np.exp(x) if p.log else x) for p, x in zip(c.params, u)}}


def strengths(values: dict[str, float | str]) -> dict[str, float]:
    """The fitted numbers of model ``values`` (without the laws)."""
    return {k: v for k, v in values.items() if not isinstance(v, str)}


def to_internal(c: Candidate, values: dict[str, float | str]) -> np.ndarray:
    """Internal coordinates of ``values`` (a parameter they lack: its start value)."""
    x = [values.get(p.name, p.start) for p in c.params]
    return np.array([np.log(v) if p.log else v for p, v in zip(c.params, x)])


def internal_bounds(c: Candidate) -> tuple[np.ndarray, np.ndarray]:
    """Lower and upper bounds of ``c``'s parameters in internal coordinates."""
    return (np.array([np.log(p.lower) if p.log else p.lower for p in c.params]),
            np.array([np.log(p.upper) if p.log else p.upper for p in c.params]))


@dataclass(frozen=True)
class FitResult:
    candidate: Candidate
    values: dict[str, float | str]  # laws and fitted parameters (see ``to_values``)
    chi2: float
    n_residuals: int

    @property
    def n_params(self) -> int:
        return len(self.candidate.params)


def fit_candidate(sim: Simulated, c: Candidate, points: pd.DataFrame,
                  sigma: dict[str, np.ndarray], start: dict[str, float] | None = None,
                  max_nfev: int = 40, loss: str = "soft_l1") -> FitResult:
    """Best parameters of ``c`` on ``points`` (``sigma``: the points' uncertainties;
    ``loss``: ``soft_l1`` (robust) or ``linear`` (plain least squares))."""
    lo, hi = internal_bounds(c)
    u0 = to_internal(c, start) if start else to_internal(c, {p.name: p.start for p in c.params})
    u0 = np.clip(u0, lo + 1e-9 * (hi - lo), hi - 1e-9 * (hi - lo))

    residuals_at = residual_function(sim, points, sigma)

    def residuals(u):
        return np.nan_to_num(residuals_at(to_values(c, u)), nan=1e3, posinf=1e3, neginf=-1e3)

    sol = least_squares(residuals, u0, bounds=(lo, hi), x_scale=np.maximum(hi - lo, 1e-9) / 10,
                        diff_step=1e-3, max_nfev=max_nfev, xtol=1e-4, ftol=1e-4,
                        loss=loss, f_scale=SOFT_L1_SCALE_SIGMA)
    return FitResult(c, to_values(c, sol.x), float(np.sum(sol.fun ** 2)), int(sol.fun.size))


@dataclass(frozen=True)
class MapFit:
    """A candidate's maximum a posteriori fit: the fit, its internal coordinates, the
    prediction of every measured entry (flat, row-major over points x quantities) and its
    Jacobian with respect to the internal coordinates (entries x parameters)."""

    fit: FitResult
    internal: np.ndarray
    predicted: np.ndarray
    jac: np.ndarray


def fit_map(sim: Simulated, c: Candidate, points: pd.DataFrame, sigma: dict[str, np.ndarray],
            prior: tuple[np.ndarray, np.ndarray], start: dict[str, float] | None = None,
            max_nfev: int = 40) -> MapFit:
    """The MAP of ``c``: least squares of the standardised residuals (noise ``sigma``)
    stacked with one prior residual ``(u - centre)/sd`` per parameter (Gaussian likelihood
    and prior; MacKay 2003 ch. 27), bounded by the law's range."""
    centre, sd = prior
    lo, hi = internal_bounds(c)
    u0 = to_internal(c, start) if start else to_internal(c, {p.name: p.start for p in c.params})
    u0 = np.clip(u0, lo + 1e-9 * (hi - lo), hi - 1e-9 * (hi - lo))
    residuals_at = residual_function(sim, points, sigma)
    measured = points[quantities_of(points)].to_numpy(float)
    where = independent_entries(points)
    scale = np.column_stack([sigma[q] for q in quantities_of(points)])[where]

    def data(u):
        return np.nan_to_num(residuals_at(to_values(c, u)), nan=1e3, posinf=1e3, neginf=-1e3)

    sol = least_squares(lambda u: np.concatenate([data(u), (u - centre) / sd]), u0,
                        bounds=(lo, hi), x_scale=np.maximum(hi - lo, 1e-9) / 10,
                        diff_step=1e-3, max_nfev=max_nfev, xtol=1e-4, ftol=1e-4)
    n = scale.size
    r = sol.fun[:n]
    fit = FitResult(c, to_values(c, sol.x), float(np.sum(r ** 2)), int(n))
    return MapFit(fit, sol.x, measured[where] - scale * r, -scale[:, None] * sol.jac[:n])
