"""The bagged posterior of the hypotheses (BayesBag; Bühlmann 2014, "Discussion of Big Bayes
Stories and BayesBag", Statistical Science 29:91-94; Huggins & Miller 2023, "Reproducible
model selection using bagged posteriors", Bayesian Analysis 18:79-104): the posterior
probability of each hypothesis averaged over bootstrap copies of the campaign,

    P_bag(H) = (1/B) sum_b P(H | runs resampled with replacement, copy b)

When every hypothesis is misspecified (another solver than the lab's wheel, laws of other
shapes than the soil's), Bayes' rule concentrates on whichever one the particular runs
favour, and another set of runs of the same campaign may favour another: its probabilities
are neither reproducible nor calibrated. The bagged posterior is stable under resampling
of the runs, and concentrates on one hypothesis only where the runs agree on it; where the
models are right it agrees with Bayes' rule (Huggins & Miller, Theorems 1-3).

Each copy resamples the campaign's runs (points) with replacement; a run drawn ``m``
times counts as the mean of ``m`` runs at its condition
(:func:`sim_gap.evidence.covariance_at`). Each hypothesis'
evidence on a copy is the linearised Laplace evidence of
:func:`sim_gap.evidence.grid_log_evidence` at its most probable discrepancy, nugget and run-soil
sizes on the whole campaign (type-II; the sizes are not refitted per copy), plus the Occam
factor of those sizes on the whole campaign, with the same truncated priors.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from sim_gap.evidence import (Covariances, CovarianceTerms, Observations, PriorTerms,
                              prepared_log_evidence)
from sim_gap.decide import posterior

#: bootstrap copies: the Monte Carlo error of a probability near the 0.9 of a call is then
#: about sqrt(0.9 x 0.1 / 200) = 0.02
N_BAGS = 200


@dataclass(frozen=True)
class BagModel:
    """What one hypothesis' evidence on a copy needs: its observations (their kernels), the
    sizes of its covariance (``grid``: shared, outside, nugget, run soil, in floor or
    soil-spread units), its MAP prediction, Jacobian, offset from the prior centre, prior
    standard deviations and bounds (internal coordinates, from the prior centre), and the
    Occam factor of those sizes on the whole campaign (``log Z - log Z(grid)``: what
    integrating over the sizes costs against fixing them at their best; a hypothesis with
    an extra discrepancy pays for its flexibility on every copy as it does on the
    campaign)."""

    obs: Observations
    grid: tuple[float, ...]
    predicted: np.ndarray
    jac: np.ndarray
    offset: np.ndarray
    sd: np.ndarray
    bounds: tuple[np.ndarray, np.ndarray]
    occam: float


def _factor(a: np.ndarray) -> Covariances:
    lower = np.linalg.cholesky(a)
    return Covariances(lower[None], np.array([2.0 * np.sum(np.log(np.diag(lower)))]),
                       (1, 1, 1, 1), np.zeros((1, 4)))


def resample(point: np.ndarray, counts: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The entries of the points a bootstrap copy draws (``counts[p]`` times point ``p``)
    and how many times each entry's point was drawn."""
    take = np.flatnonzero(counts[point] > 0)
    return take, counts[point[take]].astype(float)


def bagged_posterior(models: dict[str, BagModel], prior: dict[str, float], eta: float,
                     n_bags: int = N_BAGS, seed: int = 0) -> dict[str, float]:
    """``P_bag`` of every key of ``models`` (module docstring) with priors ``prior`` and
    learning rate ``eta``. Every model's observations hold the same entries (the campaign's)."""
    rng = np.random.default_rng(seed)
    keys = list(models)
    point = models[keys[0]].obs.point
    n_points = int(point.max()) + 1
    total = dict.fromkeys(keys, 0.0)
    # what a copy does not change, once: the prior's terms, the MAP predictions as the
    # evidence reads them
    priors = {key: PriorTerms.of(models[key].sd, models[key].bounds) for key in keys}
    predicted = {key: np.nan_to_num(models[key].predicted, nan=0.0) for key in keys}
    for _ in range(n_bags):
        take, times = resample(point, rng.multinomial(n_points,
                                                      np.full(n_points, 1 / n_points)))
        factors: dict[tuple, Covariances] = {}
        terms: dict[int, CovarianceTerms] = {}
        logs = {}
        for key in keys:
            m = models[key]
            cache = (id(m.obs), m.grid)
            if cache not in factors:
                if id(m.obs) not in terms:
                    terms[id(m.obs)] = CovarianceTerms.of(m.obs, take, times)
                factors[cache] = _factor(terms[id(m.obs)].at(m.grid))
            jac = m.jac[take]
            residual = m.obs.y[take] - predicted[key][take] + jac @ m.offset
            logs[key] = m.occam + float(prepared_log_evidence(
                factors[cache], residual, jac, priors[key])[0])
        for key, p in posterior(logs, prior, eta).items():
            total[key] += p / n_bags
    return total
