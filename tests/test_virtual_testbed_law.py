"""The testbed's truth law is the terramechanics model: BB2-like magnitudes and the slip roots."""

from __future__ import annotations

import numpy as np
import pytest

from virtual_testbed.law import PerformanceLaw, bb2_sand_law, self_propelled_slip, towed_slip
from virtual_testbed.rig import BB2_WHEEL

LAW = bb2_sand_law()


def test_is_a_performance_law():
    law: PerformanceLaw = LAW
    out = law.evaluate(np.array([70.0, 180.0]), np.array([0.1, 0.5]), 0, 9.80665)
    assert set(out) == {"dp_n", "torque_nm", "thrust_n", "resistance_n", "sinkage_m"}
    assert all(v.shape == (2,) for v in out.values())
    np.testing.assert_allclose(out["thrust_n"] - out["resistance_n"], out["dp_n"])
    np.testing.assert_allclose(out["torque_nm"], out["thrust_n"] * 0.125)
    assert law.parameters()["name"] == "terramechanics.WheelModel"


def test_rig_wheel_matches_the_model_wheel():
    model = LAW.model
    assert model.wheel.radius_m == BB2_WHEEL.radius_m
    assert model.wheel.width_m == BB2_WHEEL.width_m
    assert model.wheel.grouser_count == BB2_WHEEL.grouser_count
    assert model.wheel.grouser_height_m == BB2_WHEEL.grouser_height_m
    flex = model.effects["wheel_flexibility"]
    assert flex.radial_stiffness_n_m == pytest.approx(1000.0 * BB2_WHEEL.stiffness_n_per_mm)


def test_magnitudes_at_180_n_undisturbed():
    """BB2 at 180 N: resistance about 18 N near zero slip, maximum DP about 0.4-0.5 W."""
    out = LAW.evaluate(180.0, np.array([0.0, 0.2, 0.6]), 0)
    assert out["resistance_n"][0] == pytest.approx(18.0, abs=1.0)
    dp_max = LAW.evaluate(180.0, np.linspace(0.0, 0.95, 96), 0)["dp_n"].max()
    assert 0.38 <= dp_max / 180.0 <= 0.5
    assert 0.0 < out["sinkage_m"][0] < out["sinkage_m"][1] < out["sinkage_m"][2] < 0.03


def test_sinkage_grows_with_load_and_compacted_soil_sinks_and_resists_less():
    loads = np.array([70.0, 180.0, 300.0])
    mp0, mp1 = LAW.evaluate(loads, 0.3, 0), LAW.evaluate(loads, 0.3, 1)
    assert np.all(np.diff(mp0["sinkage_m"]) > 0)
    assert np.all(mp1["sinkage_m"] < mp0["sinkage_m"])
    assert np.all(mp1["resistance_n"] < mp0["resistance_n"])


def test_dp_rises_with_slip_up_to_its_peak():
    """On each branch: braked/towed (Wong & Reece 1967 part II) and driven (part I); the two
    parts' peak-stress laws differ at s = 0 (part II puts it at the transition angle, which
    tends to the bottom), a step of under 3 % W."""
    braked, driven = np.linspace(-0.3, -1e-4, 100), np.linspace(0.0, 0.6, 100)
    dp_braked = LAW.evaluate(180.0, braked, 0)["dp_n"]
    dp_driven = LAW.evaluate(180.0, driven, 0)["dp_n"]
    assert np.all(np.diff(dp_braked) > 0) and np.all(np.diff(dp_driven) > 0)
    assert abs(dp_driven[0] - dp_braked[-1]) < 0.03 * 180.0


def test_slip_roots():
    s_sp = self_propelled_slip(LAW, 180.0, 0)
    s_tow = towed_slip(LAW, 180.0, 0)
    assert 0.0 < s_sp < 0.1
    assert -0.1 < s_tow < 0.0
    assert float(LAW.evaluate(180.0, s_sp, 0)["dp_n"]) == pytest.approx(0.0, abs=1e-6)
    towed = LAW.evaluate(180.0, s_tow, 0)
    assert float(towed["torque_nm"]) == pytest.approx(0.0, abs=1e-7)
    assert float(towed["dp_n"]) == pytest.approx(-float(towed["resistance_n"]), abs=1e-6)
