"""The bagged posterior (sim_gap.bagging): a copy's covariance against the mean of repeated
runs worked by hand, agreement with Bayes' rule where the runs agree, and a spread where
one run alone decides (BayesBag; Huggins & Miller 2023)."""

from __future__ import annotations

import numpy as np
import pytest

from sim_gap.bagging import BagModel, bagged_posterior, resample
from sim_gap.decide import posterior
from sim_gap.evidence import Observations, covariance_at, covariances, log_evidence

GRID = (0.0, 0.0, 0.0, 0.0)


def _obs(y: np.ndarray, sigma: float = 0.3, smooth: bool = True) -> Observations:
    """Observations of ``y`` at evenly spaced x; ``smooth=False``: no discrepancy and a
    negligible floor (a plain linear model, whose evidence Bayes' rule reads exactly)."""
    n = y.size
    x = np.linspace(0.0, 1.0, n)
    kernel = np.exp(-0.5 * ((x[:, None] - x[None, :]) / 0.3) ** 2) * smooth
    return Observations(y, np.full(n, sigma), np.full(n, 0.1 if smooth else 1e-9),
                        np.arange(n), np.zeros(n, int), np.ones((n, 1), bool), kernel,
                        np.zeros((n, n)), np.zeros((n, 0)))


def test_a_run_drawn_m_times_is_the_mean_of_m_runs():
    """Entries of points drawn 0, 2 and 1 times: the point drawn twice keeps its
    discrepancy and has its noise and nugget halved (the variance of a mean of two runs)."""
    obs = _obs(np.zeros(3))
    take, times = resample(obs.point, np.array([0, 2, 1]))
    assert take.tolist() == [1, 2] and times.tolist() == [2.0, 1.0]
    tau, nugget = 1.5, 2.0
    got = covariance_at(obs, (tau, 0.0, nugget, 0.0), take, times)
    noise = 0.3 ** 2 + (nugget * 0.1) ** 2
    expected = tau ** 2 * obs.kernel_shared[np.ix_(take, take)] + np.diag([noise / 2, noise])
    np.testing.assert_allclose(got, expected)


def _model(obs: Observations, slope_prior_sd: float | None, x: np.ndarray) -> BagModel:
    """A hypothesis ``y = a x`` (prior N(0, sd^2)), or ``y = 0`` (no parameter)."""
    if slope_prior_sd is None:
        return BagModel(obs, GRID, np.zeros_like(x), np.zeros((x.size, 0)), np.zeros(0),
                        np.zeros(0), (np.zeros(0), np.zeros(0)), 0.0)
    return BagModel(obs, GRID, np.zeros_like(x), x[:, None], np.zeros(1),
                    np.array([slope_prior_sd]), (np.array([-1e9]), np.array([1e9])), 0.0)


def _bayes(obs: Observations, models: dict[str, BagModel], prior: dict[str, float]) -> dict:
    cov = covariances(obs)
    logs = {k: log_evidence(cov, obs.y, m.predicted, m.jac, m.offset, m.sd).log_evidence
            for k, m in models.items()}
    return posterior(logs, prior, 1.0)


def test_bagging_agrees_with_bayes_where_every_run_agrees():
    """A clear slope in 30 runs: every copy, and so the bagged posterior, calls it."""
    rng = np.random.default_rng(1)
    x = np.linspace(0.0, 1.0, 30)
    obs = _obs(2.0 * x + rng.normal(0.0, 0.3, 30), smooth=False)
    models = {"flat": _model(obs, None, x), "slope": _model(obs, 2.0, x)}
    prior = {"flat": 0.5, "slope": 0.5}
    assert _bayes(obs, models, prior)["slope"] > 0.999
    assert bagged_posterior(models, prior, 1.0, n_bags=100)["slope"] > 0.99


def test_bagging_spreads_what_one_run_alone_decides():
    """Flat data but for one run far off at the end: Bayes' rule calls the slope with
    near certainty from that run; copies without it do not, so the bagged probability
    stays far from a call."""
    x = np.linspace(0.0, 1.0, 20)
    rng = np.random.default_rng(2)
    y = rng.normal(0.0, 0.3, 20)
    y[-1] = 3.0
    obs = _obs(y, smooth=False)
    models = {"flat": _model(obs, None, x), "slope": _model(obs, 2.0, x)}
    prior = {"flat": 0.5, "slope": 0.5}
    bayes = _bayes(obs, models, prior)["slope"]
    bagged = bagged_posterior(models, prior, 1.0, n_bags=200)["slope"]
    assert bayes > 0.95
    assert bagged < 0.8
    assert bagged == pytest.approx(bagged_posterior(models, prior, 1.0, n_bags=200)["slope"])
