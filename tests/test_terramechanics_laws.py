"""The published laws of each effect: registry, hand calculations, published data.

Independent checks: hand calculations from each paper's formula (Bekker's grouser
side shear, Lyasko's slip-sinkage coefficient, Bekker's flexible-wheel flat contact,
Rankine's passive pressure), gravity similitude, and published measurements (Ding et al.
2011 smooth and lug wheels; Hurrell et al. 2025 Rashid-1 grousered wheel).
"""

from __future__ import annotations

import dataclasses
import re
import sys
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

import terramechanics as tm
from terramechanics import ding2011
from terramechanics.effects import DEFAULT_LAWS, LAWS, law_class, make_effect
from terramechanics.effects.load_varying import STRENGTH
from terramechanics.effects.grousers_bekker1956 import side_shear_factors
from terramechanics.model_file import ModelFileError, model_from_dict, model_to_dict

DATA = Path(tm.__file__).parent / "data"
BB2 = tm.shipped_model("bb2_sand").with_effects(**{n: False for n in tm.EFFECTS})


def test_registry_laws_declare_source_and_fit_parameters():
    assert all(len(laws) >= 2 for laws in tm.PUBLISHED_LAWS.values()) and len(LAWS) == 6
    for name, laws in tm.PUBLISHED_LAWS.items():
        assert tm.EFFECTS[name] is laws[DEFAULT_LAWS[name]]
        for law, cls in laws.items():
            assert cls.name == name and cls.law == law and cls.__doc__
            assert re.search(r"(19|20)\d\d$", law)  # named after its source
            doc = sys.modules[cls.__module__].__doc__
            assert re.search(r"\b(19|20)\d\d\b", doc) and cls.__module__.endswith(f"{name}_{law}")
            fields = {f.name: f.default for f in dataclasses.fields(cls)}
            assert cls.fit and all(p.name in fields and p.lower <= p.start <= p.upper
                                   and p.lower <= fields[p.name] <= p.upper for p in cls.fit)
            assert make_effect(name, law) == cls()
    with pytest.raises(KeyError, match="unknown law"):
        law_class("grousers", "magic1999")


@pytest.mark.parametrize("name, law", [(n, law) for (n, law) in STRENGTH])
def test_a_load_varying_law_is_its_published_law_at_each_load(name, law):
    """``law~load`` at load W: the published law with its strength times (W / 100 N)^a;
    at a = 0 the published law itself. Each load computed alone by the published law."""
    varying = LAWS[name][law + "~load"]
    published = LAWS[name][law]
    assert varying.relaxes == law and tm.published_law(name, varying.law) == law
    assert [p.name for p in varying.fit] == [p.name for p in published.fit] + ["load_exponent"]
    strength = STRENGTH[(name, law)]
    start = {p.name: p.start for p in published.fit}[strength]
    loads, slip = np.array([70.0, 100.0, 300.0]), 0.4
    both = BB2.with_effects(**{name: {"law": varying.law, strength: start,
                                      "load_exponent": -0.7}}).curves(loads, slip)
    flat = BB2.with_effects(**{name: {"law": varying.law, strength: start}}).curves(loads, slip)
    alone = BB2.with_effects(**{name: {"law": law, strength: start}}).curves(loads, slip)
    for q in ("dp_n", "torque_nm", "sinkage_m"):
        assert flat[q] == pytest.approx(alone[q], rel=1e-12)
    for i, load in enumerate(loads):
        scaled = BB2.with_effects(**{name: {"law": law, strength: start * (load / 100.0) ** -0.7}})
        one = scaled.curves(load, slip)
        for q in ("dp_n", "torque_nm", "sinkage_m"):
            assert both[q][i] == pytest.approx(float(one[q]), rel=1e-9)
    assert abs(both["sinkage_m"][2] / alone["sinkage_m"][2] - 1) > 1e-3  # the exponent acts


@pytest.mark.parametrize("name, law", [(n, law) for n, laws in LAWS.items() for law in laws])
def test_every_law_stays_in_vertical_equilibrium(name, law):
    model = tm.shipped_model("bb2_sand").with_effects(**{name: {"law": law}})
    out = model.curves(np.array([70.0, 300.0])[:, None], np.linspace(-0.5, 0.9, 15),
                       multipass=1, gravity_mps2=3.71)
    assert out["converged"].all()


def test_model_file_picks_the_law_and_old_files_get_the_default():
    tables = {"wheel": {"radius_m": 0.1, "width_m": 0.08}, "soil": {"preset": "lete_sand"},
              "effects": {"grousers": {"law": "ding2011", "lug_sinkage_gain": 2.0},
                          "slip_sinkage": {"n1": 0.2}}}
    model = model_from_dict(tables)
    assert model.effects["grousers"].law == "ding2011"
    assert model.effects["grousers"].lug_sinkage_gain == 2.0
    assert model.effects["slip_sinkage"].law == DEFAULT_LAWS["slip_sinkage"]
    assert model_from_dict(model_to_dict(model)) == model
    with pytest.raises(ModelFileError, match=r"\[effects.grousers\].*unknown law"):
        model_from_dict({**tables, "effects": {"grousers": {"law": "nope"}}})
    switched = model.with_effects(grousers={"law": "bekker1956"})
    assert switched.effects["grousers"] == law_class("grousers", "bekker1956")()


def test_bekker_side_shear_factors_and_thrust():
    # Bekker: c (1 + 2h/b), tan(phi) (1 + 0.64 (h/b) arccot(h/b)); h = b: 3 and 1 + 0.16 pi
    assert side_shear_factors(0.1, 0.1) == pytest.approx((3.0, 1 + 0.64 * np.pi / 4), rel=1e-12)
    assert side_shear_factors(0.0, 0.1) == (1.0, 1.0)
    # fully mobilised shear (s = 0.9) at the rim radius (lambda = 0): the thrust of a purely
    # frictional and of a purely cohesive soil grows by the friction and the cohesion factor,
    # less the little the larger vertical shear component lifts the wheel (<= 2.5 %)
    wheel = tm.Wheel(0.125, 0.112, 12, 0.0092)
    h_b = 0.0092 / 0.112
    frictional = dataclasses.replace(tm.LETE_SAND, cohesion_pa=0.0)
    cohesive = dataclasses.replace(tm.LETE_SAND, friction_angle_deg=0.0, cohesion_pa=3e3)
    for soil, factor in ((frictional, 1 + 0.64 * h_b * np.arctan(1 / h_b)),
                         (cohesive, 1 + 2 * h_b)):
        plain = tm.WheelModel(wheel, soil)
        on = plain.with_effects(grousers={"shear_radius_factor": 0.0}).curves(180.0, 0.9)
        assert on["thrust_n"] / plain.curves(180.0, 0.9)["thrust_n"] == pytest.approx(
            factor, rel=0.025)


def test_grousers_without_double_counting_on_rashid1():
    """Hurrell et al. 2025, Rashid-1 (20 mm grousers) on cohesive FJS-1: the smooth-rim
    model underpredicts DP (RMSE 5.1 N); the passive-pressure law of before went to 12.4 N.
    Neither grouser law may overpredict like that: RMSE below the smooth-rim model's
    (4.7 N with Bekker's tip shear, 3.3 N with Ding's equivalent radius)."""
    points = pd.read_csv(DATA / "hurrell2025_rashid1.csv", comment="#")
    soil = tm.SoilParams(kc=1.37e3, kphi=820e3, n=1.0, cohesion_pa=2400.0,
                         friction_angle_deg=38.0, shear_modulus_m=0.018, density_kg_m3=1740.0)
    model = tm.WheelModel(tm.Wheel(0.1, 0.08, 14, 0.02), soil)

    def rmse(m):
        return float(np.sqrt(np.mean((m.curves(24.5, points["slip"])["dp_n"]
                                      - points["dp_n"]) ** 2)))

    smooth_rim = rmse(model)
    assert smooth_rim == pytest.approx(5.1, abs=0.1)
    for law in LAWS["grousers"]:
        assert rmse(model.with_effects(grousers={"law": law})) < smooth_rim


def test_ding_lugs_add_slip_sinkage_in_proportion_to_lug_height():
    lugged = BB2.with_effects(grousers={"law": "ding2011", "shear_radius_factor": 0.0,
                                        "lug_sinkage_gain": 5.0})
    # n1_lug = kappa h / r = 5 * 0.0092 / 0.125 = 0.368: the same as slip_sinkage n1 = 0.368
    as_slip_sinkage = BB2.with_effects(slip_sinkage={"n1": 5.0 * 0.0092 / 0.125})
    slips = np.linspace(0.0, 0.8, 5)
    np.testing.assert_allclose(lugged.curves(180.0, slips)["sinkage_m"],
                               as_slip_sinkage.curves(180.0, slips)["sinkage_m"], rtol=1e-9)
    smooth = lugged.with_wheel(grouser_height_m=0.0).curves(180.0, slips)
    np.testing.assert_allclose(smooth["sinkage_m"], BB2.curves(180.0, slips)["sinkage_m"])


def test_bekkers_lugs_with_lyaskos_slip_sinkage_by_hand():
    """``bekker1956~slip``: Bekker's grouser law on a soil softened by Lyasko's factor
    raised to g h/r, i.e. the same curves as Bekker's lugs with Lyasko's slip-sinkage of
    coefficient g h/r; g = 0 is Bekker's law; a smooth wheel is untouched."""
    law = "bekker1956~slip"
    assert LAWS["grousers"][law].relaxes == "bekker1956"
    assert tm.published_law("grousers", law) == "bekker1956"
    lugged = BB2.with_effects(grousers={"law": law, "shear_radius_factor": 0.4,
                                        "lug_slip_gain": 8.0})
    by_hand = BB2.with_effects(grousers={"law": "bekker1956", "shear_radius_factor": 0.4},
                               slip_sinkage={"law": "lyasko2010",
                                             "coefficient": 8.0 * 0.0092 / 0.125})
    loads, slips = np.array([[60.0], [250.0]]), np.linspace(-0.4, 0.8, 7)
    for q in ("sinkage_m", "dp_n", "torque_nm"):
        np.testing.assert_allclose(lugged.curves(loads, slips)[q], by_hand.curves(loads, slips)[q],
                                   rtol=1e-9, atol=1e-12)
    published = BB2.with_effects(grousers={"law": "bekker1956", "shear_radius_factor": 0.4})
    at_zero = lugged.with_effects(grousers={"lug_slip_gain": 0.0})
    np.testing.assert_array_equal(at_zero.curves(loads, slips)["dp_n"],
                                  published.curves(loads, slips)["dp_n"])
    smooth = lugged.with_wheel(grouser_height_m=0.0).curves(180.0, slips)
    np.testing.assert_array_equal(smooth["sinkage_m"], BB2.curves(180.0, slips)["sinkage_m"])
    assert np.all(np.diff(lugged.curves(180.0, slips[slips >= 0])["sinkage_m"]) > 0)


def test_lyasko_slip_sinkage_coefficient():
    # (1 + i)/(1 - 0.5 i): 1, 4/3, 7/4, 16/7 at i = 0, 0.2, 0.4, 0.6; the Wong-Reece sinkage
    # follows Bekker's closed-form scaling within 4 %
    model = tm.WheelModel(tm.Wheel(0.125, 0.112), tm.LETE_SAND)
    slips = np.array([0.0, 0.2, 0.4, 0.6])
    ratio = (model.with_effects(slip_sinkage={"law": "lyasko2010"}).curves(180.0, slips)
             ["sinkage_m"] / model.curves(180.0, slips)["sinkage_m"])
    np.testing.assert_allclose(ratio, [1.0, 4 / 3, 7 / 4, 16 / 7], rtol=0.04)
    assert ratio[0] == pytest.approx(1.0, rel=1e-9)


def test_bekker_flexible_wheel_flat_contact():
    # bb2 soil: kc = 0, kphi = 1.8e7, n = 1; W = 180 N, b = 0.112 m, D = 0.25 m
    z0 = (3 * 180 / ((3 - 1) * 0.112 * 1.8e7 * np.sqrt(0.25))) ** (2 / 3)  # 4.155 mm
    critical_pa = 1.8e7 * z0  # 74.8 kPa
    half_m = 180 / (0.112 * 20e3) / 2  # flat contact 80.4 mm long at 20 kPa
    delta_m = 0.125 - np.sqrt(0.125**2 - half_m**2)  # 6.63 mm
    soft = BB2.with_effects(wheel_flexibility={"law": "bekker1969", "ground_pressure_pa": 20e3})
    out = soft.curves(180.0, np.array([0.0, 0.3]))
    np.testing.assert_allclose(out["deflection_m"], delta_m, rtol=1e-12)
    assert np.all(out["sinkage_m"] < BB2.curves(180.0, np.array([0.0, 0.3]))["sinkage_m"])
    stiff = BB2.with_effects(wheel_flexibility={"law": "bekker1969",
                                                "ground_pressure_pa": 1.01 * critical_pa})
    assert np.all(stiff.curves(180.0, np.array([0.0, 0.3]))["deflection_m"] == 0.0)


def test_rankine_bulldozing_hand_calculation():
    model = tm.WheelModel(tm.Wheel(0.125, 0.112), tm.LETE_SAND)
    on = model.with_effects(bulldozing={"law": "rankine_terzaghi1943"}).curves(180.0, 0.3)
    z, phi = on["sinkage_m"], np.radians(31.1)
    n_phi = np.tan(np.radians(45) + phi / 2) ** 2
    # gamma = rho g0 (the soil parameters hold at standard gravity, 9.80665 m/s^2)
    hand = 0.112 * (0.5 * 1600 * 9.80665 * z**2 * n_phi + 2 * 1300 * z * np.sqrt(n_phi))
    assert on["bulldozing_n"] == pytest.approx(hand, rel=1e-12)
    assert model.curves(180.0, 0.3)["dp_n"] - on["dp_n"] == pytest.approx(hand, rel=1e-9)


def test_depth_varying_bulldozing_by_hand():
    """``rankine_terzaghi1943~depth``: Rankine's passive force times the coefficient and
    (z / 10 mm)^a at the solved sinkage (bulldozing leaves the sinkage alone); a = 0 is the
    published law; its coefficient may go to 20, the published law's to 5."""
    model = tm.WheelModel(tm.Wheel(0.125, 0.112), tm.LETE_SAND)
    law = "rankine_terzaghi1943"
    varying = LAWS["bulldozing"][law + "~depth"]
    assert varying.relaxes == law and tm.published_law("bulldozing", varying.law) == law
    assert {p.name: p.upper for p in varying.fit} == {"coefficient": 20.0,
                                                      "depth_exponent": 1.5}
    loads = np.array([60.0, 180.0, 300.0])
    on = model.with_effects(bulldozing={"law": varying.law, "coefficient": 8.0,
                                        "depth_exponent": -0.4}).curves(loads, 0.3)
    flat = model.with_effects(bulldozing={"law": varying.law, "coefficient": 3.0}).curves(
        loads, 0.3)
    published = model.with_effects(bulldozing={"law": law, "coefficient": 3.0}).curves(loads, 0.3)
    z, phi = on["sinkage_m"], np.radians(31.1)
    n_phi = np.tan(np.radians(45) + phi / 2) ** 2
    rankine = 0.112 * (0.5 * 1600 * 9.80665 * z**2 * n_phi + 2 * 1300 * z * np.sqrt(n_phi))
    assert on["bulldozing_n"] == pytest.approx(8.0 * (z / 0.01) ** -0.4 * rankine, rel=1e-12)
    assert on["sinkage_m"] == pytest.approx(model.curves(loads, 0.3)["sinkage_m"], rel=1e-12)
    assert flat["bulldozing_n"] == pytest.approx(published["bulldozing_n"], rel=1e-12)


def test_bekker_bulldozing_is_17_to_180_times_rankines_on_planetary_ruts():
    # the ratio the Rankine module's docstring quotes for its fit range
    from terramechanics.effects.bulldozing_bekker1969 import bulldozing_resistance_n
    from terramechanics.effects.bulldozing_rankine_terzaghi1943 import rankine_passive_n_m

    z, phi, c = np.meshgrid(np.linspace(0.003, 0.04, 8), np.radians(np.linspace(28, 38, 6)),
                            np.linspace(0.0, 800.0, 5))
    ratio = (bulldozing_resistance_n(z, 0.3, 0.12, c, phi, 15e3)
             / (0.12 * rankine_passive_n_m(z, c, phi, 15e3)))
    assert 16.5 < ratio.min() < 17.5 and 175 < ratio.max() < 185


def test_scm_multipass_reloads_elastically():
    # a rerun (i >= 1) meets sigma = K_e dz: the same as a soil kc = 0, kphi = K_e, n = 1
    k_e = 4e7
    model = BB2.with_effects(multipass={"law": "krenn_hirzinger2009",
                                        "elastic_stiffness_pa_m": k_e})
    slips = np.array([0.0, 0.3])
    rerun = model.curves(180.0, slips, multipass=np.array([[1], [3]]))
    linear = BB2.with_soil(kc=0.0, kphi=k_e, n=1.0).curves(180.0, slips)
    for row in rerun["sinkage_m"]:
        np.testing.assert_allclose(row, linear["sinkage_m"], rtol=1e-9)
    np.testing.assert_allclose(model.curves(180.0, slips)["dp_n"], BB2.curves(180.0, slips)["dp_n"])
    # BB2 (swtlab issue): resistance about 18 N virgin, about 15 N at multipass 2
    bb2 = tm.shipped_model("bb2_sand").with_effects(multipass={"law": "krenn_hirzinger2009"})
    passes = bb2.curves(180.0, 0.0, multipass=np.array([0, 2]))["resistance_n"]
    np.testing.assert_allclose(passes, [18.0, 15.0], atol=0.5)


@pytest.mark.parametrize("other", [{"reduced_gravity": {"law": "reece1965"}},
                                   {"reduced_gravity": {"law": "wong_kobayashi2012"}},
                                   {"slip_sinkage": {"law": "lyasko2010"}}])
def test_the_rerun_soil_is_what_gravity_and_slip_then_act_on(other):
    # a rerun rut reloads at K_e (Krenn & Hirzinger 2009); reduced gravity and Lyasko's slip
    # softening then scale that soil as they scale a virgin one (terramechanics.SOIL_ORDER):
    # the rerun equals a virgin soil kc = 0, kphi = K_e, n = 1 under the same other effect
    k_e = 4e7
    slips = np.array([0.1, 0.4])
    rerun = BB2.with_effects(multipass={"law": "krenn_hirzinger2009",
                                        "elastic_stiffness_pa_m": k_e}, **other)
    linear = BB2.with_soil(kc=0.0, kphi=k_e, n=1.0).with_effects(**other)
    for q in ("sinkage_m", "dp_n", "torque_nm"):
        np.testing.assert_allclose(
            rerun.curves(180.0, slips, multipass=1, gravity_mps2=3.71)[q],
            linear.curves(180.0, slips, gravity_mps2=3.71)[q], rtol=1e-9)


SLIPS = np.linspace(0.05, 0.7, 14)


def _gravity_runs(law: str, load_n: float):
    model = tm.WheelModel(ding2011.wheel(ding2011.load_points(), "smooth"), ding2011.SOIL)
    model = model.with_effects(reduced_gravity={"law": law})
    earth = model.curves(load_n, SLIPS, gravity_mps2=9.81)
    moon_load = model.curves(load_n, SLIPS, gravity_mps2=1.62)
    moon_mass = model.curves(load_n * 1.62 / 9.81, SLIPS, gravity_mps2=1.62)
    return earth, moon_load, moon_mass


def test_similitude_law_reproduces_the_flight_trends():
    earth, moon_load, moon_mass = _gravity_runs("wong_kobayashi2012", 80.0)
    # equal mass: sinkage and DP/W unchanged (Wong & Kobayashi 2012: little change);
    # exact here, all stresses scale with g
    np.testing.assert_allclose(moon_mass["sinkage_m"], earth["sinkage_m"], rtol=1e-5)
    np.testing.assert_allclose(moon_mass["dp_n"] / moon_mass["load_n"],
                               earth["dp_n"] / 80.0, rtol=1e-4, atol=1e-6)
    # equal load: deeper sinkage, less traction (Niksirat et al. 2020: about -20 % on
    # average; 10-40 % accepted, their wheel and GRC-1 soil are not Ding's), more slip
    # at the same DP/W (Kobayashi et al. 2010)
    assert np.all(moon_load["sinkage_m"] > 1.5 * earth["sinkage_m"])
    loss = 1 - moon_load["dp_n"].mean() / earth["dp_n"].mean()
    assert 0.10 <= loss <= 0.40
    slip_at = lambda c: np.interp(0.1, c["dp_n"] / 80.0, SLIPS)  # noqa: E731
    assert slip_at(moon_load) > slip_at(earth)


def test_similitude_law_on_the_bb2_example():
    """The shipped BB2 model with its effects (flexible lugged wheel): at equal load the
    lunar mean DP over s = 0.05-0.7 drops by about 20 % (Niksirat et al. 2020; the
    15-25 % band of 'about 20 %'), sinkage about 3 x; at equal mass the sinkage changes
    by under 20 % on average (Wong & Kobayashi 2012: little change; +16 %, up to +26 % at
    low slip: the wheel's deflection W/k does not scale with g)."""
    model = tm.shipped_model("bb2_sand").with_effects(reduced_gravity=True)
    earth = model.curves(180.0, SLIPS, gravity_mps2=9.81)
    moon_load = model.curves(180.0, SLIPS, gravity_mps2=1.62)
    moon_mass = model.curves(180.0 * 1.62 / 9.81, SLIPS, gravity_mps2=1.62)
    assert 0.15 <= 1 - moon_load["dp_n"].mean() / earth["dp_n"].mean() <= 0.25
    assert np.all(moon_load["sinkage_m"] > 2 * earth["sinkage_m"])
    assert np.mean(moon_mass["sinkage_m"] / earth["sinkage_m"]) == pytest.approx(1.0, abs=0.2)


def test_reece_law_is_what_the_flights_contradict():
    """Reece's kphi ~ g with c unscaled: better lunar DP/W at equal mass (the issue: +35 %
    peak on its example), the opposite of Wong & Kobayashi 2012."""
    earth, _, moon_mass = _gravity_runs("reece1965", 80.0)
    gain = (moon_mass["dp_n"] / moon_mass["load_n"]).max() / (earth["dp_n"] / 80.0).max() - 1
    assert gain > 0.2


def test_ding2011_accuracy_with_held_out_laws():
    """Ding et al. 2011 at 80 N, laws with no constant fitted to these curves (Lyasko's
    slip-sinkage, Bekker's grousers), soil of the paper with kc, kphi scaled by the one
    factor that matches the smooth wheel's zero-slip sinkage. Issue target: DP <= 15 %,
    sinkage <= 25 % (median |error|); the DP target is missed (28 %, 23 %): with a
    constant K the model's thrust builds up more slowly with slip than measured
    (bench/bench_ding2011.py; K = K0 + K1 s: tests/test_terramechanics_slip_soil.py)."""
    points = ding2011.load_points()
    published = tm.WheelModel(ding2011.wheel(points, "smooth"), ding2011.SOIL)
    plain = ding2011.errors(published, points, "smooth")
    assert plain["sinkage_median_rel"] > 0.4  # the Bekker-Wong baseline: 43 %
    factor = ding2011.static_stiffness_factor(published, points)
    assert 3 < factor < 5  # the paper's soil sinks 2.3 x deeper at rest than measured
    soil = published.soil
    model = published.with_soil(kc=soil.kc * factor, kphi=soil.kphi * factor).with_effects(
        slip_sinkage={"law": "lyasko2010"}, grousers={"law": "bekker1956"})
    for name in ding2011.WHEELS:
        err = ding2011.errors(model, points, name)
        assert err["sinkage_median_rel"] <= 0.25
        assert err["dp_median_rel"] <= 0.30
    lug_off = ding2011.errors(model.with_effects(grousers=False), points, "lug10")
    assert ding2011.errors(model, points, "lug10")["dp_median_rel"] < lug_off["dp_median_rel"]


def _hand_static_sinkage_m(c1: float) -> float:
    """Sinkage of the Ding et al. 2011 wheel (R = 157.35 mm, b = 165 mm) at 80 N and s = 0 on
    the paper's Table 2 soil, by adaptive quadrature of Wong & Reece (1967, J. Terramech.
    4(1)) part I: sigma = (kc/b + kphi) (r (cos t - cos t1))^n in front of
    theta_m = c1 theta_1, the same law at the mirrored angle behind it (theta_2 = 0),
    Janosi-Hanamoto shear with j = r [(t1 - t) - (sin t1 - sin t)] at s = 0, and
    W = b r int (sigma cos t + tau sin t) dt solved for theta_1."""
    from scipy.integrate import quad
    from scipy.optimize import brentq
    r, b, n = 0.15735, 0.165, 1.10
    k, c, tan_phi, shear_k = 15.6e3 / b + 2407.4e3, 250.0, np.tan(np.radians(31.9)), 0.011

    def load(t1):
        tm_ = c1 * t1

        def sigma(t):
            equiv = t if t >= tm_ else t1 - t / tm_ * (t1 - tm_)
            return k * (r * max(np.cos(equiv) - np.cos(t1), 0.0)) ** n

        def tau(t):
            j = r * ((t1 - t) - (np.sin(t1) - np.sin(t)))
            return (c + sigma(t) * tan_phi) * -np.expm1(-j / shear_k)

        return b * r * quad(lambda t: sigma(t) * np.cos(t) + tau(t) * np.sin(t), 0.0, t1,
                            points=[tm_] if tm_ > 0 else None, limit=200)[0]

    return 0.15735 * (1 - np.cos(brentq(lambda t: load(t) - 80.0, 1e-3, 1.2, xtol=1e-12)))


def test_ding2011_published_soil_static_sinkage_is_what_the_equations_give():
    """The plain model's 11.6 mm at rest on Ding's Table 2 soil (5.0 mm measured) is the
    Wong-Reece answer for that soil, not a coding error: an independent quadrature gives
    the same; with theta_m = 0 both give Bekker's closed form for a rigid wheel (Bekker
    1969, Introduction to Terrain-Vehicle Systems; Wong, Theory of Ground Vehicles 2008,
    ch. 2), z0 = [3W / ((3 - n)(kc + b kphi) sqrt(D))]^(2/(2n + 1)) = 9.13 mm (its
    small-angle approximations: within 2 %). The textbook theta_m = 0.4 theta_1 (c1 = 0.4,
    c2 = 0.2) sinks it 11.3 mm; no theta_m brings it near 5 mm."""
    points = ding2011.load_points()
    published = tm.WheelModel(ding2011.wheel(points, "smooth"), ding2011.SOIL)
    bekker = (3 * 80.0 / ((3 - 1.10) * (15.6e3 + 0.165 * 2407.4e3) * np.sqrt(2 * 0.15735))
              ) ** (2 / (2 * 1.10 + 1))
    assert bekker == pytest.approx(9.13e-3, abs=0.01e-3)
    for c1, c2 in ((0.43, 0.32), (0.4, 0.2), (0.0, 0.0)):
        z = float(published.with_soil(c1=c1, c2=c2).curves(80.0, 0.0)["sinkage_m"])
        assert z == pytest.approx(_hand_static_sinkage_m(c1), rel=1e-5)
        assert z > 1.75 * 5.0e-3  # measured 5.0 mm
    z0 = float(published.with_soil(c1=0.0, c2=0.0).curves(80.0, 0.0)["sinkage_m"])
    assert z0 == pytest.approx(bekker, rel=0.02)
