"""Gap diagnosis on synthetic model data with injected effects: the decision rule, clear cases
found, the untestable effect named with the contrast it needs, the separating test."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

import terramechanics as tm
from terramechanics.effects.load_varying import SUFFIX as LOAD_VARYING
from sim_gap import candidates
from sim_gap.decide import Z_TIE, decide, gain_over_noise, paired_z, rank
from sim_gap.diagnose import Settings, diagnose
from sim_gap.discriminate import separating_test
from sim_gap.laws import assignments, best_fitting_laws, reference_laws, robust_decide
from sim_gap.simulated import Simulated

BASE = tm.shipped_model("bb2_sand").with_effects(**{n: False for n in tm.EFFECTS})
FAST = Settings(max_nfev=25, fold_nfev=8, n_boot=20)
DEFAULT_LAWS = Settings(max_nfev=25, fold_nfev=8, n_boot=20,
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


@pytest.mark.parametrize("effects, expected", [
    ({}, []),
    ({"bulldozing": {"coefficient": 1.5}}, ["bulldozing"]),
])
def test_injected_effect_is_found(effects, expected):
    """Under the default laws (the truth's): a law-robust call, as only one law is tried."""
    truth = BASE.with_soil(**TRUTH_SOIL).with_effects(**effects)
    report = diagnose(synthetic_points(truth), Simulated(BASE), CANDIDATES, DEFAULT_LAWS)
    assert report["verdict"] == expected
    assert report["folds"] == ["load=80", "load=180", "load=300"]
    labels = [c["label"] for c in report["candidates"]]
    assert set(labels) >= {"soil_only", "grousers(bekker1956)", "slip_sinkage(ding2011)",
                           "bulldozing(bekker1969)"}
    assert report["decision"]["law_sensitivity"]["one_law_only"]
    if expected:
        chosen = next(c for c in report["candidates"] if c["label"] == report["decision"]["chosen"])
        assert chosen["effects"] == expected
        soil = next(c for c in report["candidates"] if c["label"] == "soil_only")
        assert chosen["held_out_score"] < 0.6 * soil["held_out_score"]
        assert report["shrink"]["shrink_pct"]["dp_n"] > 40.0
        assert report["shrink"]["shrink_pct"]["resistance_n"] > 40.0


def test_slip_sinkage_is_found_on_a_smooth_wheel_and_aliased_on_a_lugged_one():
    """The same soil slip-sinkage: named on the smooth BB2 rim; on the lugged wheel the
    call is inconclusive, aliased with the lugs' slip-sinkage (sim_gap.aliasing)."""
    smooth = BASE.with_wheel(grouser_count=0, grouser_height_m=0.0)
    for base, candidates_ in ((smooth, ["slip_sinkage", "bulldozing"]), (BASE, CANDIDATES)):
        truth = base.with_soil(**TRUTH_SOIL).with_effects(slip_sinkage={"n1": 0.6})
        report = diagnose(synthetic_points(truth), Simulated(base), candidates_, DEFAULT_LAWS)
        chosen = report["decision"]["chosen"]
        assert chosen == "slip_sinkage(ding2011)"
        if base is smooth:
            assert report["verdict"] == ["slip_sinkage"]
            assert report["shrink"]["shrink_pct"]["sinkage_m"] > 40.0
        else:
            assert report["verdict"] == "inconclusive" and report["decision"]["aliased"]
            assert "smooth wheel" in report["decision"]["separating_test"]["test"]


def test_multipass_on_one_level_is_untestable_with_the_contrast_it_needs():
    truth = BASE.with_effects(multipass={"stiffness_gain_per_pass": 0.3})
    # 9 points: three per soil parameter, the fewest that can call "no missing effect"
    points = synthetic_points(truth, multipass=(0,), slips=(0.2, 0.35, 0.5))
    report = diagnose(points, Simulated(BASE), ["multipass", "bulldozing"], FAST)
    assert "multipass" in report["untestable_effects"]
    assert "second multipass level" in report["untestable_effects"]["multipass"]
    assert "neither found nor ruled out: multipass" in report["decision"]["reason"]
    assert report["contrasts"] == {"load": 3, "multipass": 1, "gravity": 1}


def test_without_the_contrast_the_call_is_inconclusive_with_a_test_to_run():
    """Grousers on one load, drawbar pull only: slip-sinkage mimics them on four slips; the
    diagnosis must not name either, and proposes the test that separates them."""
    truth = BASE.with_soil(kphi=2.3e7).with_effects(grousers={"shear_radius_factor": 0.8})
    points = synthetic_points(truth, loads=(180.0,), multipass=(0,))
    points = points[["run_id", "load_set_n", "wheel_load_n", "multipass", "gravity_mps2", "slip",
                     "dp_n", "dp_n_se"]]
    points.attrs.update(source="synthetic", wheel=truth.wheel, sinkage_relative=False)
    report = diagnose(points, Simulated(BASE), ["grousers", "slip_sinkage"], FAST)
    assert report["verdict"] == "inconclusive"
    assert report["folds"][0].startswith("slip band")
    assert "only 3.4 SE" in report["decision"]["reason"]
    test = report["decision"]["separating_test"]
    assert test["test"] == "add skid (braked) slips (-0.5, -0.2)"
    assert test["separation_sigma"] > 2.0


def test_separating_test_asks_for_the_missing_contrast():
    points = synthetic_points(BASE, multipass=(0,), slips=(0.2, 0.5))
    test = separating_test(Simulated(BASE), points, {},
                           {"effects.multipass.stiffness_gain_per_pass": 0.4})
    assert test["test"] == "run multipass level 1"
    assert test["separation_sigma"] > 3.0


def _fake(labels_losses: dict[str, np.ndarray]):
    """rank/decide inputs without fits: a stand-in for CrossValidated. A key is an effect
    set (``grousers+slip_sinkage``) or effects with their laws (``grousers(ding2011)``)."""

    class Fit:
        def __init__(self, key):
            parts = [] if key == "soil_only" else key.split("+")
            effects = tuple(p.split("(")[0] for p in parts)
            laws = tuple(p.split("(")[1].rstrip(")") if "(" in p else "law" for p in parts)
            self.candidate = candidates.Candidate(effects, (), laws)
            self.n_params, self.aicc, self.values = 3 + len(parts), 0.0, {}

    class CV:
        def __init__(self, key, losses):
            self.full, self.losses, self.held_out = Fit(key), losses, []

        def run_losses(self, n):
            return self.losses

    return {k: CV(k, v) for k, v in labels_losses.items()}


def test_decide_tied_singles_are_inconclusive_and_clear_single_is_called():
    rng = np.random.default_rng(1)
    noise = lambda: rng.normal(0, 0.05, 40)  # noqa: E731
    tied = {"soil_only": 6 + noise(), "grousers": 1 + noise(), "slip_sinkage": 1 + noise(),
            "grousers+slip_sinkage": 1 + noise()}
    ranked = rank(_fake(tied), 40)
    out = decide(ranked, tied)
    assert out["verdict"] == "inconclusive"
    assert set(out["leaders"]) == {"grousers", "slip_sinkage"}
    clear = dict(tied, slip_sinkage=3 + noise())
    out = decide(rank(_fake(clear), 40), clear)
    assert out["verdict"] == ["grousers"]
    assert out["z_vs_soil_only"] > 50


def test_decide_weak_gain_and_unexplained_gap_are_inconclusive():
    rng = np.random.default_rng(2)
    bull = 1.0 + rng.normal(0, 0.3, 30)
    weak = {"soil_only": bull + 0.08 + rng.normal(0, 0.2, 30), "bulldozing": bull}
    out = decide(rank(_fake(weak), 30), weak)
    assert 2.0 < out["z_vs_soil_only"] < 4.0
    assert out["verdict"] == "inconclusive" and out["leaders"] == ["bulldozing", "soil_only"]
    big = {"soil_only": 400 + rng.normal(0, 1, 30), "bulldozing": 100 + rng.normal(0, 1, 30)}
    out = decide(rank(_fake(big), 30), big)
    assert out["verdict"] == "inconclusive" and out.get("unexplained")
    assert "outside the candidate set" in out["reason"]
    # soil only leaves 2.5 sigma RMS (a flexible wheel under a law not in the candidates,
    # bench seed 13) or 1.7 (seed 14): no confident call; 1.2 sigma RMS still is one
    for level, verdict in ((6.0, "inconclusive"), (3.0, "inconclusive"), (1.5, [])):
        left = {"soil_only": level + rng.normal(0, 0.3, 30),
                "bulldozing": level + rng.normal(0, 0.3, 30)}
        assert decide(rank(_fake(left), 30), left)["verdict"] == verdict


def test_a_pair_is_called_only_if_each_effect_earns_its_place():
    """The pair beats wheel_flexibility alone consistently (> the 2 SE tie) but by 10 % of
    the held-out mean square only: the second effect may only patch the first one's law,
    so the pair is no practical improvement, the single is tied with it (rule 2) and,
    simpler, is the call. A pair that clears 38 % is called; one that clears 25 % or more
    but not by 4 SE is inconclusive."""
    rng = np.random.default_rng(4)
    flex = 1.0 + rng.normal(0, 0.3, 40)
    losses = {"soil_only": 6 + rng.normal(0, 0.1, 40), "grousers": 5 + rng.normal(0, 0.1, 40),
              "wheel_flexibility": flex, "grousers+wheel_flexibility": 0.9 * flex - 0.01
              + rng.normal(0, 0.05, 40)}
    ranked = rank(_fake(losses), 40)
    assert ranked[0]["label"] == "grousers+wheel_flexibility"
    assert paired_z(losses["wheel_flexibility"], losses["grousers+wheel_flexibility"]) > 4
    out = decide(ranked, losses)
    assert out["chosen"] == "wheel_flexibility" and out["verdict"] == ["wheel_flexibility"]
    # flexibility alone leaves 1.7 sigma RMS, the pair 1.2: 38 % of the held-out mean square
    losses["wheel_flexibility"] = 3.0 * flex
    losses["grousers+wheel_flexibility"] = 1.5 * flex + rng.normal(0, 0.02, 40)
    out = decide(rank(_fake(losses), 40), losses)
    assert out["verdict"] == ["grousers", "wheel_flexibility"]
    assert "each of its singles by at least 4 SE" in out["reason"]
    # more than half the mean square cleared, but on 5 of the 40 runs only: short of 4 SE
    losses = {"soil_only": 60 + rng.normal(0, 0.1, 40), "grousers": 50 + rng.normal(0, 0.1, 40),
              "wheel_flexibility": flex + np.where(np.arange(40) < 5, 30.0, 0.0),
              "grousers+wheel_flexibility": flex + rng.normal(0, 0.01, 40)}
    z = paired_z(losses["wheel_flexibility"], losses["grousers+wheel_flexibility"])
    assert Z_TIE < z < 4
    assert gain_over_noise(losses["wheel_flexibility"], losses["grousers+wheel_flexibility"]) > 0.25
    out = decide(rank(_fake(losses), 40), losses)
    assert out["chosen"] == "grousers+wheel_flexibility" and out["verdict"] == "inconclusive"
    assert out["leaders"] == ["grousers+wheel_flexibility", "wheel_flexibility"]
    assert "improves on wheel_flexibility alone by only" in out["reason"]


def test_the_nested_tie_is_for_the_better_single_only():
    """Bench seed 27 c009 (second signal model, a Ding grouser truth under Bekker's law):
    grousers + slip_sinkage 1.42, grousers alone 1.72 (11 % of its mean square), slip
    sinkage alone 2.2 (24 %, but 0.5 behind grousers on every run). Grousers, which the pair
    adds to, is tied with it; slip sinkage is no rival of grousers, and the call is
    grousers."""
    rng = np.random.default_rng(7)
    base = 1.42 + rng.normal(0, 0.05, 60)
    losses = {"soil_only": base + 1.06, "grousers": base + 0.30 + rng.normal(0, 0.02, 60),
              "slip_sinkage": base + 0.78 + rng.normal(0, 0.02, 60),
              "grousers+slip_sinkage": base}
    assert gain_over_noise(losses["slip_sinkage"], base) < 0.25
    out = decide(rank(_fake(losses), 60), losses)
    assert out["chosen"] == "grousers" and out["verdict"] == ["grousers"]


def test_a_second_effect_inside_the_repeatability_does_not_earn_its_place():
    """Bench seed 21 c011 in family: a flexible wheel (Wong's law) fitted to 0.37 sigma RMS
    held out, and a Rankine bulldozing of 0.1 x the formula that brought it to 0.15 sigma,
    6.4 SE consistently over the runs, 85 % of the loss: both far inside the run-to-run
    repeatability (1 sigma), so 10 % of the held-out mean square. Bulldozing is not named;
    the flexible wheel, the truth, is the call."""
    rng = np.random.default_rng(5)
    flex = 0.136 + rng.normal(0, 0.03, 48)
    losses = {"soil_only": 6 + rng.normal(0, 0.1, 48), "wheel_flexibility": flex,
              "bulldozing": 5 + rng.normal(0, 0.1, 48),
              "wheel_flexibility+bulldozing": 0.15 * flex + rng.normal(0, 0.002, 48)}
    assert paired_z(losses["wheel_flexibility"], losses["wheel_flexibility+bulldozing"]) > 4
    assert 1 - losses["wheel_flexibility+bulldozing"].mean() / flex.mean() > 0.8
    out = decide(rank(_fake(losses), 48), losses)
    assert out["chosen"] == "wheel_flexibility"
    assert out["verdict"] == ["wheel_flexibility"]


def test_candidates_free_the_fit_parameters_their_law_declares():
    """A candidate frees the strengths of the effect's law: the default law's when the
    simulation does not have the effect, else the law the simulation uses."""
    names = lambda c: [p.name for p in c.params[3:]]  # noqa: E731 (after the 3 soil ones)
    assert names(candidates.candidate(BASE, ("grousers",))) == [
        "effects.grousers.shear_radius_factor"]
    lugged = BASE.with_effects(grousers={"law": "ding2011"})
    assert names(candidates.candidate(lugged, ("grousers",))) == [
        "effects.grousers.shear_radius_factor", "effects.grousers.lug_sinkage_gain"]
    flex = candidates.effect_params("wheel_flexibility", "bekker1969")
    assert [(p.name, p.lower, p.upper, p.log) for p in flex] == [
        ("effects.wheel_flexibility.ground_pressure_pa", 2e3, 5e5, True)]
    for p in candidates.candidate(lugged, ("grousers",)).params[3:]:  # the names resolve
        lugged.with_parameters({p.name: p.start})


def test_a_call_that_holds_under_one_law_only_is_inconclusive_naming_the_law():
    """slip_sinkage wins under its ding2011 law, grousers 2-4 SE behind (not tied); under
    lyasko2010 slip_sinkage fits badly and grousers wins, and that assignment's best is
    within 4 SE of the reference's: the call depends on the law's shape."""
    rng = np.random.default_rng(3)
    noise = lambda s=0.05: rng.normal(0, s, 30)  # noqa: E731
    ding = 1 + noise()
    grousers = ding + 0.1 + noise(0.15)
    losses = {"soil_only": 8 + noise(), "grousers(bekker1956)": grousers,
              "slip_sinkage(ding2011)": ding, "slip_sinkage(lyasko2010)": 1.6 + noise(),
              "grousers(bekker1956)+slip_sinkage(ding2011)": ding + 0.02 + noise(0.01),
              "grousers(bekker1956)+slip_sinkage(lyasko2010)": grousers + noise(0.01)}
    assert 2.0 < paired_z(grousers, ding) < 4.0
    allowed = {"grousers": ("bekker1956",), "slip_sinkage": ("ding2011", "lyasko2010")}
    results = _fake(losses)
    reference = reference_laws(results, 30)
    assert reference == {"grousers": "bekker1956", "slip_sinkage": "ding2011"}
    out = robust_decide(results, allowed, reference, 30)
    assert out["verdict"] == "inconclusive" and out["law_dependent"]
    assert out["law_sensitivity"]["disagreeing"] == [
        {"effect": "slip_sinkage", "law": "lyasko2010", "verdict": ["grousers"],
         "chosen": "grousers(bekker1956)"}]
    assert out["law_sensitivity"]["refuted"] == []
    assert out["leaders"] == ["slip_sinkage(ding2011)", "grousers(bekker1956)"]
    assert "with slip_sinkage under lyasko2010 it is grousers" in out["reason"]
    # lyasko2010 far worse than everything ding2011 allows: refuted, the call stands
    losses["grousers(bekker1956)"] = 3 + noise()
    losses["grousers(bekker1956)+slip_sinkage(lyasko2010)"] = 3 + noise()
    out = robust_decide(_fake(losses), allowed, reference, 30)
    assert out["verdict"] == ["slip_sinkage"] and out["chosen"] == "slip_sinkage(ding2011)"
    (refuted,) = out["law_sensitivity"]["refuted"]
    assert refuted["law"] == "lyasko2010" and refuted["z_best_vs_reference"] > 4
    assert "refuted by the data" in out["reason"]
    # both laws explain the data far better than grousers: agreement, nothing refuted
    losses["slip_sinkage(lyasko2010)"] = ding + 0.001 + noise(0.001)
    losses["grousers(bekker1956)+slip_sinkage(lyasko2010)"] = ding + 0.02 + noise(0.01)
    out = robust_decide(_fake(losses), allowed, reference, 30)
    assert out["verdict"] == ["slip_sinkage"]
    sens = out["law_sensitivity"]
    assert sens["robust"] and not sens["refuted"] and [
        a["verdict"] for a in sens["assignments"]] == [["slip_sinkage"], ["slip_sinkage"]]


def test_the_law_check_is_centred_on_the_best_candidates_laws():
    """Bench seed 22 c005 in family: Bekker's flexible wheel fits best alone, but with
    slip-sinkage the pair fits best under Wong's law (the truth's). Centred on each effect's
    best law alone, the call was read under Bekker's flexibility, where the pair hardly beats
    slip-sinkage alone: inconclusive. Centred on the best candidate's laws it is the pair."""
    rng = np.random.default_rng(6)
    noise = lambda s=0.02: rng.normal(0, s, 40)  # noqa: E731
    slip = 1.2 + noise(0.1)
    losses = {"soil_only": 9 + noise(), "slip_sinkage(lyasko2010)": slip,
              "wheel_flexibility(bekker1969)": 3.0 + noise(),
              "wheel_flexibility(wong2010)": 3.3 + noise(),
              "slip_sinkage(lyasko2010)+wheel_flexibility(bekker1969)": 0.97 * slip,
              "slip_sinkage(lyasko2010)+wheel_flexibility(wong2010)": 0.01 + noise(0.002)}
    allowed = {"slip_sinkage": ("lyasko2010",),
               "wheel_flexibility": ("bekker1969", "wong2010")}
    results = _fake(losses)
    alone = reference_laws(results, 40)
    assert alone == {"slip_sinkage": "lyasko2010", "wheel_flexibility": "bekker1969"}
    centre = best_fitting_laws(results, alone, 40)
    assert centre == {"slip_sinkage": "lyasko2010", "wheel_flexibility": "wong2010"}
    assert robust_decide(results, allowed, alone, 40)["verdict"] == "inconclusive"
    out = robust_decide(results, allowed, centre, 40)
    assert out["verdict"] == ["slip_sinkage", "wheel_flexibility"]
    assert out["chosen"] == "slip_sinkage(lyasko2010)+wheel_flexibility(wong2010)"
    (refuted,) = out["law_sensitivity"]["refuted"]
    assert refuted == {"effect": "wheel_flexibility", "law": "bekker1969",
                       "z_best_vs_reference": refuted["z_best_vs_reference"]}


def test_pairs_vary_one_law_at_a_time():
    allowed = {"grousers": ("bekker1956", "ding2011"), "slip_sinkage": ("ding2011", "lyasko2010"),
               "bulldozing": ("bekker1969",)}
    reference = {"grousers": "ding2011", "slip_sinkage": "ding2011", "bulldozing": "bekker1969"}
    assert [c.key for c in candidates.singles(BASE, allowed)] == [
        "soil_only", "grousers(bekker1956)", "grousers(ding2011)", "slip_sinkage(ding2011)",
        "slip_sinkage(lyasko2010)", "bulldozing(bekker1969)"]
    assert [c.key for c in candidates.pairs(BASE, allowed, reference)] == [
        "grousers(ding2011)+slip_sinkage(ding2011)", "grousers(bekker1956)+slip_sinkage(ding2011)",
        "grousers(ding2011)+slip_sinkage(lyasko2010)",
        "grousers(ding2011)+bulldozing(bekker1969)", "grousers(bekker1956)+bulldozing(bekker1969)",
        "slip_sinkage(ding2011)+bulldozing(bekker1969)",
        "slip_sinkage(lyasko2010)+bulldozing(bekker1969)"]
    assert assignments(allowed, reference) == [
        reference, {**reference, "grousers": "bekker1956"},
        {**reference, "slip_sinkage": "lyasko2010"}]
    lyasko = candidates.candidate(BASE, ("slip_sinkage",), {"slip_sinkage": "lyasko2010"})
    model = BASE.with_parameters({**lyasko.law_values(), "effects.slip_sinkage.coefficient": 0.5})
    assert model.effects["slip_sinkage"].law == "lyasko2010"
    assert model.effects["slip_sinkage"].coefficient == 0.5
    with pytest.raises(KeyError, match="unknown law 'x' of effect 'grousers'"):
        candidates.allowed_laws(BASE, ["grousers"], {"grousers": ("x",)})


def test_lug_sinkage_mimics_soil_slip_sinkage_on_one_grousered_wheel():
    """Ding 2011 lugs add n1_lug = kappa h / r to the sinkage exponent's slip slope: on one
    grousered wheel soil slip-sinkage n1 = 0.6 reads as lugs with kappa = 0.6 r / h and
    no extra shear radius. Under every law the call is inconclusive, and the test that
    tells them apart is a smooth wheel."""
    truth = BASE.with_soil(**TRUTH_SOIL).with_effects(slip_sinkage={"n1": 0.6})
    report = diagnose(synthetic_points(truth), Simulated(BASE), CANDIDATES, FAST)
    assert report["verdict"] == "inconclusive"
    # the slip-sinkage leader is Ding's law, published or load-varying (0.10.0: its exponent
    # fits the noise a little better, held out as well)
    assert {label.replace(LOAD_VARYING, "") for label in report["decision"]["leaders"]} == {
        "slip_sinkage(ding2011)", "grousers(ding2011)"}
    lugs = next(c for c in report["candidates"] if c["label"] == "grousers(ding2011)")
    kappa = 0.6 * BASE.wheel.radius_m / BASE.wheel.grouser_height_m  # 8.15
    assert lugs["parameters"]["effects.grousers.lug_sinkage_gain"] == pytest.approx(kappa,
                                                                                  rel=0.05)
    assert lugs["parameters"]["effects.grousers.shear_radius_factor"] < 0.1
    assert report["decision"]["separating_test"]["test"].startswith("run a smooth wheel")
