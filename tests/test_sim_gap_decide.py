"""Gap diagnosis by posterior probabilities: the evidence against a closed form, the priors
and what the lab knows, injected effects found on synthetic model data (in family: the
truths are this model's own laws), an effect outside the candidates, sibling contrasts."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pandas as pd
import pytest
from scipy import integrate, stats

import terramechanics as tm
from terramechanics.model import BRAKED_LAWS
from sim_gap import candidates
from sim_gap.decide import (CALL_PROBABILITY, by_effect_set, decide, learning_rate,
                            posterior)
from sim_gap.diagnose import Settings, diagnose
from sim_gap.evidence import (NUGGET_GRID, RUN_SOIL_GRID, TAU_GRID, Observations, covariances,
                              held_out_dispersion, log_evidence, run_soil, soil_drift)
from sim_gap.hypotheses import (OUTSIDE, admissible, hypothesis_priors,
                                outside_prior, set_prior)
from sim_gap.siblings import contrasts
from sim_gap.simulated import Simulated
from swtlab_base.domain import Wheel

BASE = tm.shipped_model("bb2_sand").with_effects(**{n: False for n in tm.EFFECTS})
FAST = Settings(max_nfev=25, n_boot=20)
DEFAULT_LAWS = Settings(max_nfev=25, n_boot=20,
                        laws={e: (law,) for e, law in tm.DEFAULT_LAWS.items()})


def synthetic_points(truth: tm.WheelModel, seed: int = 0, loads=(80.0, 180.0, 300.0),
                     slips=(0.1, 0.3, 0.5, 0.7), multipass=(0, 1),
                     gravity=(9.80665,)) -> pd.DataFrame:
    """Model values with Gaussian noise of 0.5 % of the load (forces), 0.1 mm (sinkage)."""
    rng = np.random.default_rng(seed)
    grids = np.meshgrid(loads, slips, multipass, gravity, indexing="ij")
    load, slip, mp, g = (a.ravel() for a in grids)
    c = truth.curves(load, slip, mp, g)
    points = pd.DataFrame({"run_id": [f"r{i}" for i in range(load.size)], "load_set_n": load,
                           "wheel_load_n": load, "multipass": mp.astype(int),
                           "gravity_mps2": g, "slip": slip})
    noise = {"dp_n": 0.005 * load, "torque_nm": 0.005 * load * 0.125, "sinkage_m": 1e-4,
             "resistance_n": 0.005 * load}
    for q, sd in noise.items():
        points[q] = c[q] + rng.normal(0.0, 1.0, load.size) * sd
        points[f"{q}_se"] = 0.2 * np.broadcast_to(sd, load.shape)
    points.attrs.update(source="synthetic", wheel=truth.wheel, sinkage_relative=False)
    return points


TRUTH_SOIL = {"kphi": 1.8e7 * 1.3, "friction_angle_deg": 35.5}
CANDIDATES = ["grousers", "slip_sinkage", "bulldozing"]


def _normal_pdf(cov: np.ndarray):
    """The density of ``N(0, cov)`` at a residual, its inverse and determinant taken once:
    ``stats.multivariate_normal(mean, cov).pdf`` checks and factors ``cov`` again at each of
    the quadrature's thousands of points (7 CPU-s for the 50 integrals below, 0.3 s this way;
    the integrals agree to 4e-13 relative)."""
    precision = np.linalg.inv(cov)
    log_norm = -0.5 * (np.linalg.slogdet(cov)[1] + len(cov) * np.log(2 * np.pi))
    return lambda r: np.exp(log_norm - 0.5 * r @ precision @ r)


def test_linearised_evidence_equals_the_integral_over_the_parameter():
    """A model linear in one parameter: the evidence is the integral of likelihood times
    prior over the parameter and the discrepancy grids (numerical quadrature)."""
    rng = np.random.default_rng(3)
    x = np.linspace(0.0, 1.0, 8)
    sigma, floor = np.full(8, 0.3), np.full(8, 0.2)
    y = 1.7 * x + rng.normal(0, 0.3, 8)
    kernel = np.exp(-0.5 * ((x[:, None] - x[None, :]) / 0.3) ** 2) * 0.04
    obs = Observations(y, sigma, floor, np.arange(8), np.zeros(8, int), np.ones((8, 1), bool),
                       kernel, np.zeros((8, 8)), np.zeros((8, 0)))
    mu, sd, a_hat = 1.0, 0.8, 1.5  # prior N(1, 0.8^2); expanded at a = 1.5 (any point)
    got = log_evidence(covariances(obs), y, a_hat * x, x[:, None], np.array([a_hat - mu]),
                       np.array([sd]))

    prior = stats.norm(mu, sd)

    def integrand(a, likelihood):
        return likelihood(y - a * x) * prior.pdf(a)

    z = np.mean([integrate.quad(integrand, -6, 8, args=(
        _normal_pdf(np.diag(sigma ** 2 + (v * floor) ** 2) + t ** 2 * kernel),))[0]
        for t in TAU_GRID for v in NUGGET_GRID])
    assert got.log_evidence == pytest.approx(np.log(z), abs=1e-6)
    assert got.tau_weights.sum() == pytest.approx(1.0)


def test_evidence_integrates_only_over_the_parameters_range():
    """A strength that cannot be negative (a resistance), data that slope downwards: the
    evidence is the integral over the range only, with the prior renormalised to it
    (quadrature), far below the untruncated one that credits a negative strength."""
    rng = np.random.default_rng(4)
    x = np.linspace(0.0, 1.0, 8)
    sigma, floor = np.full(8, 0.3), np.full(8, 0.2)
    y = -1.2 * x + rng.normal(0, 0.3, 8)
    obs = Observations(y, sigma, floor, np.arange(8), np.zeros(8, int), np.ones((8, 1), bool),
                       np.zeros((8, 8)), np.zeros((8, 8)), np.zeros((8, 0)))
    mu, sd, lo, hi = 1.0, 0.5, 0.0, 2.0  # the law's range [0, 2] as +-2 sd
    bounded = log_evidence(covariances(obs), y, 0.0 * x, x[:, None], np.array([lo - mu]),
                           np.array([sd]), (np.array([lo - mu]), np.array([hi - mu])))
    free = log_evidence(covariances(obs), y, 0.0 * x, x[:, None], np.array([lo - mu]),
                        np.array([sd]))
    prior_mass = stats.norm(mu, sd).cdf(hi) - stats.norm(mu, sd).cdf(lo)

    prior = stats.norm(mu, sd)

    def integrand(a, likelihood):
        return likelihood(y - a * x) * prior.pdf(a) / prior_mass

    z = np.mean([integrate.quad(integrand, lo, hi, args=(
        _normal_pdf(np.diag(sigma ** 2 + (v * floor) ** 2)),))[0] for v in NUGGET_GRID])
    assert bounded.log_evidence == pytest.approx(np.log(z), abs=1e-6)
    assert free.log_evidence - bounded.log_evidence > 2.0


def test_priors_sum_to_one_and_split_a_set_over_its_laws():
    c = [candidates.candidate(BASE, ())] + [
        candidates.candidate(BASE, ("grousers",), {"grousers": law})
        for law in ("bekker1956", "ding2011")] + [
        candidates.candidate(BASE, ("bulldozing",)),
        candidates.candidate(BASE, ("grousers", "bulldozing"))]
    prior = hypothesis_priors(c, 2)
    assert sum(prior.values()) == pytest.approx(1.0)
    assert prior["grousers(bekker1956)"] == pytest.approx(set_prior(("g",), 2) / 2)
    # each number of missing effects equally likely (0, 1 or 2 of two: a third each, x 0.9),
    # a size's third shared by its sets: one of two singles 1/6, split over two laws 1/12
    assert prior["soil_only"] == pytest.approx(0.9 / 3)
    assert prior["grousers(bekker1956)"] == pytest.approx(0.9 / 12)
    assert prior["grousers(bekker1956)+bulldozing(bekker1969)"] == pytest.approx(0.9 / 3)
    assert prior[OUTSIDE] == pytest.approx(0.1)  # nothing but another effect with two
    assert outside_prior(3) == pytest.approx(0.1 + 0.9 / 4)  # all three: one size of four


def _braked_truth_points(law: str) -> pd.DataFrame:
    truth = replace(BASE.with_soil(**TRUTH_SOIL), braked_law=law)
    return synthetic_points(truth, loads=(80.0, 300.0), slips=(-0.4, -0.1, 0.1, 0.4),
                            multipass=(0,))


@pytest.fixture(scope="module")
def driven_only():
    """The driven runs (slip > 0) of :func:`_braked_truth_points` and their diagnosis, once:
    a braked law changes braked runs only, so each law's driven runs are these (the test
    checks it) and their diagnosis the same."""
    points = _braked_truth_points(BRAKED_LAWS[0])
    driven = points[points["slip"] > 0]
    return driven, diagnose(driven, Simulated(BASE), ["bulldozing"], FAST)


@pytest.mark.parametrize("law", BRAKED_LAWS)
def test_the_base_model_takes_the_braked_branch_the_braked_runs_show(law, driven_only):
    """In family (the truth is this model under one braked law): with braked runs, the soil
    recalibrated under the truth's braked law has the larger evidence and every hypothesis
    is fitted under it; without braked runs nothing is chosen."""
    points = _braked_truth_points(law)
    report = diagnose(points, Simulated(BASE), ["bulldozing"], FAST)
    assert report["base_model"]["braked_law"] == law
    evidence = report["base_model"]["soil_only_log_evidence"]
    assert evidence[law] > max(v for k, v in evidence.items() if k != law) + 5.0
    driven, driven_report = driven_only
    pd.testing.assert_frame_equal(points[points["slip"] > 0], driven)
    assert driven_report["base_model"] == {}


def test_what_the_lab_declared_limits_the_hypotheses():
    rigid_smooth = Wheel(name="rim", radius_m=0.125, width_m=0.1, grouser_count=0,
                         grouser_height_m=0.0)
    points = synthetic_points(BASE, multipass=(0,))
    points.attrs.update(wheels={"lab": rigid_smooth})
    keep, excluded = admissible(list(tm.EFFECTS), points)
    assert set(excluded) == {"wheel_flexibility", "grousers", "multipass", "reduced_gravity"}
    assert "declared radial stiffness" in excluded["wheel_flexibility"]
    flexible = Wheel(name="tyre", radius_m=0.125, width_m=0.1, grouser_count=12,
                     grouser_height_m=0.01, stiffness_n_per_mm=30.0)
    points = synthetic_points(BASE)
    points.attrs.update(wheels={"lab": flexible})
    assert admissible(list(tm.EFFECTS), points)[1] == {
        "reduced_gravity": "two gravity levels"}


def test_posterior_sums_laws_and_calls_only_at_the_threshold():
    hyps = [{"key": "soil_only", "effects": []}, {"key": "grousers(a)", "effects": ["grousers"]},
            {"key": "grousers(b)", "effects": ["grousers"]}, {"key": OUTSIDE, "effects": []}]
    prior = {"soil_only": 0.5, "grousers(a)": 0.1, "grousers(b)": 0.1, OUTSIDE: 0.3}
    for logs, verdict in (({"soil_only": 0.0, "grousers(a)": 4.0, "grousers(b)": 3.0,
                            OUTSIDE: -5.0}, ["grousers"]),
                          ({"soil_only": 0.0, "grousers(a)": 1.0, "grousers(b)": 0.0,
                            OUTSIDE: -5.0}, "inconclusive")):
        p = posterior(logs, prior)
        assert sum(p.values()) == pytest.approx(1.0)
        h = [{**x, "probability": p[x["key"]]} for x in hyps]
        sets = {s["label"]: s["probability"] for s in by_effect_set(h)}
        assert sets["grousers"] == pytest.approx(p["grousers(a)"] + p["grousers(b)"])
        d = decide(h)
        assert d["verdict"] == verdict
        assert (sets["grousers"] >= CALL_PROBABILITY) == (verdict != "inconclusive")
        lead = by_effect_set(h)[0]["label"]
        assert d["chosen"] == {"grousers": "grousers(a)", "soil_only": "soil_only"}[lead]


def test_learning_rate_tempers_the_evidence_not_the_prior():
    """``P(H) Z^eta``: at eta = 0 the posterior is the prior, at eta = 1 Bayes' rule, in
    between the log odds are the prior's plus eta times the log evidence ratio; eta is one
    over the Pearson dispersion, at most one (worked by hand)."""
    prior = {"a": 0.75, "b": 0.25}
    logs = {"a": 0.0, "b": 10.0}
    assert posterior(logs, prior, eta=0.0)["a"] == pytest.approx(0.75)
    for eta in (0.16, 0.5, 1.0):
        p = posterior(logs, prior, eta=eta)
        assert np.log(p["b"] / p["a"]) == pytest.approx(np.log(0.25 / 0.75) + 10.0 * eta)
    assert learning_rate(4.0) == pytest.approx(0.25)
    assert learning_rate(0.5) == 1.0


def _two_quantity_obs(n_points: int, rng) -> tuple[Observations, np.ndarray]:
    """Two quantities per point, independent noise, no discrepancy; a soil Jacobian that
    moves both quantities of a point together (entries x one soil parameter)."""
    point = np.repeat(np.arange(n_points), 2)
    quantity = np.tile([0, 1], n_points)
    sigma, floor = np.where(quantity == 0, 0.5, 0.2), np.full(point.size, 0.1)
    soil_jac = np.where(quantity == 0, 2.0, -1.0)[:, None] * rng.uniform(0.5, 1.5, (point.size, 1))
    obs = Observations(np.zeros(point.size), sigma, floor, point, quantity,
                       np.ones((n_points, 2), bool), np.zeros((point.size,) * 2),
                       np.zeros((point.size,) * 2), np.zeros((point.size, 0)))
    return obs, soil_jac


def test_run_soil_moves_one_runs_quantities_together_and_no_other_run():
    """The run soil's kernel is ``J diag(s^2) J^T`` within a point and zero between points;
    the covariances gain its grid (:data:`RUN_SOIL_GRID`)."""
    obs, jac = _two_quantity_obs(3, np.random.default_rng(0))
    with_soil = run_soil(obs, jac, np.array([0.4]))
    k = with_soil.kernel_run
    assert k[0, 1] == pytest.approx(jac[0, 0] * jac[1, 0] * 0.16) and k[0, 1] < 0
    assert k[0, 2] == 0.0 and k[1, 5] == 0.0
    assert covariances(with_soil).shape[-1] == RUN_SOIL_GRID.size
    assert covariances(obs).shape[-1] == 1


def test_soil_drift_is_a_trend_in_the_runs_start_times():
    """The drift's kernel is the run soil's ``J diag(s^2) J^T`` times ``u u'``, ``u`` the
    start time from -1 (first run) to +1 (last), scaled to a mean variance of one floor
    squared: nothing at the campaign's middle, opposite signs at its ends; no drift where a
    start time is missing or every run started together."""
    obs, jac = _two_quantity_obs(3, np.random.default_rng(0))
    spread = np.array([0.4])
    k = soil_drift(obs, np.array([0.0, 1.0, 2.0]), jac, spread).kernel_grouped
    soil = run_soil(obs, jac, spread).kernel_run
    scale = k[0, 1] / soil[0, 1]
    assert k[0, 4] == pytest.approx(-scale * jac[0, 0] * jac[4, 0] * 0.16)
    assert k[0, 2] == 0.0 and k[2, 3] == 0.0
    assert np.mean(np.diagonal(k) / obs.floor ** 2) == pytest.approx(1.0)
    assert soil_drift(obs, np.array([0.0, np.nan, 2.0]), jac, spread) is None
    assert soil_drift(obs, np.full(3, 5.0), jac, spread) is None


def test_held_out_dispersion_is_the_leave_one_run_out_chi2():
    """The closed form equals each run's entries predicted from all the others by
    conditioning the Gaussian explicitly; data drawn from the model give about 1, data
    scattered twice as wide about 4 (averaged over 40 campaigns)."""
    rng = np.random.default_rng(5)
    obs, jac_soil = _two_quantity_obs(6, rng)
    obs = run_soil(obs, jac_soil, np.array([0.3]))
    cov = covariances(obs)
    grid = 7
    x = rng.uniform(0, 1, (obs.y.size, 1))
    sd = np.array([0.5])
    factor = cov.lower[grid]
    marginal = factor @ factor.T + 0.25 * x @ x.T
    y = rng.multivariate_normal(np.zeros(obs.y.size), marginal)
    got = held_out_dispersion(cov, grid, y, np.zeros_like(y), x, np.zeros(1), sd, obs.point)
    chi2 = 0.0
    for b in range(6):
        at, rest = np.flatnonzero(obs.point == b), np.flatnonzero(obs.point != b)
        gain = marginal[np.ix_(at, rest)] @ np.linalg.inv(marginal[np.ix_(rest, rest)])
        mean = gain @ y[rest]
        var = marginal[np.ix_(at, at)] - gain @ marginal[np.ix_(rest, at)]
        chi2 += (y[at] - mean) @ np.linalg.solve(var, y[at] - mean)
    assert got == pytest.approx(chi2 / y.size, rel=1e-9)
    chol = np.linalg.cholesky(marginal)
    draws = [held_out_dispersion(cov, grid, scale * chol @ rng.normal(size=y.size),
                                 np.zeros_like(y), x, np.zeros(1), sd, obs.point)
             for scale in (1.0, 2.0) for _ in range(40)]
    assert np.mean(draws[:40]) == pytest.approx(1.0, abs=0.15)
    assert np.mean(draws[40:]) == pytest.approx(4.0, abs=0.6)


@pytest.mark.slow_diagnosis  # one diagnosis of 48 points per case
@pytest.mark.parametrize("effects, expected", [
    ({}, []),
    ({"bulldozing": {"coefficient": 1.5}}, ["bulldozing"]),
])
def test_injected_effect_is_found(effects, expected):
    """In family (the truth's law is a candidate law): the truth's effect set leads and each
    of its effects has probability >= 0.9; a call names the truth. With bulldozing found, a
    pair that adds grousers at their prior is a set of the same prior size class, and these
    points leave it about 1.5 nats behind: bulldozing alone leads (about 0.85) without a call."""
    truth = BASE.with_soil(**TRUTH_SOIL).with_effects(**effects)
    report = diagnose(synthetic_points(truth), Simulated(BASE), CANDIDATES, FAST)
    assert report["effect_sets"][0]["label"] == ("+".join(expected) or "soil_only")
    assert report["verdict"] in (expected, "inconclusive")
    assert sum(h["probability"] for h in report["hypotheses"]) == pytest.approx(1.0)
    assert {"soil_only", "grousers(bekker1956)", "slip_sinkage(ding2011)",
            "bulldozing(bekker1969)", OUTSIDE} <= {h["key"] for h in report["hypotheses"]}
    if expected:
        assert report["effect_probabilities"]["bulldozing"] >= CALL_PROBABILITY
        assert report["shrink"]["shrink_pct"]["dp_n"] > 40.0
        assert report["shrink"]["shrink_pct"]["resistance_n"] > 40.0


def test_a_gap_no_candidate_can_make_is_outside_the_candidates():
    """Drawbar pull 6 % of the load higher at multipass 1 only (a rig artefact of one pass,
    no candidate among grousers, slip-sinkage, bulldozing changes with the pass)."""
    points = synthetic_points(BASE.with_soil(**TRUTH_SOIL))
    later = points["multipass"] == 1
    points.loc[later, "dp_n"] += 0.06 * points.loc[later, "wheel_load_n"]
    report = diagnose(points, Simulated(BASE), CANDIDATES, FAST)
    assert report["effect_sets"][0]["label"] == OUTSIDE
    assert report["verdict"] == OUTSIDE
    assert report["decision"]["separating_test"]["test"].startswith("no candidate test")


@pytest.mark.slow  # one diagnosis of 24 runs (about 10 s)
@pytest.mark.slow_diagnosis
def test_a_soil_that_drifts_through_the_campaign_is_outside_the_candidates():
    """In family (the base model's own soil laws, the drift a straight line in time): the
    runs, in a random order 20 min apart, meet a soil whose k_phi falls by a factor 1.6 and
    friction angle by 3 degrees from the first run to the last. Soil drift is no candidate,
    so the outside hypothesis leads and the page says it is the drift; without the start
    times nothing can tell the drift from scatter between runs."""
    rng = np.random.default_rng(3)
    points = synthetic_points(BASE.with_soil(**TRUTH_SOIL), multipass=(0,))
    order = rng.permutation(len(points)) / (len(points) - 1)
    for i, when in enumerate(order):
        drifted = BASE.with_soil(kphi=TRUTH_SOIL["kphi"] * np.exp(-0.47 * (when - 0.5)),
                                 friction_angle_deg=TRUTH_SOIL["friction_angle_deg"]
                                 - 3.0 * (when - 0.5))
        row = points.iloc[i]
        c = drifted.curves(np.array([row["wheel_load_n"]]), np.array([row["slip"]]),
                           np.array([0]), np.array([row["gravity_mps2"]]))
        noise = rng.normal(0.0, 1.0, 4) * [0.005 * row["wheel_load_n"],
                                           0.005 * row["wheel_load_n"] * 0.125, 1e-4,
                                           0.005 * row["wheel_load_n"]]
        for q, n in zip(("dp_n", "torque_nm", "sinkage_m", "resistance_n"), noise):
            points.loc[i, q] = float(c[q][0]) + n
    points["started_unix_h"] = 490_000.0 + order * (len(points) - 1) / 3.0
    report = diagnose(points, Simulated(BASE), CANDIDATES, FAST)
    assert report["effect_sets"][0]["label"] == OUTSIDE
    assert "soil that drifts through the campaign" in report["decision"]["reason"]
    blind = diagnose(points.drop(columns="started_unix_h"), Simulated(BASE), CANDIDATES, FAST)
    outside_p = {r["label"]: r["probability"] for r in blind["effect_sets"]}[OUTSIDE]
    assert outside_p < report["effect_sets"][0]["probability"]


def test_multipass_on_one_level_is_not_a_hypothesis_and_the_page_says_what_it_needs():
    truth = BASE.with_effects(multipass={"stiffness_gain_per_pass": 0.3})
    points = synthetic_points(truth, multipass=(0,), slips=(0.2, 0.35, 0.5))
    report = diagnose(points, Simulated(BASE), ["multipass", "bulldozing"], FAST)
    assert "two multipass levels" in report["untestable_effects"]["multipass"]
    assert all("multipass" not in h["effects"] for h in report["hypotheses"])
    assert report["contrasts"] == {"load": 3, "multipass": 1, "gravity": 1}


def test_sibling_contrast_of_a_known_shift_at_matched_slips():
    """The treated source is the control plus 2 N at slips between the control's: the
    contrast is 2 N, its u from the interpolation weights (GUM 5.1.2)."""
    control = pd.DataFrame({"slip": [0.1, 0.3, 0.5, 0.7], "dp_n": [10.0, 20.0, 26.0, 28.0]})
    treated = pd.DataFrame({"slip": [0.2, 0.4, 0.6]})
    treated["dp_n"] = np.interp(treated["slip"], control["slip"], control["dp_n"]) + 2.0
    points = pd.concat([control.assign(grouser_count=0, grouser_height_m=0.0),
                        treated.assign(grouser_count=12, grouser_height_m=0.01)],
                       ignore_index=True).assign(load_set_n=100.0, multipass=0,
                                                 gravity_mps2=9.80665)
    sigma = {"dp_n": np.full(len(points), 0.5)}
    prediction = {"dp_n": np.where(points["grouser_count"] > 0, 1.5, 0.0)}
    [c] = contrasts(points, sigma, {"grousers": prediction})
    u_each = np.hypot(0.5, 0.5 * np.sqrt(0.5))  # midway: (0.5 u)^2 + (0.5 u)^2 per control
    assert c["feature"] == "grousers" and c["n"] == 3
    assert c["contrast"] == pytest.approx(2.0)
    assert c["u"] == pytest.approx(u_each / np.sqrt(3))
    assert c["predicted"]["grousers"] == pytest.approx(1.5)


def test_a_free_form_beside_the_effects_own_law_keeps_the_law_and_its_strengths():
    single = candidates.candidate(BASE, ("multipass",), {"multipass": "krenn_hirzinger2009"})
    beside = candidates.with_free_form(single, "multipass")
    assert beside.effects == ("multipass",) and beside.params == single.params
    assert beside.key == "multipass(krenn_hirzinger2009/free_form)"
    assert candidates.is_free_form(beside.laws[0]) and not candidates.is_free_form(single.laws[0])
    other = candidates.with_free_form(single, "reduced_gravity")
    assert dict(zip(other.effects, other.laws)) == {"multipass": "krenn_hirzinger2009",
                                                    "reduced_gravity": candidates.FREE_FORM}
