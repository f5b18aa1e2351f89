"""The next test by expected information gain (sim_gap.next_test): the Monte Carlo estimate
against the closed form of two equally likely one-dimensional Gaussians, the ordering of
tests on two linear-Gaussian hypotheses, the bound log2(labels), and proposals that never
repeat a measured condition."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest
from scipy.integrate import quad
from scipy.stats import norm

import terramechanics as tm
from sim_gap.next_test import (SLIP_TOLERANCE, candidate_tests, information_gain, leading,
                               new_conditions)

G0 = 9.80665


def _exact_two_gaussians_bits(delta: float) -> float:
    """I(H; y) for H uniform on two labels, y | h ~ N(+-delta/2, 1): H[y] - H[y | h] by
    quadrature."""
    def mix(y):
        return 0.5 * (norm.pdf(y, -delta / 2) + norm.pdf(y, delta / 2))

    h_y = quad(lambda y: -mix(y) * np.log(mix(y)), -delta - 12, delta + 12, limit=200)[0]
    return (h_y - 0.5 * np.log(2 * np.pi * np.e)) / np.log(2)


@pytest.mark.parametrize("delta", [0.5, 2.0, 4.0])
def test_gain_of_two_gaussians_matches_quadrature(delta):
    exact = _exact_two_gaussians_bits(delta)
    got = information_gain([np.array([-delta / 2]), np.array([delta / 2])],
                           [np.eye(1), np.eye(1)], np.array([0.5, 0.5]), ["a", "b"],
                           draws=4000)
    assert got == pytest.approx(exact, abs=0.03)


def _linear_hypotheses(x: np.ndarray, noise: float = 0.1):
    """Two linear-Gaussian hypotheses on a test at conditions ``x``: y = a x + e under
    ``a``, y = b x^2 + e under ``b``, each slope with prior N(1, 0.05^2) (carried into the
    predictive as x S x^T, the linear model's exact marginal)."""
    j_a, j_b = x[:, None], (x ** 2)[:, None]
    cov = [0.05 ** 2 * j @ j.T + noise ** 2 * np.eye(x.size) for j in (j_a, j_b)]
    return [x, x ** 2], cov


def test_the_test_where_predictions_differ_most_gains_most_and_coinciding_gains_nothing():
    """y = x and y = x^2 coincide at x = 0 and 1 and differ most at x = 0.5 (by 0.25, 2.5
    noise sd) and at x = 2 (by 2): the test at 2 gains most (nearly the whole bit), the test
    at 0.5 less, the tests at 0 and 1 nothing; never more than log2(2) = 1 bit."""
    gains = {}
    for where in (0.0, 1.0, 0.5, 2.0):
        means, covs = _linear_hypotheses(np.array([where]))
        gains[where] = information_gain(means, covs, np.array([0.5, 0.5]), ["a", "b"])
    assert gains[0.0] == pytest.approx(0.0, abs=0.02)
    assert gains[1.0] == pytest.approx(0.0, abs=0.02)
    assert gains[2.0] > gains[0.5] > 0.3
    assert gains[2.0] > 0.95
    assert max(gains.values()) <= 1.0


def test_gain_is_about_the_label_and_bounded_by_its_entropy():
    """Two laws of one effect set and a second set: telling the laws apart is worth nothing
    about the label; a test that separates everything gains the labels' entropy (<= log2 of
    the number of labels)."""
    weights = np.array([0.3, 0.3, 0.4])
    labels = ["a", "a", "b"]
    laws_apart = information_gain([np.array([0.0]), np.array([50.0]), np.array([0.0])],
                                  [np.eye(1)] * 3, weights, ["a", "a", "b"])
    # the "a" laws differ, but "b" sits on one of them: the label stays partly uncertain
    every_apart = information_gain([np.array([0.0]), np.array([50.0]), np.array([100.0])],
                                   [np.eye(1)] * 3, weights, labels)
    entropy = -(0.6 * np.log2(0.6) + 0.4 * np.log2(0.4))
    assert every_apart == pytest.approx(entropy, abs=0.01)
    assert every_apart <= np.log2(2) and laws_apart < every_apart
    same_label = information_gain([np.array([0.0]), np.array([50.0])], [np.eye(1)] * 2,
                                  np.array([0.5, 0.5]), ["a", "a"])
    assert same_label == 0.0


def test_leading_hypotheses_hold_the_posterior_asked_for():
    hyps = [{"key": k, "probability": p} for k, p in
            (("x", 0.6), ("y", 0.3), ("z", 0.095), ("w", 0.005))]
    assert [h["key"] for h in leading(hyps, 0.99)] == ["x", "y", "z"]
    assert [h["key"] for h in leading(hyps, 0.5)] == ["x"]


def _campaign(loads=(60.0, 120.0, 200.0), slips=(-0.2, 0.0, 0.1, 0.25, 0.45, 0.7),
              multipass=(0,), lugs=12) -> pd.DataFrame:
    rows = [{"source": "lab", "wheel_radius_m": 0.13, "wheel_width_m": 0.1,
             "grouser_count": lugs, "grouser_height_m": 0.008 if lugs else 0.0,
             "load_set_n": w, "wheel_load_n": w, "slip": s + 0.003, "multipass": m,
             "gravity_mps2": G0, "dp_n": 1.0, "dp_n_se": 0.1}
            for w in loads for s in slips for m in multipass]
    return pd.DataFrame(rows)


def test_no_proposal_repeats_a_measured_condition():
    """Every test but the replicates: no row at a measured source, wheel, multipass and
    gravity with a set load within 5 % and a slip within the tolerance; the braked band
    drops -0.2 (measured) and keeps -0.4 and -0.1; a lugged wheel gets a smooth-wheel test,
    one multipass level a second, one gravity level another."""
    points = _campaign()
    tests = candidate_tests(points, grousered=True)
    kinds = [t["kind"] for t in tests]
    assert {"load", "slips", "smooth wheel", "multipass", "gravity"} <= set(kinds)
    for t in tests:
        grid = t["points"]
        for r in grid.itertuples():
            same = points[(points["source"] == r.source)
                          & (points["grouser_count"] == r.grouser_count)
                          & (points["multipass"] == r.multipass)
                          & np.isclose(points["gravity_mps2"], r.gravity_mps2)
                          & (np.abs(points["load_set_n"] / r.load_set_n - 1) <= 0.05)]
            assert (np.abs(same["slip"] - r.slip) > SLIP_TOLERANCE).all(), (t["test"], r)
    braked = next(t for t in tests if t["test"].startswith("braked"))
    assert sorted(set(braked["points"]["slip"])) == [-0.4, -0.1]
    assert "(6 runs)" in braked["test"]
    # a campaign that has the second pass and a smooth wheel is not offered them again
    both = pd.concat([_campaign(multipass=(0, 1)),
                      _campaign(lugs=0).assign(source="smooth")], ignore_index=True)
    kinds = {t["kind"] for t in candidate_tests(both, grousered=True)}
    assert "multipass" not in kinds and "smooth wheel" not in kinds


def test_new_conditions_keeps_only_unmeasured_rows():
    points = _campaign(loads=(100.0,), slips=(0.1,))
    grid = points[["source", "wheel_radius_m", "wheel_width_m", "grouser_count",
                   "grouser_height_m", "load_set_n", "wheel_load_n", "multipass",
                   "gravity_mps2"]].iloc[[0, 0, 0, 0]].assign(slip=[0.1, 0.115, 0.13, 0.1])
    grid.iloc[3, grid.columns.get_loc("load_set_n")] = 120.0
    assert new_conditions(points, grid)["slip"].tolist() == [0.13, 0.1]


def test_next_tests_on_a_campaign_that_lacks_the_contrast():
    """A noisy model campaign (8 runs, one multipass level) whose truth has slip-sinkage,
    diagnosed among slip-sinkage and bulldozing: the tests are ranked, gains in [0, entropy of the
    leading sets], none at a measured condition but the replicates."""
    from sim_gap.diagnose import Settings, diagnose
    from sim_gap.simulated import Simulated

    base = tm.shipped_model("bb2_sand").with_effects(**{n: False for n in tm.EFFECTS})
    truth = base.with_effects(slip_sinkage=True)
    loads, slips = np.array([60.0, 120.0]), np.array([0.05, 0.2, 0.4, 0.6])
    w, s = np.meshgrid(loads, slips, indexing="ij")
    points = pd.DataFrame({"load_set_n": w.ravel(), "wheel_load_n": w.ravel(),
                           "slip": s.ravel(), "multipass": 0, "gravity_mps2": G0})
    curves = truth.curves(points["wheel_load_n"], points["slip"])
    rng = np.random.default_rng(3)
    for q in ("dp_n", "sinkage_m"):
        sd = 0.15 * np.abs(curves[q]) + (1e-3 if q == "sinkage_m" else 2.0)
        points[q] = curves[q] + rng.normal(0, sd)
        points[f"{q}_se"] = sd
    report = diagnose(points, Simulated(base), ["slip_sinkage", "bulldozing"],
                      Settings(max_nfev=15, fold_nfev=2, n_boot=5))
    assert report["verdict"] == "inconclusive"  # noise of 15 % + 2 N: no set reaches 0.9
    tests = report["decision"]["next_tests"]
    gains = [t["gain_bits"] for t in tests]
    assert 1 <= len(tests) <= 3 and gains == sorted(gains, reverse=True)
    p = np.array([x["probability"] for x in report["effect_sets"]])
    assert 0 <= min(gains) and max(gains) <= -np.sum(p * np.log2(p)) + 0.01
    for t in tests:
        if t["kind"] != "replicates":
            new = pd.DataFrame(t["conditions"])
            assert len(new_conditions(points, new)) == len(new)
