"""Evidence of a hypothesis: the marginal likelihood of the measured points under a candidate
model with its parameters' priors, the measured noise and a model discrepancy.

The model of an observation (one quantity of one run) is Kennedy & O'Hagan's (2001, "Bayesian
calibration of computer models", JRSS B 63:425-464)::

    y = eta(u) + delta(x) + eps,      eps ~ N(0, sigma^2),   delta ~ GP(0, tau^2 k)

``eta`` the candidate's prediction at internal parameters ``u`` (prior ``N(mu, S)``),
``sigma`` the measured noise (:func:`sim_gap.fit.sigmas`), ``delta`` the discrepancy of the
base model, a Gaussian process per quantity over slip and log load whose amplitude is ``tau``
times the quantity's assumed repeatability floor ``f`` (:func:`sim_gap.vocabulary.
model_error_floor`) at each point: ``cov = tau^2 f_i f_j exp(-ds^2/2 l_s^2 - dlnW^2/2 l_W^2)``.

The evidence is the Laplace approximation at the MAP ``u*`` (MacKay 2003, Information Theory,
Inference and Learning Algorithms, ch. 27-28) in its linearised form: with ``eta(u) ~ eta* +
J (u - u*)`` the marginal of ``y`` is Gaussian, ``N(eta* + J (mu - u*), C + J S J^T)``, exact
for a model linear in its parameters and the Laplace evidence to first order otherwise. Its
Occam factor (a parameter the data pin down costs ``log(prior width / posterior width)``)
is what lets a one-effect explanation beat a two-effect one that fits as well.

``tau`` is integrated over a log-uniform grid (a scale prior, Jeffreys 1961): the base model
may be right to a quarter of the repeatability floor or wrong by as much as the quantity
itself: 128 floors is about the wheel load in drawbar pull at the loads of a lab campaign
(the floor is 1 % of the load + 0.3 N), and no model misses a force by more than the load it
carries (:data:`TAU_GRID`). A smooth error common to every source and level is discrepancy,
not evidence for an effect, whatever its size. The discrepancy is *shared*: one function of
slip and load for every source, multipass level and gravity level, so an error common to
sibling sources (a smooth and a lugged wheel on one soil) cancels in their contrast, which
only an effect (or the hypothesis "outside the candidates", :func:`covariances`'
``outside``) can carry.

The base model's error also has a part that is not smooth in slip and load: what differs
from one run to the next beyond the measured repeatability (the soil state under that run,
a law's shape between two tested slips). It is a *nugget* (Kennedy & O'Hagan 2001 sec. 4.2;
Gramacy & Lee 2012, "Cases for the nugget in modeling computer experiments", Statistics and
Computing 22:713-722): independent per entry, ``nu`` times the floor, integrated over
:data:`NUGGET_GRID` (none, or 1 to 64 floors, equal weights). Without it an error the smooth
discrepancy cannot bend to is read as evidence for whichever effect bends the curve there.
"""

from __future__ import annotations

import itertools
from collections.abc import Sequence
from dataclasses import dataclass, replace

import numpy as np
import pandas as pd
from scipy.linalg import cho_solve, cholesky
from scipy.linalg.lapack import dpotrf, dpotrs, dtrtrs
from scipy.special import log_ndtr, logsumexp

from sim_gap.fit import independent_entries, quantities_of
from sim_gap.vocabulary import model_error_floor

#: discrepancy length scales: a quarter of the slip range a campaign spans (-0.3 to 0.9), and
#: half a unit of log load (a factor 1.65 in load): smooth against one curve's knee, free
#: between loads that differ by a factor three
LENGTH_SLIP = 0.3
LENGTH_LOG_LOAD = 0.5
#: the shared discrepancy's amplitude in units of the repeatability floor (log-uniform)
TAU_GRID = np.geomspace(0.25, 128.0, 10)
#: the nugget's size in units of the floor (module docstring)
NUGGET_GRID = np.array([0.0, 1.0, 4.0, 16.0, 64.0])
#: the scatter of one run's soil about the campaign's, in units of the soil prior's spread
#: (:func:`run_soil`), equal weights: none, or a sixteenth to half the spread between
#: published soils (one prepared bin is one soil, so its runs differ by less than two soils
#: do; below a sixteenth the scatter is within the repeatability floor)
RUN_SOIL_GRID = np.array([0.0, 1 / 16, 1 / 8, 1 / 4, 1 / 2])
#: prior standard deviation of a profiled offset (a relative sinkage's unknown zero), m
OFFSET_PRIOR_SD_M = 0.1


@dataclass(frozen=True)
class Observations:
    """The measured entries of the points, flat: value, noise, floor, the point and quantity
    each belongs to; the unit-amplitude kernels of the shared discrepancy and of one apart
    per group (source, multipass, gravity); the design of profiled offsets."""

    y: np.ndarray
    sigma: np.ndarray
    floor: np.ndarray
    point: np.ndarray
    quantity: np.ndarray
    where: np.ndarray  # (points, quantities) mask of the measured entries
    kernel_shared: np.ndarray
    kernel_grouped: np.ndarray
    offsets: np.ndarray  # (entries, offsets) design, possibly zero columns
    kernel_run: np.ndarray | None = None  # :func:`run_soil`


def _unit_kernel(points: pd.DataFrame, point: np.ndarray, quantity: np.ndarray,
                 floor: np.ndarray) -> np.ndarray:
    entries = (points["slip"].to_numpy(float)[point],
               points["wheel_load_n"].to_numpy(float)[point], quantity, floor)
    return cross_kernel(entries, entries)


def cross_kernel(a: tuple[np.ndarray, ...], b: tuple[np.ndarray, ...]) -> np.ndarray:
    """The shared discrepancy's unit-amplitude covariance between entries ``a`` and ``b``,
    each ``(slip, wheel load N, quantity index, floor)`` (flat arrays)."""
    (slip_a, load_a, q_a, f_a), (slip_b, load_b, q_b, f_b) = a, b
    log_a, log_b = np.log(np.maximum(load_a, 1e-9)), np.log(np.maximum(load_b, 1e-9))
    d2 = (((slip_a[:, None] - slip_b[None, :]) / LENGTH_SLIP) ** 2
          + ((log_a[:, None] - log_b[None, :]) / LENGTH_LOG_LOAD) ** 2)
    same_q = q_a[:, None] == q_b[None, :]
    return np.where(same_q, np.exp(-0.5 * d2), 0.0) * f_a[:, None] * f_b[None, :]


def observations(points: pd.DataFrame, sigma: dict[str, np.ndarray], radius_m: float
                 ) -> Observations:
    """The flat observations of ``points`` with noise ``sigma`` (:func:`sim_gap.fit.sigmas`)."""
    quantities = quantities_of(points)
    values = points[quantities].to_numpy(float)
    where = independent_entries(points)
    point, qi = np.nonzero(where)
    load = points["wheel_load_n"].to_numpy(float)
    floor_by_q = np.column_stack([model_error_floor(q, load, radius_m) for q in quantities])
    sig = np.column_stack([sigma[q] for q in quantities])
    floor = floor_by_q[point, qi]
    shared = _unit_kernel(points, point, qi, floor)
    group = level_groups(points)[point]
    grouped = np.where(group[:, None] == group[None, :], shared, 0.0)
    offsets = np.zeros((point.size, 0))
    if points.attrs.get("sinkage_relative") and "sinkage_m" in quantities:
        offsets = (qi == quantities.index("sinkage_m")).astype(float)[:, None]
    return Observations(values[where], sig[where], floor, point, qi, where, shared, grouped,
                        offsets)


def level_groups(points: pd.DataFrame) -> np.ndarray:
    """Per point, the index of its source, multipass level and gravity level together."""
    return pd.factorize(pd.Series(list(zip(
        points["source"] if "source" in points else [""] * len(points),
        points["multipass"].to_numpy(int), points["gravity_mps2"].round(6))),
        dtype=object))[0]


def same_partition(a: np.ndarray, b: np.ndarray) -> bool:
    """Whether labels ``a`` and ``b`` (one per point) group the points alike."""
    pairs = pd.Series(list(zip(a.tolist(), b.tolist())), dtype=object)
    return pairs.nunique() == pd.Series(a).nunique() == pd.Series(b).nunique()


def apart_by(obs: Observations, levels: np.ndarray) -> Observations:
    """``obs`` whose second discrepancy is apart per value of ``levels`` (one per point: a
    multipass level, a gravity level, a wheel) instead of per source and level."""
    group = pd.factorize(pd.Series(list(levels), dtype=object))[0][obs.point]
    same = group[:, None] == group[None, :]
    return replace(obs, kernel_grouped=np.where(same, obs.kernel_shared, 0.0))


def run_soil(obs: Observations, soil_jac: np.ndarray, soil_spread: np.ndarray
             ) -> Observations:
    """``obs`` with a soil state of each run: the prepared soil under one run differs from the
    campaign's by ``d ~ N(0, (g s)^2)`` in the calibrated soil parameters (``s``: their prior
    spread, ``g`` on :data:`RUN_SOIL_GRID`), which moves that run's drawbar pull, torque and
    sinkage together by ``J d`` (``soil_jac``: entries x soil parameters, the base model's
    Jacobian). The unit kernel is ``J diag(s^2) J^T`` within a point, zero between points: a
    run-level random effect (Kennedy & O'Hagan 2001 sec. 4.2 give the model's inputs an
    uncertainty of their own). Without it the evidence counts one run's soil three times,
    once per quantity, and credits whichever effect moves the three as that soil does."""
    scaled = soil_jac * soil_spread
    same_point = obs.point[:, None] == obs.point[None, :]
    return replace(obs, kernel_run=np.where(same_point, scaled @ scaled.T, 0.0))


def soil_drift(obs: Observations, started_h: np.ndarray, soil_jac: np.ndarray,
               soil_spread: np.ndarray) -> Observations | None:
    """``obs`` whose second discrepancy is a soil that drifts through the campaign: the bin
    loosens or compacts as the runs go on, a slow change whose first-order term is a straight
    line in time, so the soil under a run started at ``t`` (hours, one per point) differs
    from the campaign's by ``b u(t)``, ``u = (t - t_mid) / (span / 2)`` (-1 at the first
    run, +1 at the last) and ``b ~ N(0, diag(s^2))`` (``s``: the soil prior's spread). It
    moves a run's drawbar pull, torque and sinkage by ``J b u(t)`` (``soil_jac``, as
    :func:`run_soil`): kernel ``J diag(s^2) J^T u u^T``, of rank at most the number of soil
    parameters, so it carries a trend in time and nothing that scatters from run to run
    (that is :func:`run_soil`'s). Scaled to a mean variance of one floor squared, so that its
    amplitude is in floor units as the other outside forms' are
    (:func:`sim_gap.diagnose.outside_forms`). None where a run's start time is unknown or all
    runs started together: then no drift can be told from the soil itself."""
    times = np.asarray(started_h, float)
    if not np.isfinite(times).all() or np.ptp(times) <= 0:
        return None
    u = (times[obs.point] - 0.5 * (times.min() + times.max())) / (0.5 * np.ptp(times))
    scaled = soil_jac * soil_spread
    kernel = (scaled @ scaled.T) * (u[:, None] * u[None, :])
    size = float(np.mean(np.diagonal(kernel) / obs.floor ** 2))
    return replace(obs, kernel_grouped=kernel / size) if size > 0 else None


@dataclass(frozen=True)
class Covariances:
    """The noise-plus-discrepancy covariance ``A`` of every grid point (shared amplitude x
    outside amplitude x nugget x run soil), factored once for all candidates: ``lower`` Cholesky
    factors (grid points, entries, entries), ``log_det`` of each ``A`` and the ``sizes``
    (shared, outside, nugget, run soil) of each grid point (:func:`covariance_at`)."""

    lower: np.ndarray
    log_det: np.ndarray
    shape: tuple[int, int, int, int]
    sizes: np.ndarray  # (grid points, 4)


def covariance_at(obs: Observations, sizes: Sequence[float], take: np.ndarray | None = None,
                  times: np.ndarray | None = None) -> np.ndarray:
    """``A = diag(sigma^2) + offsets + t^2 K_shared + o^2 K_grouped + v^2 diag(f^2)
    + g^2 K_run`` at ``sizes = (t, o, v, g)``, over the entries ``take`` (default: all).
    ``times``: how often each entry's run is drawn in a bootstrap copy
    (:mod:`sim_gap.bagging`); a run drawn ``m`` times counts as the mean of ``m`` runs at its
    condition, so its noise, nugget and soil (its own, independent from run to run) are
    divided by ``m`` and the discrepancies (of the condition) are not."""
    return CovarianceTerms.of(obs, take, times).at(sizes)


@dataclass(frozen=True)
class CovarianceTerms:
    """The terms of :func:`covariance_at` over some entries, before their sizes: a bagged
    copy (:mod:`sim_gap.bagging`) takes them once and combines them at each hypothesis'
    sizes."""

    noise: np.ndarray  # the diagonal of the noise term
    offsets: np.ndarray
    shared: np.ndarray
    grouped: np.ndarray
    floor: np.ndarray  # the diagonal of the nugget term
    run: np.ndarray | None
    per_run: np.ndarray

    @classmethod
    def of(cls, obs: Observations, take: np.ndarray | None = None,
           times: np.ndarray | None = None) -> CovarianceTerms:
        if take is None:
            take = np.arange(obs.y.size)
        per_run = np.ones(take.size) if times is None else times
        ix = np.ix_(take, take)
        offsets = obs.offsets[take]
        return cls(obs.sigma[take] ** 2 / per_run,
                   OFFSET_PRIOR_SD_M ** 2 * offsets @ offsets.T,
                   obs.kernel_shared[ix], obs.kernel_grouped[ix],
                   obs.floor[take] ** 2 / per_run,
                   None if obs.kernel_run is None else obs.kernel_run[ix], per_run)

    def at(self, sizes: Sequence[float]) -> np.ndarray:
        """``A`` at ``sizes = (t, o, v, g)``: the terms added in that order (the diagonal
        ones only where they are not zero, which adds nothing elsewhere)."""
        t, o, v, g = sizes
        a = self.offsets.copy()
        diagonal = np.einsum("ii->i", a)
        diagonal += self.noise
        a += t ** 2 * self.shared
        a += o ** 2 * self.grouped
        diagonal += v ** 2 * self.floor
        if self.run is not None and g > 0:
            a += g ** 2 * self.run / self.per_run[:, None]
        return a


def covariances(obs: Observations, outside: np.ndarray | None = None) -> Covariances:
    """Factor :func:`covariance_at` over :data:`TAU_GRID`, ``outside`` (amplitudes of the
    discrepancy apart per group, floor units; none by default), :data:`NUGGET_GRID` and,
    where ``obs`` has a run soil kernel (:func:`run_soil`), :data:`RUN_SOIL_GRID`."""
    outside = np.zeros(1) if outside is None else np.asarray(outside, float)
    run_grid = RUN_SOIL_GRID if obs.kernel_run is not None else np.zeros(1)
    sizes = np.array(list(itertools.product(TAU_GRID, outside, NUGGET_GRID, run_grid)))
    terms = CovarianceTerms.of(obs)
    # each factor column-major, as LAPACK reads it: grid_log_evidence's triangular solves
    # would copy a row-major one at every call
    n = obs.y.size
    upper = np.empty((len(sizes), n, n))
    for i, size in enumerate(sizes):
        upper[i] = cholesky(terms.at(size), lower=True, check_finite=False).T
    lower = upper.transpose(0, 2, 1)
    log_det = 2.0 * np.sum(np.log(np.diagonal(lower, axis1=1, axis2=2)), axis=1)
    return Covariances(lower, log_det,
                       (len(TAU_GRID), len(outside), len(NUGGET_GRID), len(run_grid)), sizes)


def _log_interval(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """``log(Phi(b) - Phi(a))`` for ``a < b``, accurate in either tail."""
    a, b = np.broadcast_arrays(np.asarray(a, float), np.asarray(b, float))
    upper_tail = a > 0.0  # both in the upper tail: mirror them into the lower one
    lo, hi = np.where(upper_tail, -b, a), np.where(upper_tail, -a, b)
    log_hi, log_lo = log_ndtr(hi), log_ndtr(lo)
    return log_hi + np.log1p(-np.exp(np.minimum(log_lo - log_hi, 0.0)))


@dataclass(frozen=True)
class Evidence:
    """Log evidence (natural log); the posterior weights of the shared discrepancy's sizes
    (:data:`TAU_GRID`, summed over the other grids), of the nugget's (:data:`NUGGET_GRID`)
    and of the run soil's (:data:`RUN_SOIL_GRID`, where the covariances have it); the most
    probable grid point (flat index into :class:`Covariances`)."""

    log_evidence: float
    tau_weights: np.ndarray
    nugget_weights: np.ndarray
    best_grid: int = 0
    run_soil_weights: np.ndarray | None = None
    log_at_best: float = 0.0  # the log evidence at the most probable grid point alone

    @property
    def nugget_rms(self) -> float:
        """Posterior root-mean-square size of the nugget (floor units)."""
        return float(np.sqrt(self.nugget_weights @ NUGGET_GRID ** 2))

    @property
    def run_soil_rms(self) -> float:
        """Posterior root-mean-square scatter of a run's soil (soil prior spreads)."""
        if self.run_soil_weights is None or self.run_soil_weights.size == 1:
            return 0.0
        return float(np.sqrt(self.run_soil_weights @ RUN_SOIL_GRID ** 2))

    @property
    def tau_mean(self) -> float:
        """Posterior mean of the shared discrepancy's amplitude (floor units)."""
        return float(self.tau_weights @ TAU_GRID)


def log_evidence(cov: Covariances, y: np.ndarray, predicted: np.ndarray, jac: np.ndarray,
                 offset_from_prior: np.ndarray, prior_sd: np.ndarray,
                 bounds_from_prior: tuple[np.ndarray, np.ndarray] | None = None) -> Evidence:
    """The linearised-Laplace log evidence of a candidate (:func:`grid_log_evidence`)
    integrated over the grids of ``cov`` (:func:`covariances`), equal weights."""
    logs = grid_log_evidence(cov, y, predicted, jac, offset_from_prior, prior_sd,
                             bounds_from_prior)
    logs = logs.reshape(cov.shape) - np.log(logs.size)
    total = float(logsumexp(logs))
    weights = np.exp(logsumexp(logs, axis=(1, 2, 3)) - total)
    return Evidence(total, weights, np.exp(logsumexp(logs, axis=(0, 1, 3)) - total),
                    int(np.argmax(logs)), np.exp(logsumexp(logs, axis=(0, 1, 2)) - total),
                    float(logs.max() + np.log(logs.size)))


def grid_log_evidence(cov: Covariances, y: np.ndarray, predicted: np.ndarray, jac: np.ndarray,
                      offset_from_prior: np.ndarray, prior_sd: np.ndarray,
                      bounds_from_prior: tuple[np.ndarray, np.ndarray] | None = None
                      ) -> np.ndarray:
    """The linearised-Laplace log evidence at each grid point of ``cov`` (flat) of a
    candidate whose MAP predicts ``predicted`` (flat, the entries ``y``) with Jacobian ``jac``
    (entries x parameters, internal coordinates), ``offset_from_prior = u* - mu`` and prior
    standard deviations ``prior_sd``.

    With ``v = u - mu ~ N(0, S)`` the residual ``r = y - eta* + J (u* - mu) = J v + e``,
    ``e ~ N(0, A)``, and by Woodbury's identity and the determinant lemma, with
    ``M = S^-1 + J^T A^-1 J`` and ``b = J^T A^-1 r``::

        log N(r; 0, A + J S J^T) = log N(r; 0, A) + b^T M^-1 b / 2 - log|S M| / 2

    so each grid point needs only triangular solves with its factor of ``A``.

    ``bounds_from_prior = (lower - mu, upper - mu)``: the parameters' ranges (a law's
    declared range, the soil's plausible bounds). The prior is the Gaussian truncated to
    that box, and for a model linear in ``u`` the evidence is exactly the untruncated one
    times ``P_post(box) / P_prior(box)`` (the posterior ``N(M^-1 b, M^-1)``). Without that
    factor an effect fitted at the end of its range (a bulldozing resistance of zero) would
    be credited with the fit its Jacobian extrapolates to beyond it (a negative resistance,
    pushing the wheel). The box probabilities are taken as products of the marginal ones
    (exact for uncorrelated parameters; O'Hagan & Leonard 1976 for the one-sided case)."""
    residual = y - np.nan_to_num(predicted, nan=0.0) + jac @ offset_from_prior
    return prepared_log_evidence(cov, residual, jac, PriorTerms.of(prior_sd, bounds_from_prior))


@dataclass(frozen=True)
class PriorTerms:
    """What :func:`grid_log_evidence` needs of a candidate's prior, computed once: a bagged
    posterior (:mod:`sim_gap.bagging`) evaluates the same candidate on 200 copies."""

    bounds: tuple[np.ndarray, np.ndarray] | None
    precision: np.ndarray
    log_det: float
    in_box: float | None
    identity: np.ndarray

    @classmethod
    def of(cls, prior_sd: np.ndarray,
           bounds_from_prior: tuple[np.ndarray, np.ndarray] | None = None) -> PriorTerms:
        prior_var = prior_sd ** 2
        in_box = None
        if bounds_from_prior is not None:
            lo, hi = bounds_from_prior
            in_box = np.sum(_log_interval(lo / prior_sd, hi / prior_sd))
        return cls(bounds_from_prior, np.diag(1.0 / prior_var),
                   np.sum(np.log(prior_var)), in_box, np.eye(prior_sd.size))


def prepared_log_evidence(cov: Covariances, residual: np.ndarray, jac: np.ndarray,
                          prior: PriorTerms) -> np.ndarray:
    """:func:`grid_log_evidence` from the residual ``r = y - eta* + J (u* - mu)`` and the
    prior's terms."""
    rhs = np.column_stack([residual, jac])
    # what every grid point shares is computed once, and the box probabilities of all grid
    # points in one call: the loop runs thousands of times per diagnosis on small matrices
    n_grid, n_params = cov.log_det.size, jac.shape[1]
    logs = np.empty(n_grid)
    mean, sd = np.empty((n_grid, n_params)), np.empty((n_grid, n_params))
    gauss_norm = 0.5 * residual.size * np.log(2.0 * np.pi)
    for g, (factor, log_det) in enumerate(zip(cov.lower, cov.log_det)):
        x = _lapack(dtrtrs, factor, rhs, lower=1)
        xr, xj = x[:, 0], x[:, 1:]
        b = xj.T @ xr
        m_factor = _lapack(dpotrf, prior.precision + xj.T @ xj, lower=1, clean=1)
        w = _lapack(dtrtrs, m_factor, b, lower=1)
        logs[g] = (-0.5 * (xr @ xr - w @ w) - 0.5 * log_det
                   - 0.5 * (prior.log_det + 2.0 * np.sum(np.log(np.diagonal(m_factor))))
                   - gauss_norm)
        if prior.bounds is not None:
            post_cov = _lapack(dpotrs, m_factor, prior.identity, lower=1)
            mean[g], sd[g] = post_cov @ b, np.sqrt(np.diagonal(post_cov))
    if prior.bounds is not None:
        lo, hi = prior.bounds
        logs += np.sum(_log_interval((lo - mean) / sd, (hi - mean) / sd), axis=1) - prior.in_box
    return logs


def _lapack(routine, *args, **options) -> np.ndarray:
    """The result of a LAPACK routine of :mod:`scipy.linalg.lapack` (Cholesky factor,
    triangular solve, solve with a Cholesky factor), raising on failure: the evidence
    calls these thousands of times per diagnosis on small matrices, where the wrappers of
    :mod:`scipy.linalg` cost more than the arithmetic. A hypothesis without parameters has
    empty matrices, which LAPACK refuses: their result is the empty right-hand side."""
    if args[0].size == 0:
        return args[-1]
    out, info = routine(*args, **options)
    if info != 0:
        raise np.linalg.LinAlgError(f"{routine.__name__}: LAPACK info {info}")
    return out


def held_out_dispersion(cov: Covariances, grid: int, y: np.ndarray, predicted: np.ndarray,
                        jac: np.ndarray, offset_from_prior: np.ndarray, prior_sd: np.ndarray,
                        point: np.ndarray) -> float:
    """The dispersion of a candidate's marginal model (noise, discrepancy and parameters at
    grid point ``grid`` of ``cov``) on held-out runs: each point's entries predicted from
    all the others, ``chi2_b = g_b^T (P_bb)^-1 g_b`` with ``P`` the inverse of the marginal
    covariance and ``g = P r`` (the leave-one-out identities of a Gaussian; Sundararajan &
    Keerthi 2001, Neural Computation 13:1103-1118; Rasmussen & Williams 2006, sec. 5.4.2),
    summed over points and divided by the number of entries: 1 when the model's covariance
    describes how its errors scatter from one run to the next, ``phi`` when they scatter
    ``sqrt(phi)`` times wider."""
    residual = y - np.nan_to_num(predicted, nan=0.0) + jac @ offset_from_prior
    factor = cov.lower[grid]
    marginal = factor @ factor.T + (jac * prior_sd ** 2) @ jac.T
    precision = cho_solve((cholesky(marginal, lower=True, check_finite=False), True),
                          np.eye(residual.size), check_finite=False)
    g = precision @ residual
    chi2 = 0.0
    for b in np.unique(point):
        at = np.flatnonzero(point == b)
        chi2 += float(g[at] @ np.linalg.solve(precision[np.ix_(at, at)], g[at]))
    return chi2 / residual.size
