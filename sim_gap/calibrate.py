"""Calibrate the base model's soil on measured points (no effect), with priors from the
published soil tables (:mod:`sim_gap.priors`), and the posterior of the fit.

Maximum a posteriori by bounded least squares on the standardised residuals of every
measured quantity (a relative sinkage has its offset profiled out) stacked with one prior
residual per parameter, ``(x - centre)/spread`` (log space for the moduli). Posterior: the
Laplace approximation at the MAP (Laplace 1774; MacKay 2003, Information Theory, Inference
and Learning Algorithms, ch. 27), covariance ``(J^T J)^-1`` of the stacked residuals'
Jacobian ``J`` in the fitted coordinates. Each quantity's sigmas are scaled so that its
reduced chi-square at the MAP is at least 1 (a second fit with the scaled sigmas): the
model's misfit of one quantity (e.g. a relative sinkage measured to 0.3 mm) must not
outweigh the others, and the posterior is not narrower than the misfit allows. The
pressure-sinkage modulus is fitted as ``kphi`` with ``kc = 0``, i.e. ``k = kc/b + kphi`` at
the wheel's one width. A MAP on a bound has status ``at_bound`` (its covariance is not a
posterior), one that ran out of evaluations ``not_converged``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pandas as pd
from scipy.optimize import least_squares

import terramechanics as tm
from sim_gap.fit import quantities_of, sigmas, standardiser
from sim_gap.priors import ParamPrior, soil_prior
from sim_gap.simulated import Simulated

#: fitted parameters and their bounds (natural units)
BOUNDS = {"soil.kphi": (1e4, 1e8), "soil.n": (0.3, 2.0), "soil.cohesion_pa": (0.0, 5e3),
          "soil.friction_angle_deg": (15.0, 50.0), "soil.shear_modulus_m": (1e-4, 0.1)}
#: a MAP closer to a bound than this fraction of the (internal) range is on the bound
AT_BOUND_FRACTION = 1e-3
#: finite-difference step of the prediction bands, in posterior standard deviations
BAND_STEP_SIGMA = 0.1


@dataclass(frozen=True)
class SoilCalibration:
    """A soil calibration: the model at the MAP, the posterior covariance in the fitted
    coordinates (``names``, log for ``log``), the chi-squares (with the sigmas scaled by
    ``sigma_scale`` per quantity) and a status (``ok``, ``at_bound`` with the parameters in
    ``at_bound``, or ``not_converged``)."""

    model: tm.WheelModel
    names: tuple[str, ...]
    log: tuple[bool, ...]
    internal: np.ndarray
    covariance: np.ndarray
    chi2_data: float
    chi2_prior: float
    n_data: int
    status: str
    at_bound: tuple[str, ...]
    start: str
    sigma_scale: dict[str, float]

    @property
    def ok(self) -> bool:
        return self.status == "ok"

    @property
    def values(self) -> dict[str, float]:
        return _to_values(self.names, self.log, self.internal)

    def std(self) -> dict[str, float]:
        """Posterior standard deviation of each parameter in its natural unit (a log
        parameter's: value times its log-space std, to first order)."""
        sd = np.sqrt(np.diag(self.covariance))
        return {n: float(sd[i] * (self.values[n] if lg else 1.0))
                for i, (n, lg) in enumerate(zip(self.names, self.log))}

    def interval(self, name: str, z: float = 1.0) -> tuple[float, float]:
        """The ``z``-sigma posterior interval of ``name`` (log-normal for a log parameter)."""
        i = self.names.index(name)
        lo, hi = (self.internal[i] + s * z * np.sqrt(self.covariance[i, i]) for s in (-1, 1))
        return (float(np.exp(lo)), float(np.exp(hi))) if self.log[i] else (float(lo), float(hi))


def _to_values(names, log, u) -> dict[str, float]:
    return {n: float(np.exp(x) if lg else x) for n, lg, x in zip(names, log, u)}


def _internal(names, log, values) -> np.ndarray:
    return np.array([np.log(values[n]) if lg else values[n] for n, lg in zip(names, log)])


def _starts(model: tm.WheelModel, priors: tuple[ParamPrior, ...], n_starts: int):
    """The prior centre, the model's own soil, then each literature soil (at the width)."""
    b = model.wheel.width_m
    centre = {p.name: p.centre_value for p in priors}
    soils = [("prior_centre", centre)] + [
        (s.name, {"soil.kphi": s.kc / b + s.kphi, "soil.n": s.n,
                  "soil.cohesion_pa": s.cohesion_pa,
                  "soil.friction_angle_deg": s.friction_angle_deg,
                  "soil.shear_modulus_m": s.shear_modulus_m})
        for s in [model.soil, *tm.SOILS.values()]]
    return soils[:n_starts]


def calibrate_soil(points: pd.DataFrame, model: tm.WheelModel,
                   priors: tuple[ParamPrior, ...] | None = None, n_starts: int = 5,
                   max_nfev: int = 200, quantities: tuple[str, ...] | None = None
                   ) -> SoilCalibration:
    """The MAP soil of ``model`` (effects kept as they are) on ``points`` (only the
    ``quantities`` given, default all measured) and its Laplace posterior: the best of
    ``n_starts`` starts (the fit has several local minima)."""
    if quantities is not None:
        unknown = set(quantities) - set(quantities_of(points))
        if unknown:
            raise ValueError(f"quantities {sorted(unknown)} not measured in the points")
        dropped = [c for q in quantities_of(points) if q not in quantities
                   for c in (q, f"{q}_se")]
        attrs, points = dict(points.attrs), points.drop(columns=dropped)
        points.attrs.update(attrs)
    priors = soil_prior(model.wheel.width_m) if priors is None else priors
    if {p.name for p in priors} != set(BOUNDS):
        raise ValueError(f"priors must cover exactly {sorted(BOUNDS)}")
    names = tuple(BOUNDS)
    prior = {p.name: p for p in priors}
    log = tuple(prior[n].log for n in names)
    lo, hi = (_internal(names, log, {n: BOUNDS[n][i] for n in names}) for i in (0, 1))
    base = model.with_soil(kc=0.0)
    sim, sig = Simulated(base), sigmas(points, model.wheel.radius_m)
    quantities = quantities_of(points)
    measured = np.isfinite(points[quantities].to_numpy(float))
    centre = np.array([prior[n].centre for n in names])
    spread = np.array([prior[n].spread for n in names])

    predict, standardised = sim.predictor(points), standardiser(points)

    def data_residuals(u, scale):
        scaled = {q: sig[q] * scale[q] for q in quantities}
        r = standardised(predict(_to_values(names, log, u)), scaled, np.inf)
        return np.nan_to_num(r, nan=1e3, posinf=1e3, neginf=-1e3)

    def fit(u0, scale):
        u0 = np.clip(u0, lo + 1e-6 * (hi - lo), hi - 1e-6 * (hi - lo))
        return least_squares(
            lambda u: np.concatenate([data_residuals(u, scale)[measured], (u - centre) / spread]),
            u0, bounds=(lo, hi), x_scale=spread, diff_step=1e-4, max_nfev=max_nfev,
            xtol=1e-6, ftol=1e-8, loss="linear")

    scale = {q: 1.0 for q in quantities}
    best = None
    for label, start in _starts(model, priors, n_starts):
        sol = fit(_internal(names, log, start), scale)
        if best is None or sol.cost < best[1].cost:
            best = label, sol
    r = data_residuals(best[1].x, scale)
    for i, q in enumerate(quantities):
        has = measured[:, i]
        scale[q] = float(np.sqrt(max(1.0, np.sum(r[has, i] ** 2) / max(has.sum() - 1, 1))))
    best = best[0], fit(best[1].x, scale)
    label, sol = best
    n_data = int(measured.sum())
    chi2_data = float(np.sum(sol.fun[:n_data] ** 2))
    margin = AT_BOUND_FRACTION * (hi - lo)
    near = (sol.x - lo < margin) | (hi - sol.x < margin)
    at_bound = tuple(n for n, b in zip(names, near) if b)
    covariance = np.linalg.pinv(sol.jac.T @ sol.jac)
    status = "at_bound" if at_bound else ("ok" if sol.status > 0 else "not_converged")
    return SoilCalibration(
        model=base.with_parameters(_to_values(names, log, sol.x)), names=names, log=log,
        internal=sol.x, covariance=covariance, chi2_data=chi2_data,
        chi2_prior=float(np.sum(sol.fun[n_data:] ** 2)), n_data=n_data, status=status,
        at_bound=at_bound, start=label, sigma_scale=scale)


def predict_with_se(cal: SoilCalibration, load_n, slip, quantities=("dp_n", "sinkage_m")
                    ) -> dict[str, tuple[np.ndarray, np.ndarray]]:
    """Each quantity's prediction at (load, slip) and its posterior standard error, the
    covariance propagated to first order (``se^2 = g^T C g``, ``g`` by central differences
    of ``BAND_STEP_SIGMA`` posterior sigmas)."""
    def at(u):
        out = cal.model.with_parameters(_to_values(cal.names, cal.log, u)).curves(load_n, slip)
        return {q: out[q] for q in quantities}

    mean = at(cal.internal)
    sd = np.sqrt(np.diag(cal.covariance))
    grads = {q: [] for q in quantities}
    for i, step in enumerate(np.maximum(BAND_STEP_SIGMA * sd, 1e-9)):
        du = np.zeros_like(cal.internal)
        du[i] = step
        up, down = at(cal.internal + du), at(cal.internal - du)
        for q in quantities:
            grads[q].append((up[q] - down[q]) / (2 * step))
    out = {}
    for q in quantities:
        g = np.stack(grads[q], axis=-1)
        var = np.einsum("...i,ij,...j->...", g, cal.covariance, g)
        out[q] = (mean[q], np.sqrt(np.maximum(var, 0.0)))
    return out
