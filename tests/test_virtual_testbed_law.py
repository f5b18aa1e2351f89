"""Placeholder performance law: magnitudes of a BB2-like wheel on sand, and the slip roots."""

from __future__ import annotations

import numpy as np
import pytest

from virtual_testbed.law import PerformanceLaw, PlaceholderLaw, self_propelled_slip, towed_slip

LAW = PlaceholderLaw()


def test_is_a_performance_law():
    law: PerformanceLaw = LAW
    out = law.evaluate(np.array([70.0, 180.0]), np.array([0.1, 0.5]), 0, 9.80665)
    assert set(out) == {"dp_n", "torque_nm", "thrust_n", "resistance_n", "sinkage_m"}
    assert all(v.shape == (2,) for v in out.values())
    np.testing.assert_allclose(out["thrust_n"] - out["resistance_n"], out["dp_n"])
    np.testing.assert_allclose(out["torque_nm"], out["thrust_n"] * 0.125)
    assert law.parameters()["name"] == "PlaceholderLaw"


def test_magnitudes_at_180_n_undisturbed():
    out = LAW.evaluate(180.0, np.array([0.0, 0.2, 0.9]), 0)
    assert out["resistance_n"][0] == pytest.approx(18.0, abs=2.0)
    assert out["dp_n"][2] / 180.0 == pytest.approx(0.47, abs=0.05)
    assert 0.010 <= out["sinkage_m"][0] < out["sinkage_m"][1] < out["sinkage_m"][2] <= 0.025


def test_sinkage_grows_with_load_and_compacted_soil_sinks_and_resists_less():
    loads = np.array([70.0, 180.0, 300.0])
    mp0, mp1 = LAW.evaluate(loads, 0.3, 0), LAW.evaluate(loads, 0.3, 1)
    assert np.all(np.diff(mp0["sinkage_m"]) > 0)
    assert np.all(mp1["sinkage_m"] < mp0["sinkage_m"])
    assert np.all(mp1["resistance_n"] < mp0["resistance_n"])
    assert np.all(mp1["dp_n"] > mp0["dp_n"])


def test_dp_rises_monotonically_with_slip():
    slips = np.linspace(-0.3, 0.95, 200)
    assert np.all(np.diff(LAW.evaluate(180.0, slips, 0)["dp_n"]) > 0)


def test_slip_roots():
    s_sp = self_propelled_slip(LAW, 180.0, 0)
    s_tow = towed_slip(LAW, 180.0, 0)
    assert s_sp == pytest.approx(0.0473, abs=1e-3)
    assert s_tow == pytest.approx(LAW.towed_skid, abs=1e-8)
    assert float(LAW.evaluate(180.0, s_sp, 0)["dp_n"]) == pytest.approx(0.0, abs=1e-8)
    assert float(LAW.evaluate(180.0, s_tow, 0)["dp_n"]) == pytest.approx(-18.54, abs=0.01)
