"""Can the campaign identify a candidate's free parameters? A fit of k parameters to a
handful of points always finds values, and a held-out score on so few points cannot tell a
real fit from an over-fit; such a call must be ``inconclusive``, never a confident ``[]``.

Three checks on the chosen candidate's full-data fit: (1) at least
:data:`MIN_POINTS_PER_PARAM` measured points (conditions; the quantities of one point share
its condition) per free parameter; (2) the Jacobian of the standardised residuals with
respect to the parameters, each column scaled by its parameter's fitted range (bounds,
log for log parameters), has full numerical rank: singular values above
:data:`RANK_RTOL` times the largest (a direction of the parameters the points do not
constrain makes the Fisher information ``J^T J`` singular; Rothenberg 1971, Econometrica
39(3):577-591, "Identification in parametric models"); (3) no parameter ends on a bound
of its range (within :data:`AT_BOUND_FRACTION` of it, log for log parameters), except a
strength at a lower bound of zero (that part of the law is off): a law pinned at its limit
cannot give what the data ask, and a second effect that makes up the rest only patches it
(the out-of-family bench: Bekker bulldozing under the weaker Rankine law, coefficient at
its upper limit 5, called "wheel_flexibility + bulldozing"). A fit on a bound is no fit
(the calibration's ``at_bound`` status, :mod:`sim_gap.calibrate`)."""

from __future__ import annotations

import numpy as np
import pandas as pd

from sim_gap.fit import FitResult, residual_function, to_internal, to_values
from sim_gap.simulated import Simulated

#: fewest measured points per free parameter for a confident call
MIN_POINTS_PER_PARAM = 3.0
#: a scaled singular value below this fraction of the largest is an unconstrained direction
RANK_RTOL = 1e-4
#: a parameter closer to a bound than this fraction of its range is on the bound
AT_BOUND_FRACTION = 1e-3
#: central-difference step, as a fraction of each parameter's (internal) range
STEP_FRACTION = 1e-3


def jacobian(sim: Simulated, fit: FitResult, points: pd.DataFrame,
             sigma: dict[str, np.ndarray]) -> np.ndarray:
    """d(standardised residual)/d(parameter / its internal range) at the fit, by central
    differences; rows: the measured residuals."""
    c = fit.candidate
    span = np.array([np.log(p.upper / p.lower) if p.log else p.upper - p.lower
                     for p in c.params])
    u = to_internal(c, fit.values)
    residuals_at = residual_function(sim, points, sigma)
    r = lambda x: residuals_at(to_values(c, x))  # noqa: E731

    cols = []
    for i, h in enumerate(STEP_FRACTION * span):
        du = np.zeros_like(u)
        du[i] = h
        cols.append((r(u + du) - r(u - du)) / (2 * STEP_FRACTION))
    return np.column_stack(cols)


def parameters_on_bounds(fit: FitResult) -> list[str]:
    """``name = value (lower|upper limit)`` of each free parameter of ``fit`` on a bound, a
    linear parameter at a lower bound of 0 excepted (the law's part it scales is off)."""
    out = []
    for p in fit.candidate.params:
        v = float(fit.values[p.name])
        frac = (np.log(v / p.lower) / np.log(p.upper / p.lower) if p.log
                else (v - p.lower) / (p.upper - p.lower))
        if frac > 1 - AT_BOUND_FRACTION:
            out.append(f"{p.name} = {v:.3g}, its upper limit")
        elif frac < AT_BOUND_FRACTION and (p.log or p.lower != 0):
            out.append(f"{p.name} = {v:.3g}, its lower limit")
    return out


def identification_problem(sim: Simulated, fit: FitResult, points: pd.DataFrame,
                           sigma: dict[str, np.ndarray]) -> str | None:
    """Why ``points`` cannot identify ``fit``'s parameters (one sentence), or None."""
    n, k, label = len(points), fit.n_params, fit.candidate.label
    if n < MIN_POINTS_PER_PARAM * k:
        return (f"{n} measured points cannot identify the {k} free parameters of {label} "
                f"(fewer than {MIN_POINTS_PER_PARAM:g} points per parameter): neither an "
                "effect nor its absence can be called")
    bound = parameters_on_bounds(fit)
    if bound:
        return (f"the fit of {label} ends on a bound ({'; '.join(bound)}): its law cannot give "
                "what the data ask, so neither it nor a second effect that makes up the rest "
                "can be called")
    s = np.linalg.svd(jacobian(sim, fit, points, sigma), compute_uv=False)
    rank = int(np.sum(s > RANK_RTOL * s[0])) if s.size and s[0] > 0 else 0
    if rank < k:
        return (f"the points fix only {rank} of the {k} free parameters of {label} (the "
                "Jacobian of the residuals is rank-deficient): neither an effect nor its "
                "absence can be called")
    return None
