"""Braked and towed rigid wheels (skid s = (r w - v)/v < 0) against Wong & Reece (1967),
J. Terramech. 4(2), part II, computed here by hand from the paper's equations, and against
the CMU 3d-terramechanics smooth-wheel skid runs (real data).

Part II, with r w / v = 1 + s:
  transition   tan(45 deg - phi/2) = (cos t_t - r w/v) / sin t_t, peak normal stress at t_t
  front zone   j = (v/w)[(t1 - t)(sin t1 - sin t_t)/(t1 - t_t) - (sin t1 - sin t)]
  rear zone    j = r (t_t - t) - (v/w)(sin t_t - sin t)
  normal       sigma = (kc/b + kphi) (r (cos t - cos t1))^n in front of t_t, the rear mapped
               linearly onto the front (part I)
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from scipy.integrate import quad
from scipy.optimize import brentq

from terramechanics import (SOILS, WONG_DRY_SAND, SoilParams, Wheel, WheelModel, load_model,
                            save_model)
from terramechanics.model_file import ModelFileError

WHEEL = Wheel(radius_m=0.25, width_m=0.15)
CMU_RUNS = Path(__file__).resolve().parents[2] / "shared/data/cmu-3d-terramechanics/smooth_runs.csv"
#: the CMU authors' own smooth-wheel soil (3d-terramechanics terramechanics/set_soil_params.m,
#: 'K10_mini_smooth'): sigma = k z^n0 with k = 8e3 kN/m^(n+2), n0 = 1.4, c = 1.0 kPa,
#: phi = 29 deg, K = 0.01 m, density 1330 kg/m^3 (their skid exponent n2 is not used here)
CMU_AUTHORS_SOIL = SoilParams(kc=0.0, kphi=8e6, n=1.4, cohesion_pa=1.0e3,
                              friction_angle_deg=29.0, shear_modulus_m=0.01,
                              density_kg_m3=1330.0, name="cmu_authors_smooth")
CMU_WHEEL = Wheel(radius_m=0.058, width_m=0.05)


def hand_forces(soil, wheel, sinkage_m, skid):
    """Fz, DP, T (N, N, N m) of a braked wheel at a given sinkage, by quadrature of part II."""
    r, b, n = wheel.radius_m, wheel.width_m, soil.n
    phi, c, k_shear = np.radians(soil.friction_angle_deg), soil.cohesion_pa, soil.shear_modulus_m
    rolling = 1.0 + skid  # r w / v
    t1 = np.arccos(1 - sinkage_m / r)
    tt = brentq(lambda t: np.tan(np.pi / 4 - phi / 2) - (np.cos(t) - rolling) / np.sin(t),
                1e-9, np.pi / 2)
    tt = min(tt, t1)

    def sigma(t):
        t_eq = t if t >= tt else t1 - t / tt * (t1 - tt)
        return (soil.kc / b + soil.kphi) * (r * (np.cos(t_eq) - np.cos(t1))) ** n

    def tau(t):
        if t >= tt:  # flow zone: soil moves with the rim, shear drives
            bracket = (t1 - t) * (np.sin(t1) - np.sin(tt)) / (t1 - tt) - (np.sin(t1) - np.sin(t))
        else:  # rim slides forward over the soil, shear brakes
            bracket = rolling * (tt - t) - (np.sin(tt) - np.sin(t))
        mobilised = 1.0 if rolling == 0 else 1 - np.exp(-abs(r * bracket / rolling) / k_shear)
        return np.sign(bracket) * (c + sigma(t) * np.tan(phi)) * mobilised

    def integral(f):
        return sum(quad(f, lo, hi, epsabs=1e-10, epsrel=1e-10)[0]
                   for lo, hi in ((0.0, tt), (tt, t1)) if hi > lo)

    fz = b * r * integral(lambda t: sigma(t) * np.cos(t) + tau(t) * np.sin(t))
    dp = b * r * integral(lambda t: tau(t) * np.cos(t) - sigma(t) * np.sin(t))
    torque = b * r * r * integral(tau)
    return fz, dp, torque


@pytest.mark.parametrize("sinkage_m, skid", [(0.04, -0.3), (0.06, -0.05), (0.15, -1.0)],
                         ids=["skid 0.3", "towed-like 0.05", "locked"])
def test_braked_wheel_matches_hand_calculation_of_part_two(sinkage_m, skid):
    fz, dp, torque = hand_forces(WONG_DRY_SAND, WHEEL, sinkage_m, skid)
    out = WheelModel(WHEEL, WONG_DRY_SAND).curves(fz, skid)
    assert out["converged"]
    assert out["sinkage_m"] == pytest.approx(sinkage_m, rel=1e-4)
    assert out["dp_n"] == pytest.approx(dp, rel=1e-3, abs=1e-3 * fz)
    assert out["torque_nm"] == pytest.approx(torque, rel=1e-3, abs=1e-5 * fz)


def test_transition_angle_limits_of_part_two():
    """t_t -> 0 for a free-rolling wheel, 45 deg + phi/2 for a locked one (then beyond the
    entry at shallow sinkage: the whole arc brakes)."""
    model = WheelModel(WHEEL, WONG_DRY_SAND)
    deep = model.curves(3000.0, np.array([-1.0, -1e-4]))
    assert deep["theta1_rad"][0] > np.radians(45 + 14)
    assert deep["thetam_rad"][0] == pytest.approx(np.radians(45 + 14), rel=1e-9)
    assert deep["thetam_rad"][1] < 0.02 * deep["theta1_rad"][1]


def test_locked_wheel_converges_on_every_literature_soil():
    for soil in SOILS.values():
        out = WheelModel(WHEEL, soil).curves(np.array([100.0, 500.0]), -1.0)
        assert out["converged"].all() and np.isfinite(out["dp_n"]).all()
        assert np.all(out["sinkage_m"] < WHEEL.radius_m)


def test_skid_drawbar_pull_falls_with_skid_and_a_locked_wheel_digs_in():
    """DP falls steadily with skid; a locked wheel sinks deep and pushes a bow wave: its
    resistance exceeds the load (the CMU locked wheel measures DP/W = -2)."""
    out = WheelModel(WHEEL, WONG_DRY_SAND).curves(300.0, np.linspace(-0.9, -0.01, 30))
    assert np.all(np.diff(out["dp_n"]) > 0) and np.all(np.diff(out["sinkage_m"]) < 0)
    locked = WheelModel(WHEEL, WONG_DRY_SAND).curves(300.0, -1.0)
    assert locked["dp_n"] < -300.0 and locked["sinkage_m"] > 0.5 * WHEEL.radius_m


def cmu_straight_skid_runs() -> pd.DataFrame:
    runs = pd.read_csv(CMU_RUNS)
    return runs[(runs["slip_angle_deg"] == 0) & (runs["slip"] < -0.1)]


@pytest.mark.skipif(not CMU_RUNS.exists(), reason="CMU data not present")
def test_cmu_skid_runs_with_the_authors_soil():
    """The CMU smooth wheel braked at s = -0.2 ... -1 (12 runs), predicted with the
    authors' own soil (not fitted here): DP RMSE 3.3 N (the part-I skid model gave 8.4 N,
    and -24.7/-21.8 N at s = -0.7/-1 where the runs measure -24.1/-38.8 N)."""
    runs = cmu_straight_skid_runs()
    out = WheelModel(CMU_WHEEL, CMU_AUTHORS_SOIL).curves(runs["wheel_load_n"].to_numpy(),
                                                         runs["slip"].to_numpy())
    assert out["converged"].all()
    measured = runs["tractive_force_n"].to_numpy()
    assert np.sqrt(np.mean((out["dp_n"] - measured) ** 2)) < 4.0
    for skid in (-1.0, -0.7, -0.5, -0.2):
        band = np.abs(runs["slip"].to_numpy() - skid) < 0.01
        assert out["dp_n"][band].mean() == pytest.approx(measured[band].mean(), rel=0.25)
    # the locked wheel digs in: deeper than at s = -0.2 by about the measured hub drop
    hub_drop_m = (runs["hub_z_mm"][runs["slip"] > -0.3].mean()
                  - runs["hub_z_mm"][runs["slip"] < -0.99].mean()) / 1000
    lock, light = (np.abs(runs["slip"].to_numpy() - s) < 0.01 for s in (-1.0, -0.2))
    model_drop_m = out["sinkage_m"][lock].mean() - out["sinkage_m"][light].mean()
    assert model_drop_m == pytest.approx(hub_drop_m, rel=0.35)


@pytest.mark.parametrize("sinkage_m, skid", [(0.05, -0.3), (0.15, -1.0)])
def test_skid_sinkage_exponent_matches_hand_calculation(sinkage_m, skid):
    """The braked branch's own exponent slope (CMU model, 3d-terramechanics sigma.m:
    N = n0 - n2 (r w - v)/v when skidding): part II by hand with n = n0 + n2 |s|, while the
    driving slope n1 plays no part. In Reece's form of Ding et al. (2011), ``p = k b^n0
    (z/b)^N``: the pressure at z = b is kept (sigma.m writes ``k z^N``)."""
    n2, soil, b = 0.55, WONG_DRY_SAND, WHEEL.width_m
    n_skid = soil.n + n2 * abs(skid)
    k_reece = (soil.kc / b + soil.kphi) * b ** (soil.n - n_skid)
    hand_soil = SoilParams(**{**soil.__dict__, "kc": 0.0, "kphi": k_reece, "n": n_skid})
    fz, dp, torque = hand_forces(hand_soil, WHEEL, sinkage_m, skid)
    model = WheelModel(WHEEL, soil).with_effects(slip_sinkage={"n1": 0.9, "n2": n2})
    out = model.curves(fz, skid)
    assert out["converged"]
    assert out["sinkage_m"] == pytest.approx(sinkage_m, rel=1e-4)
    assert out["dp_n"] == pytest.approx(dp, rel=1e-3, abs=1e-3 * fz)
    assert out["torque_nm"] == pytest.approx(torque, rel=1e-3, abs=1e-5 * fz)


@pytest.mark.skipif(not CMU_RUNS.exists(), reason="CMU data not present")
def test_cmu_skid_runs_with_the_authors_skid_exponent():
    """The authors' soil with their exponent slopes (set_soil_params.m: n1 = 0.01,
    n2 = 0.55), nothing fitted: the skid runs' DP RMSE falls from 3.3 to 3.0 N and the
    relative sinkage of the skid runs from 2.9 to 2.4 mm RMS."""
    runs = cmu_straight_skid_runs()
    load, skid = runs["wheel_load_n"].to_numpy(), runs["slip"].to_numpy()
    plain = WheelModel(CMU_WHEEL, CMU_AUTHORS_SOIL)
    sloped = plain.with_effects(slip_sinkage={"n1": 0.01, "n2": 0.55})
    measured_dp, measured_z = runs["tractive_force_n"].to_numpy(), -runs["hub_z_mm"] / 1000

    def rms(model):
        out = model.curves(load, skid)
        dz = out["sinkage_m"] - measured_z.to_numpy()
        return (np.sqrt(np.mean((out["dp_n"] - measured_dp) ** 2)),
                np.sqrt(np.mean((dz - dz.mean()) ** 2)))

    (dp_plain, z_plain), (dp_sloped, z_sloped) = rms(plain), rms(sloped)
    assert dp_sloped < dp_plain < 4.0
    assert z_sloped < z_plain


def hand_forces_signed_slip(soil, wheel, sinkage_m, skid):
    """Fz, DP, T of the ``signed_slip`` braked law at a given sinkage, by quadrature of part
    I's equations at the kinematic slip i = 1 - v/(r w) = s/(1 + s): peak normal stress at
    (c1 + c2 i) t1 (kept within the contact), j = r[(t1 - t) - (1 - i)(sin t1 - sin t)]."""
    r, b, n = wheel.radius_m, wheel.width_m, soil.n
    phi, c, k_shear = np.radians(soil.friction_angle_deg), soil.cohesion_pa, soil.shear_modulus_m
    travel = 1.0 / (1.0 + skid)  # v / (r w) = 1 - i
    t1 = np.arccos(1 - sinkage_m / r)
    tm = float(np.clip((soil.c1 + soil.c2 * (1.0 - travel)) * t1, 0.0, t1))

    def sigma(t):
        t_eq = t if t >= tm else t1 - t / tm * (t1 - tm)
        return (soil.kc / b + soil.kphi) * (r * (np.cos(t_eq) - np.cos(t1))) ** n

    def tau(t):
        j = r * ((t1 - t) - travel * (np.sin(t1) - np.sin(t)))
        return np.sign(j) * (c + sigma(t) * np.tan(phi)) * (1 - np.exp(-abs(j) / k_shear))

    def integral(f):
        return sum(quad(f, lo, hi, epsabs=1e-10, epsrel=1e-10)[0]
                   for lo, hi in ((0.0, tm), (tm, t1)) if hi > lo)

    fz = b * r * integral(lambda t: sigma(t) * np.cos(t) + tau(t) * np.sin(t))
    dp = b * r * integral(lambda t: tau(t) * np.cos(t) - sigma(t) * np.sin(t))
    return fz, dp, b * r * r * integral(tau)


@pytest.mark.parametrize("sinkage_m, skid", [(0.03, -0.3), (0.04, -0.05), (0.03, -0.9)])
def test_signed_slip_law_matches_hand_calculation_of_part_one(sinkage_m, skid):
    fz, dp, torque = hand_forces_signed_slip(WONG_DRY_SAND, WHEEL, sinkage_m, skid)
    model = WheelModel(WHEEL, WONG_DRY_SAND, braked_law="signed_slip")
    out = model.curves(fz, skid)
    assert out["converged"]
    assert out["sinkage_m"] == pytest.approx(sinkage_m, rel=1e-4)
    assert out["dp_n"] == pytest.approx(dp, rel=1e-3, abs=1e-3 * fz)
    assert out["torque_nm"] == pytest.approx(torque, rel=1e-3, abs=1e-5 * fz)


def test_signed_slip_law_has_no_step_at_zero_where_part_two_has_one():
    """Issue 35 item 8: on every literature soil, DP, torque and sinkage just below s = 0 equal
    those at s = 0 under ``signed_slip``; part II's peak-stress angle jumps there."""
    for soil in SOILS.values():
        signed = WheelModel(WHEEL, soil, braked_law="signed_slip").curves(300.0, [-1e-9, 0.0])
        for name in ("dp_n", "torque_nm", "sinkage_m"):
            assert signed[name][0] == pytest.approx(signed[name][1], rel=1e-6, abs=1e-9)
    part2 = WheelModel(WHEEL, WONG_DRY_SAND).curves(300.0, [-1e-9, 0.0])
    assert abs(part2["sinkage_m"][0] - part2["sinkage_m"][1]) > 0.05 * part2["sinkage_m"][1]


def test_braked_law_is_validated_and_read_from_the_model_file(tmp_path):
    model = WheelModel(WHEEL, WONG_DRY_SAND, braked_law="signed_slip")
    save_model(model, tmp_path / "m.toml")
    assert load_model(tmp_path / "m.toml") == model
    (tmp_path / "bad.toml").write_text((tmp_path / "m.toml").read_text().replace(
        '"signed_slip"', '"part3"'))
    with pytest.raises(ModelFileError, match="braked_law 'part3'"):
        load_model(tmp_path / "bad.toml")
    with pytest.raises(ValueError, match="braked_law"):
        WheelModel(WHEEL, WONG_DRY_SAND, braked_law="part3")
