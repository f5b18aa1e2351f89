"""Base rigid-wheel model against published closed forms and known truths.

Published relations reproduced (Bekker 1969, "Introduction to terrain-vehicle
systems"; Wong, Theory of Ground Vehicles 4th ed. 2008, ch. 2, rigid wheel):
  sinkage      z0 = [3W / ((3 - n)(kc/b + kphi) b sqrt(D))]^(2/(2n+1))
  compaction   Rc = (3W)^((2n+2)/(2n+1)) / [(3 - n)^((2n+2)/(2n+1)) (n + 1)
                     b^(1/(2n+1)) (kc/b + kphi)^(1/(2n+1)) D^((n+1)/(2n+1))]
Both assume the peak normal stress at the bottom of the wheel and small angles,
so the model is run with theta_m = 0 (c1 = c2 = 0) for the comparison.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest
from scipy.special import gamma

from terramechanics import LETE_SAND, LUNAR_NOMINAL, SOILS, WONG_DRY_SAND, Wheel, WheelModel

WHEEL = Wheel(radius_m=0.25, width_m=0.15)
LOADS_N = np.array([100.0, 300.0, 1000.0])  # sinkage/radius below 0.25 for every set


def bekker_sinkage_m(load_n, soil, wheel):
    k = soil.kc / wheel.width_m + soil.kphi
    return (3 * load_n / ((3 - soil.n) * k * wheel.width_m * np.sqrt(2 * wheel.radius_m))) ** (
        2 / (2 * soil.n + 1))


def bekker_compaction_n(load_n, soil, wheel):
    n, b, d = soil.n, wheel.width_m, 2 * wheel.radius_m
    k, e = soil.kc / b + soil.kphi, (2 * n + 2) / (2 * n + 1)
    return (3 * load_n) ** e / ((3 - n) ** e * (n + 1) * b ** (1 / (2 * n + 1))
                                * k ** (1 / (2 * n + 1)) * d ** ((n + 1) / (2 * n + 1)))


@pytest.mark.parametrize("soil", [WONG_DRY_SAND, LETE_SAND, LUNAR_NOMINAL], ids=lambda s: s.name)
def test_zero_slip_sinkage_matches_bekker_closed_form(soil):
    bottom_peak = WheelModel(WHEEL, replace(soil, c1=0.0, c2=0.0))
    z = bottom_peak.curves(LOADS_N, 0.0)["sinkage_m"]
    np.testing.assert_allclose(z, bekker_sinkage_m(LOADS_N, soil, WHEEL), rtol=0.04)
    # the 4 % is Bekker's (3 - n)/3 for int_0^1 (1 - u^2)^n du; with the exact integral:
    exact_factor = np.sqrt(np.pi) * gamma(soil.n + 1) / (2 * gamma(soil.n + 1.5))
    z_exact = bekker_sinkage_m(LOADS_N, soil, WHEEL) * ((3 - soil.n) / 3 / exact_factor) ** (
        2 / (2 * soil.n + 1))
    np.testing.assert_allclose(z[:2], z_exact[:2], rtol=0.015)


@pytest.mark.parametrize("soil", [WONG_DRY_SAND, LETE_SAND, LUNAR_NOMINAL], ids=lambda s: s.name)
def test_wong_reece_distribution_sinks_somewhat_more_than_bekker(soil):
    z = WheelModel(WHEEL, soil).curves(LOADS_N, 0.0)["sinkage_m"]
    ratio = z / bekker_sinkage_m(LOADS_N, soil, WHEEL)
    assert np.all((ratio > 1.1) & (ratio < 1.35))  # theta_m = 0.43 theta_1 lowers the peak


@pytest.mark.parametrize("soil", [WONG_DRY_SAND, LETE_SAND, LUNAR_NOMINAL], ids=lambda s: s.name)
def test_frictionless_towed_resistance_matches_bekker_compaction(soil):
    no_shear = replace(soil, c1=0.0, c2=0.0, cohesion_pa=0.0, friction_angle_deg=0.0)
    out = WheelModel(WHEEL, no_shear).curves(LOADS_N, 0.0)
    assert np.all(out["torque_nm"] == 0)
    np.testing.assert_allclose(out["resistance_n"], bekker_compaction_n(LOADS_N, soil, WHEEL),
                               rtol=0.08)
    np.testing.assert_allclose(out["resistance_n"], out["compaction_resistance_n"])


def test_vertical_equilibrium_everywhere():
    slips = np.linspace(-0.9, 1.0, 39)
    for soil in SOILS.values():
        out = WheelModel(WHEEL, soil).curves(np.array([50.0, 500.0, 1500.0])[:, None], slips)
        assert out["converged"].all()
        assert np.max(np.abs(out["load_n"] - out["fz_n"]) / out["load_n"]) < 1e-3
        np.testing.assert_allclose(out["fz_residual_n"], out["load_n"] - out["fz_n"], atol=1e-9)


def test_a_wheel_sunk_to_the_hub_is_flagged():
    out = WheelModel(WHEEL, LUNAR_NOMINAL).curves(3000.0, np.array([0.5, 1.0]))
    assert out["converged"].tolist() == [True, False]
    assert out["sinkage_m"][1] == pytest.approx(WHEEL.radius_m)
    assert out["fz_residual_n"][1] > 0.01 * 3000.0


def test_broadcast_equals_pointwise():
    model = WheelModel(WHEEL, LETE_SAND)
    loads, slips = np.array([80.0, 400.0]), np.array([-0.4, 0.0, 0.3, 0.8])
    grid = model.curves(loads[:, None], slips[None, :])
    assert grid["dp_n"].shape == (2, 4)
    for i, w in enumerate(loads):
        for j, s in enumerate(slips):
            one = model.curves(w, s)
            for key in ("dp_n", "torque_nm", "sinkage_m", "theta1_rad"):
                assert one[key] == pytest.approx(grid[key][i, j], rel=1e-9)


def test_driven_branch_is_continuous_up_to_zero_slip():
    model = WheelModel(WHEEL, WONG_DRY_SAND)
    around = model.curves(300.0, np.array([0.0, 1e-6, 2e-6]))
    assert np.ptp(around["dp_n"]) < 1e-3 * abs(around["dp_n"][0]) + 1e-6


def test_curve_shapes_and_definitions():
    model = WheelModel(WHEEL, LETE_SAND)
    slips = np.linspace(-0.8, 0.9, 35)
    out = model.curves(500.0, slips)
    assert np.all(np.diff(out["dp_n"]) > 0) and np.all(np.diff(out["torque_nm"]) > 0)
    assert out["dp_n"][0] < 0 < out["dp_n"][-1] < 500.0 * np.tan(np.radians(31.1)) + 1.0
    np.testing.assert_allclose(out["resistance_n"], out["torque_nm"] / 0.25 - out["dp_n"])
    driven = slips >= 0
    np.testing.assert_allclose(out["thetam_rad"][driven],
                               (0.43 + 0.32 * slips[driven]) * out["theta1_rad"][driven])
    np.testing.assert_allclose(out["theta1_rad"], np.arccos(1 - out["sinkage_m"] / 0.25))
    # a towed rigid wheel (zero torque) skids (Wong & Reece 1967, part 2)
    towed_slip = np.interp(0.0, out["torque_nm"], slips)
    assert -0.5 < towed_slip < 0.0


def test_exit_angle_from_c3():
    out = WheelModel(WHEEL, replace(LETE_SAND, c3=0.3)).curves(300.0, 0.2)
    assert out["theta2_rad"] == pytest.approx(-0.3 * out["theta1_rad"])


def test_bad_inputs_are_refused():
    with pytest.raises(ValueError):
        WheelModel(WHEEL, LETE_SAND).curves(0.0, 0.1)
    with pytest.raises(ValueError):
        Wheel(radius_m=-1.0, width_m=0.1)
    with pytest.raises(ValueError):
        replace(LETE_SAND, friction_angle_deg=95.0)


def test_literature_sets_carry_sources():
    assert {"wong_dry_sand", "lete_sand", "lunar_nominal"} <= set(SOILS)
    assert all(s.source for s in SOILS.values())
    assert (LETE_SAND.n, LETE_SAND.kc, LETE_SAND.kphi) == (0.79, 102e3, 5301e3)
