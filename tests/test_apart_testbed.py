"""The apart testbed (testbeds/apart, docs/validation/gap-apart.md): its solver against hand
quadrature and Bekker's closed-form sinkage scaling, its effect shapes against their stated
ranges and published directions, and a generated campaign read by ``swtlab inspect``, with
its truth kept outside the campaign folder.

INDEPENDENT checks: the quadrature is scipy's ``quad`` over the stress profiles as the
solver's docstring defines them; the scaling is Bekker's rigid-wheel sinkage law
``z ~ k^(-2/(2n+1))`` (Bekker 1969, small angles); the published anchors are Ding et al.
2011's lug/smooth DP ratios (terramechanics/data/ding2011_80n.csv, read as a file). The
shape and range checks are in-family (they check the generator does what it states).
"""

from __future__ import annotations

import json
import math
import tomllib

import numpy as np
import pytest
from scipy.integrate import quad

from swtlab_cli.main import main as swtlab
from testbeds.apart import effects as fx
from testbeds.apart.campaign import draw_campaign, write_campaign_folder
from testbeds.apart.design import draw_plan
from testbeds.apart.shapes import draw_pchip, draw_power, evaluate
from testbeds.apart.soil import (PUBLISHED, ReeceSoil, from_published, pressure_pa,
                                 shear_stress_pa)
from testbeds.apart.solver import Contact, forces_at, solve

G0 = 9.80665
SOIL = from_published(PUBLISHED[1], 0.1).with_(residual_ratio=0.8)


def _tent(theta, lo, peak, hi, value):
    """The linear profile: 0 at lo, value at peak, 0 at hi."""
    if theta <= peak:
        return value * (theta - lo) / (peak - lo)
    return value * (hi - theta) / (hi - peak)


@pytest.mark.parametrize("slip", [-0.6, -0.15, 0.0, 0.2, 0.7])
def test_rigid_wheel_forces_match_hand_quadrature(slip):
    r, b, theta1 = 0.13, 0.1, 0.35
    c = Contact(SOIL, r, b, G0, shear_gain=1.3)
    got = forces_at(c, theta1, slip)
    theta_m = (0.38 + 0.22 * slip) * theta1
    theta2 = -0.1 * theta1
    ratio = 1 - slip if slip >= 0 else 1 / (1 + slip)
    sigma_m = (SOIL.cohesion_pa * SOIL.kc_prime + 1600 * G0 * b * SOIL.kphi_prime) * (
        r * (math.cos(theta_m) - math.cos(theta1)) / b) ** SOIL.n
    j_m = r * ((theta1 - theta_m) - ratio * (math.sin(theta1) - math.sin(theta_m)))
    tau_m = 1.3 * float(shear_stress_pa(SOIL, sigma_m, j_m))

    def integral(f):
        return sum(quad(f, a, e, epsabs=0, epsrel=1e-12)[0]
                   for a, e in ((theta2, theta_m), (theta_m, theta1)))

    def sigma(t):
        return _tent(t, theta2, theta_m, theta1, sigma_m)

    def tau(t):
        return _tent(t, theta2, theta_m, theta1, tau_m)

    fz = r * b * integral(lambda t: sigma(t) * math.cos(t) + tau(t) * math.sin(t))
    dp = r * b * integral(lambda t: tau(t) * math.cos(t) - sigma(t) * math.sin(t))
    torque = r * r * b * integral(tau)
    assert got["fz_n"] == pytest.approx(fz, rel=1e-9)
    assert got["dp_n"] == pytest.approx(dp, rel=1e-9, abs=1e-9)
    assert got["torque_nm"] == pytest.approx(torque, rel=1e-9, abs=1e-12)
    assert got["sinkage_m"] == pytest.approx(r * (1 - math.cos(theta1)), rel=1e-12)


def test_flexible_wheel_forces_match_hand_quadrature():
    r, b, delta, slip = 0.12, 0.09, 0.004, 0.3
    c = Contact(SOIL, r, b, G0, deflection_m=delta)
    theta1 = 0.4
    got = forces_at(c, theta1, slip)
    half = math.sqrt(2 * r * delta - delta ** 2)
    theta_f = math.asin(half / r)
    z = r * (1 - math.cos(theta1)) - delta
    sigma_f = float(pressure_pa(SOIL, z, b, G0))
    ratio = 1 - slip
    j_front = r * ((theta1 - theta_f) - ratio * (math.sin(theta1) - math.sin(theta_f)))
    tau_arc = float(shear_stress_pa(SOIL, sigma_f, j_front))
    tau_flat = float(shear_stress_pa(SOIL, sigma_f, (1 / ratio - 1) * half))
    theta2 = -theta_f - 0.1 * (theta1 - theta_f)

    def front(f):
        return quad(f, theta_f, theta1, epsrel=1e-12)[0]

    def rear(f):
        return quad(f, theta2, -theta_f, epsrel=1e-12)[0]

    def down(t):
        return (theta1 - t) / (theta1 - theta_f)

    def up(t):
        return (t - theta2) / (-theta_f - theta2)

    fz = r * b * (front(lambda t: down(t) * (sigma_f * math.cos(t) + tau_arc * math.sin(t)))
                  + rear(lambda t: up(t) * (sigma_f * math.cos(t) + tau_flat * math.sin(t))))
    fz += 2 * half * b * sigma_f
    dp = r * b * (front(lambda t: down(t) * (tau_arc * math.cos(t) - sigma_f * math.sin(t)))
                  + rear(lambda t: up(t) * (tau_flat * math.cos(t) - sigma_f * math.sin(t))))
    dp += 2 * half * b * tau_flat
    torque = r * r * b * (tau_arc * front(down) + tau_flat * rear(up))
    torque += 2 * half * b * tau_flat * (r - delta)
    assert (got["fz_n"], got["dp_n"], got["torque_nm"]) == pytest.approx((fz, dp, torque),
                                                                       rel=1e-9)
    assert got["sinkage_m"] == pytest.approx(z, rel=1e-12)


def test_hump_shear_peaks_at_the_mohr_coulomb_strength_and_ends_at_the_residual():
    sigma = 20e3
    strength = SOIL.cohesion_pa + sigma * math.tan(math.radians(SOIL.friction_angle_deg))
    j = np.linspace(0, 20 * SOIL.shear_peak_m, 20001)
    tau = shear_stress_pa(SOIL, sigma, j)
    assert tau.max() == pytest.approx(strength, rel=1e-6)
    # Wong's curve: K_r of its value at j = K_w far out; odd in j
    at_kw = float(shear_stress_pa(SOIL, sigma, SOIL.shear_peak_m))
    assert tau[-1] == pytest.approx(SOIL.residual_ratio * at_kw, rel=1e-6)
    assert float(shear_stress_pa(SOIL, sigma, -0.01)) == -float(shear_stress_pa(SOIL, sigma, 0.01))


def test_solved_sinkage_carries_the_load_and_follows_bekkers_scaling():
    """Frictionless, cohesionless soil at zero slip: no shear, so W = r b sigma_m I_c, and
    at small angles Bekker's rigid wheel z ~ k^(-2/(2n+1)) holds for any stress profile of
    fixed shape (a doubled modulus: 2^(-2/(2n+1)))."""
    soil = ReeceSoil(kc_prime=0.0, kphi_prime=2e4, n=0.8, cohesion_pa=0.0,
                     friction_angle_deg=0.0, density_kg_m3=1600.0, shear_peak_m=0.02)
    c1 = Contact(soil, 0.15, 0.1, G0)
    c2 = Contact(soil.with_(kphi_prime=4e4), 0.15, 0.1, G0)
    a, b = solve(c1, 30.0, 0.0), solve(c2, 30.0, 0.0)
    assert a["fz_n"] == pytest.approx(30.0, rel=1e-9)
    # small angles: z < 0.2 % r, theta1 < 0.064 rad, so cos and sin differ from their
    # small-angle forms by theta1^2 / 12 < 4e-4 relative
    assert a["sinkage_m"] < 0.002 * 0.15
    assert b["sinkage_m"] / a["sinkage_m"] == pytest.approx(2 ** (-2 / 2.6), rel=1e-3)


def test_no_step_through_zero_slip():
    c = Contact(SOIL, 0.12, 0.1, G0)
    h = 1e-5
    left, mid, right = (solve(c, 120.0, s) for s in (-h, 0.0, h))
    for q in ("dp_n", "torque_nm", "sinkage_m"):
        slope_left = (mid[q] - left[q]) / h
        slope_right = (right[q] - mid[q]) / h
        scale = max(abs(slope_left), abs(slope_right), 1e-9)
        assert abs(slope_left - slope_right) / scale < 0.01, q  # C1 at s = 0


def test_drawn_shapes_are_monotone_and_end_where_stated():
    x = np.linspace(0, 1, 401)
    for seed in range(50):
        rng = np.random.default_rng(seed)
        start = float(rng.uniform(0, 0.6))
        for shape in (draw_pchip(rng, start, int(rng.integers(1, 4))),
                      draw_power(rng, 1.0, 3.0)):
            y = evaluate(shape, x)
            assert np.all(np.diff(y) >= -1e-12)
            assert y[-1] == pytest.approx(1.0)
        assert evaluate(draw_pchip(rng, start), 0.0) == pytest.approx(start)


def _ding_lug_dp_ratios() -> dict[float, float]:
    """Ding et al. 2011's lug/smooth DP ratio at each slip >= 0.1 (digitised points)."""
    from pathlib import Path
    text = (Path(__file__).resolve().parents[1] / "terramechanics/data/ding2011_80n.csv")
    rows = [line.split(",") for line in text.read_text().splitlines()
            if line and not line.startswith(("#", "case_id"))]
    dp = {(int(r[4]), float(r[6])): float(r[7]) for r in rows}
    return {s: dp[(30, s)] / dp[(0, s)] for (n, s) in dp if n == 0 and s >= 0.1}


def test_lug_gain_spans_dings_published_lug_to_smooth_ratio():
    """On Ding's wheel and soil at 80 N the drawn lug laws give DP ratios that cover the
    published 1.27-1.63 (s = 0.1-0.6) and stay under 2.5."""
    published = _ding_lug_dp_ratios()
    soil = from_published(PUBLISHED[3], 0.165)
    ratios = []
    for seed in range(40):
        law = fx.draw("grousers", np.random.default_rng(seed))
        for s in (0.2, 0.4, 0.6):
            gain, dig = fx.lug_terms(law, 30, 0.010, 0.15735, s)
            lug_soil = soil.with_(kc_prime=soil.kc_prime / dig, kphi_prime=soil.kphi_prime / dig)
            lugged = solve(Contact(lug_soil, 0.15735, 0.165, G0, shear_gain=gain), 80.0, s)
            smooth = solve(Contact(soil, 0.15735, 0.165, G0), 80.0, s)
            ratios.append(lugged["dp_n"] / smooth["dp_n"])
    assert min(ratios) < min(published.values()) and max(ratios) > max(published.values())
    assert 1.0 < min(ratios) and max(ratios) < 2.5


def test_effects_act_in_their_published_directions():
    rng = np.random.default_rng(7)
    for _ in range(10):
        mp = fx.draw("multipass", rng)
        rerun = fx.multipass_soil(mp, SOIL, 1)
        virgin, second = (solve(Contact(s, 0.12, 0.1, G0), 120.0, 0.0) for s in (SOIL, rerun))
        # Holm 1969: a rerun sinks less and resists less
        assert second["sinkage_m"] < virgin["sinkage_m"]
        assert second["dp_n"] > virgin["dp_n"]
        g = fx.draw("reduced_gravity", rng)
        earth = solve(Contact(fx.gravity_soil(g, SOIL, G0), 0.12, 0.1, G0), 100.0, 0.2)
        mars = solve(Contact(fx.gravity_soil(g, SOIL, 3.71), 0.12, 0.1, 3.71), 100.0, 0.2)
        same = solve(Contact(fx.gravity_soil(None, SOIL, 3.71), 0.12, 0.1, 3.71), 100.0, 0.2)
        assert mars["sinkage_m"] > earth["sinkage_m"]  # Kobayashi et al. 2010
        assert same["sinkage_m"] == pytest.approx(earth["sinkage_m"], rel=1e-9)
        s = fx.draw("slip_sinkage", rng)
        assert fx.slip_sinkage_divisor(s, 0.0) == 1.0
        assert fx.slip_sinkage_divisor(s, 0.7) >= fx.slip_sinkage_divisor(s, 0.3) > 1.0
        flex = fx.draw("wheel_flexibility", rng)
        d = [fx.deflection_m(flex, 30.0, w, 100.0) for w in (50.0, 100.0, 200.0)]
        assert d[0] < d[1] < d[2] and d[1] == pytest.approx(
            100.0 / (1000 * 30.0 * flex["stiffness_factor"]))
        bull = fx.draw("bulldozing", rng)
        z = 0.01
        n_phi = math.tan(math.radians(45 + SOIL.friction_angle_deg / 2)) ** 2
        wall = 0.1 * (1600 * G0 * z * z * n_phi / 2 + 2 * SOIL.cohesion_pa * z * math.sqrt(n_phi))
        assert fx.bulldozing_n(bull, SOIL, z, 0.1, G0) == pytest.approx(
            bull["rankine_multiple"] * wall, rel=1e-12)


def test_stiffness_declared_only_on_flexible_wheels_and_levels_where_needed():
    for seed in range(60):
        rng = np.random.default_rng(seed)
        effects = set(rng.choice(fx.SIX, size=int(rng.integers(0, 3)), replace=False).tolist())
        plan = draw_plan(rng, "c000", effects)
        assert (plan.wheel.stiffness_n_per_mm is not None) == ("wheel_flexibility" in effects)
        assert (plan.wheel.grouser_count > 0) == ("grousers" in effects)
        assert plan.twin is None or plan.twin.grouser_count == 0
        if "multipass" in effects:
            assert plan.multipass == (0, 1)
        if "reduced_gravity" in effects:
            assert len(plan.gravity_mps2) == 2
        assert len(plan.loads_n) == 3 and min(s for s in plan.slips) < 0 < max(plan.slips)
        assert 22 <= len(plan.runs) <= 60


def test_campaigns_are_reproducible():
    a, b = draw_campaign(3, 5), draw_campaign(3, 5)
    assert [r["steady"]["dp_n"] for r in a["rows"]] == [r["steady"]["dp_n"] for r in b["rows"]]


def test_written_campaign_reads_through_inspect_and_keeps_its_truth_apart(tmp_path, capsys):
    # the first campaign of seed 1 whose plan is the smallest: a rigid smooth wheel
    index = next(i for i in range(40) if len(draw_campaign(1, i)["rows"]) == 22
                 and not draw_campaign(1, i)["outside"])
    doc = write_campaign_folder(tmp_path, 1, index)
    name = doc["campaign"]
    folder = tmp_path / name
    runs = sorted((folder / "campaign").glob("*.mcap"))
    assert len(runs) == len(doc["runs"]) == 22
    assert not (folder / "truth").exists() and not list(folder.rglob("*.json"))
    assert (tmp_path / "truth" / f"{name}.json").exists()
    sim = tomllib.loads((folder / "sim.toml").read_text())
    assert "effects" not in sim
    wheel = doc["plan"]["wheel"]
    assert sim["wheel"]["radius_m"] == wheel["radius_m"]
    assert sim["soil"]["name"] == doc["published_soil"]["name"]
    truth_by_id = {r["run_id"]: r for r in doc["runs"]}
    for path in runs[:3]:
        capsys.readouterr()
        assert swtlab(["inspect", "--json", str(path)]) == 0
        seen = json.loads(capsys.readouterr().out)["metadata"]
        t = truth_by_id[seen["run"]["run_id"]]
        assert seen["run"]["load_n"] == t["load_n"]
        assert seen["run"]["slip_setpoint"] == t["slip_setpoint"]
        assert seen["wheel"]["radius_m"] == wheel["radius_m"]
        assert seen["wheel"]["stiffness_n_per_mm"] == wheel["stiffness_n_per_mm"]


def _truth(name, effects, outside=()):
    cls = "outside" if outside else ("none", "single", "pair")[len(effects)]
    return {"campaign": name, "class": cls, "effects": list(effects), "outside": list(outside),
            "runs": [{}] * 22, "plan": {"twin": None}}


@pytest.mark.parametrize("effects, outside, report, outcome, p_true", [
    (["grousers"], [], {"verdict": ["grousers"]}, "right", None),
    (["grousers", "multipass"], [], {"verdict": ["multipass", "grousers"]}, "right", None),
    ([], [], {"verdict": []}, "right", None),
    (["grousers"], [], {"verdict": ["slip_sinkage"]}, "wrong", None),
    (["grousers"], [], {"verdict": "inconclusive",
                        "probabilities": {"grousers(ding2011)": 0.5, "grousers(bekker1956)": 0.2,
                                          "slip_sinkage(lyasko2010)": 0.3}}, "inconclusive", 0.7),
    ([], ["rate_effect"], {"verdict": "inconclusive"}, "right", None),
    ([], ["rate_effect"], {"verdict": "outside the candidates"}, "right", None),
    (["bulldozing"], ["rig_artefact"], {"verdict": ["bulldozing"]}, "wrong", None),
    ([], [], {"verdict": "inconclusive", "probabilities": [
        {"label": "soil_only", "probability": 0.6}, {"label": "outside", "probability": 0.4}]},
     "inconclusive", 0.6),
])
def test_scorer_reads_verdicts_and_probabilities(tmp_path, effects, outside, report, outcome,
                                                 p_true):
    from testbeds.apart.score import score_campaign

    (tmp_path / "gap.json").write_text(json.dumps(report))
    row = score_campaign(tmp_path, _truth("c000", effects, outside))
    assert row["outcome"] == outcome
    assert row["p_true"] == (pytest.approx(p_true) if p_true is not None else None)


def test_where_the_probability_of_a_truth_of_the_six_goes(tmp_path):
    """A single (grousers) whose probability is split, by hand: 0.5 on it (two laws), 0.2 on
    a pair holding it, 0.1 on none, 0.05 on another single, 0.15 outside; the mean over
    two campaigns per class, and none for a truth outside the six."""
    from testbeds.apart.score import calibration, calibration_markdown, score_campaign

    report = {"verdict": "inconclusive", "probabilities": {
        "grousers(ding2011)": 0.3, "grousers(bekker1956)": 0.2,
        "grousers+multipass": 0.2, "soil_only": 0.1, "slip_sinkage(lyasko2010)": 0.05,
        "outside_candidates": 0.15}}
    (tmp_path / "gap.json").write_text(json.dumps(report))
    row = score_campaign(tmp_path, _truth("c000", ["grousers"]))
    assert row["p_where"] == pytest.approx(
        {"truth": 0.5, "larger": 0.2, "smaller": 0.1, "other": 0.05, "outside": 0.15})
    other = score_campaign(tmp_path, _truth("c001", ["multipass"]))
    assert other["p_where"] == pytest.approx(
        {"truth": 0.0, "larger": 0.2, "smaller": 0.1, "other": 0.55, "outside": 0.15})
    assert "p_where" not in score_campaign(tmp_path, _truth("c002", [], ["rate_effect"]))
    cal = calibration([row, other])
    assert cal["where"]["single"] == pytest.approx(
        {"n": 2, "truth": 0.25, "larger": 0.2, "smaller": 0.1, "other": 0.3, "outside": 0.15})
    assert cal["where"]["single: grousers"] == pytest.approx({"n": 1, **row["p_where"]})
    assert cal["where"]["single: multipass"] == pytest.approx({"n": 1, **other["p_where"]})
    assert "| single | 2 | 0.25 | 0.20 | 0.10 | 0.30 | 0.15 | - |" in calibration_markdown(cal)
    with_d = calibration([{**row, "distances": {"grousers": 12.0}},
                          {**row, "distances": {"grousers": 30.0}}])
    assert with_d["where"]["single: grousers"]["median_d"] == pytest.approx(21.0)
    assert "| single: grousers | 2 | 0.50 | 0.20 | 0.10 | 0.05 | 0.15 | 21 |" in \
        calibration_markdown(with_d)


def test_scorer_counts_a_failed_step(tmp_path):
    from testbeds.apart.score import score_campaign

    (tmp_path / "failure.txt").write_text("gap: no usable run\n")
    row = score_campaign(tmp_path, _truth("c000", ["grousers"]))
    assert row["outcome"] == "failed" and row["failed"] == "gap: no usable run"


@pytest.mark.parametrize("slip", [-0.2, -0.5])
def test_braked_branch_brackets_the_cmu_smooth_wheel(ingest_cmu_root, slip):
    """INDEPENDENT, real data: the CMU smooth wheel (r 58 mm, b 50 mm, about 20 N; straight
    runs of smooth_runs.csv) brakes at DP/W about -0.35 at s = -0.2 and -0.85 at -0.5. The
    solver, untuned, on that wheel over the four published soils brackets both."""
    import pandas as pd

    runs = pd.read_csv(ingest_cmu_root / "smooth_runs.csv").dropna(subset=["run_file"])
    runs = runs[(runs.slip_angle_deg == 0) & ((runs.slip - slip).abs() < 0.01)]
    assert len(runs) >= 3
    measured = float((runs.tractive_force_n / runs.wheel_load_n).mean())
    load = float(runs.wheel_load_n.mean())
    modelled = [solve(Contact(from_published(p, 0.05), 0.058, 0.05, G0), load, slip)["dp_n"]
                / load for p in PUBLISHED]
    assert min(modelled) < measured < max(modelled)


def test_a_lugged_wheel_runs_steady_for_four_grouser_periods():
    from testbeds.apart.campaign import timeline
    from testbeds.apart.design import draw_plan

    for seed in range(20):
        plan = draw_plan(np.random.default_rng(seed), "c000", {"grousers"})
        tl = timeline(plan)
        w = plan.wheel
        slowest = min(r.velocity_mps * (1 + r.slip) if r.slip < 0 else
                      r.velocity_mps / (1 - r.slip) for _, r in plan.runs)
        period = 2 * math.pi * w.radius_m / (w.grouser_count * slowest)
        steady = tl.decel_start_s - tl.motion_start_s - tl.settle_s
        assert steady >= max(4 * period, 14.5) - 1e-9


def test_confident_wrong_upper_bound_is_clopper_pearsons():
    """The 95 % upper bound of a rate seen k times in n: the rate at which seeing k or fewer
    has probability 5 % (the binomial's own cdf, solved here by bisection)."""
    from scipy.stats import binom

    from testbeds.apart.score import upper_95

    for k, n in ((0, 208), (3, 208), (10, 112)):
        lo, hi = 0.0, 1.0
        for _ in range(60):
            mid = 0.5 * (lo + hi)
            lo, hi = (mid, hi) if binom.cdf(k, n, mid) > 0.05 else (lo, mid)
        assert upper_95(k, n) == pytest.approx(lo, abs=1e-9)
    assert upper_95(0, 208) == pytest.approx(1 - 0.05 ** (1 / 208))


def test_reliability_bins_count_each_campaign_once():
    from testbeds.apart.score import calibration

    rows = [{"class": "single", "outcome": "right" if i % 3 else "wrong", "outside": [],
             "effects": ["grousers"], "leading": "grousers" if i % 3 else "none",
             "p_leading": p, "p_true": p if i % 3 else 1 - p}
            for i, p in enumerate(np.linspace(0.3, 1.0, 30))]
    cal = calibration(rows)
    assert sum(b["n"] for b in cal["bins"]) == 30
    assert cal["confident_wrong"] == 10
    top = cal["bins"][-1]
    assert top["right"] == pytest.approx(np.mean([bool(i % 3) for i, p in enumerate(
        np.linspace(0.3, 1.0, 30)) if p >= 0.9]))


def test_reliability_per_class_of_the_truth():
    """Two classes miscalibrated in opposite directions, which the pooled bins hide: singles
    led rightly at 0.6 (stated 0.6, right 1.0), pairs led wrongly at 0.9 (a single leads;
    stated 0.9, right 0.0); campaigns without probabilities are left out."""
    from testbeds.apart.score import calibration, calibration_markdown

    single = {"class": "single", "outcome": "inconclusive", "outside": [],
              "effects": ["grousers"], "leading": "grousers", "p_leading": 0.6, "p_true": 0.6}
    pair = {"class": "pair", "outcome": "wrong", "outside": [],
            "effects": ["grousers", "bulldozing"], "leading": "grousers", "p_leading": 0.9,
            "p_true": 0.05}
    failed = {**single, "outcome": "failed", "p_leading": None, "p_true": None}
    cal = calibration([single] * 4 + [pair] * 2 + [failed])
    assert cal["by_class"] == {"single": {"n": 4, "stated": 0.6, "right": 1.0},
                               "pair": {"n": 2, "stated": 0.9, "right": 0.0}}
    assert "| pair | 2 | 0.90 | 0.00 |" in calibration_markdown(cal)


@pytest.mark.slow  # one campaign (22 runs) through swtlab process and swtlab gap: about 20 s
@pytest.mark.slow_campaign
@pytest.mark.slow_diagnosis
def test_calibration_bench_runs_the_full_chain_on_a_subset(tmp_path):
    """Plumbing of ``python -m bench gap_calibration`` on one campaign of a seed kept for
    this test (9001): the campaign written, processed, diagnosed and scored (one is enough
    for the plumbing, and a second cost 18 s; scoring many is the bench's own job)."""
    from bench.bench_gap_calibration import run

    result = run(tmp_path, (9001,), 1, jobs=1)
    assert result["n"] == 1 and (tmp_path / "s9001" / "c000" / "main.sqlite").exists()
    assert all(r["outcome"] != "failed" for r in result["campaigns"]), result["campaigns"]
    assert sum(b["n"] for b in result["calibration"]["bins"]) == 1
    assert all(0.0 <= r["p_true"] <= 1.0 for r in result["campaigns"])


def test_misfit_after_soil_recalibration_per_class(tmp_path):
    """Hand-made reports: a no-effect campaign whose points miss by 3 sigma in each quantity
    (RMS 3), a bulldozing single called "no missing effect" missing by 1 sigma (RMS 1),
    a campaign without a report left out."""
    from testbeds.apart.misfit import misfits, summary

    def point(z):
        return {q: {"measured": 1.0 + z * 0.5, "soil_only": 1.0, "sigma": 0.5}
                for q in ("dp_n", "torque_nm", "sinkage_m")}

    out = tmp_path / "s1"
    for name, cls, effects, z, verdict in (("c000", "none", [], 3.0, "inconclusive"),
                                           ("c001", "single", ["bulldozing"], -1.0, []),
                                           ("c002", "single", ["grousers"], 0.0, None)):
        (out / "truth").mkdir(parents=True, exist_ok=True)
        (out / "truth" / f"{name}.json").write_text(json.dumps(
            {"class": cls, "effects": effects, "outside": []}))
        if verdict is not None:
            (out / name).mkdir()
            (out / name / "gap.json").write_text(json.dumps(
                {"verdict": verdict, "points": [point(z), point(z)]}))
    rows = misfits([out])
    assert [(r["campaign"], r["rms"], r["wrong_none"]) for r in rows] == [
        ("s1/c000", pytest.approx(3.0), False), ("s1/c001", pytest.approx(1.0), True)]
    text = summary(rows)
    assert "| none | 1 | 3.0 | 3.0 | 3.0 | 3.0 |" in text and "s1/c001 (single) 1.0" in text


def test_paired_comparison_of_two_diagnoses_of_the_same_campaigns():
    """Hand-made score rows of three campaigns diagnosed twice: a single called rightly by
    both, a no-effect campaign that becomes a call, a rig artefact read as no missing effect
    that becomes "outside the candidates"; the figures counted by hand."""
    from testbeds.apart.compare import changed, figures, markdown

    def row(name, cls, leading, p, outcome, p_true, effects=(), outside=()):
        return {"campaign": name, "class": cls, "effects": list(effects),
                "outside": list(outside), "leading": leading, "p_leading": p,
                "outcome": outcome, "p_true": p_true}

    single = row("s1/c000", "single", "grousers", 0.95, "right", 0.95, ["grousers"])
    before = [single, row("s1/c001", "none", "none", 0.6, "inconclusive", 0.6),
              row("s1/c002", "outside", "none", 0.93, "wrong", 0.05, outside=["rig_artefact"])]
    after = [single, row("s1/c001", "none", "none", 0.92, "right", 0.92),
             row("s1/c002", "outside", "outside_candidates", 0.7, "right", 0.7,
                 outside=["rig_artefact"])]
    a, b = figures(before), figures(after)
    assert a["confidently wrong"].startswith("1 ") and b["confidently wrong"].startswith("0 ")
    assert (a["right on none and singles"], b["right on none and singles"]) == ("1/2", "2/2")
    assert (a["outside not named as one of the six"],
            b["outside not named as one of the six"]) == ("0/1", "1/1")
    assert float(a["mean log loss of the truth (nats)"]) == pytest.approx(
        -(np.log(0.95) + np.log(0.6) + np.log(0.05)) / 3, abs=5e-4)
    assert float(b["mean log loss of the truth (nats)"]) == pytest.approx(
        -(np.log(0.95) + np.log(0.92) + np.log(0.7)) / 3, abs=5e-4)
    assert [r["campaign"] for r, _ in changed(before, after)] == ["s1/c001", "s1/c002"]
    assert "| s1/c002 | none + outside: rig_artefact | none 0.93 (wrong) | " \
           "outside_candidates 0.70 (right) |" in markdown(before, after)
