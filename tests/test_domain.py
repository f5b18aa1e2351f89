"""swtlab_base.domain: one definition of each domain thing, validated on construction."""

from __future__ import annotations

import math
from pathlib import Path

import pandas as pd
import pytest

import ingest
import terramechanics as tm
import virtual_testbed as vt
from swtlab_base.domain import (COLUMNS, G0_MPS2, MARS_GRAVITY_MPS2, MOON_GRAVITY_MPS2, Soil,
                           TestCondition, Wheel, check_results, wheel_columns, wheels_of)

SAMPLE = Path(__file__).resolve().parents[1] / "sample_data" / "campaign"


def test_one_wheel_and_one_g0_everywhere():
    assert tm.Wheel is Wheel and vt.Wheel is Wheel
    run = ingest.read_run(SAMPLE / "L180_MP0_SC_s+020.mcap")
    assert run.metadata.wheel == Wheel(0.125, 0.112, 12, 0.0092, 30.0, name="BB2-like")
    assert G0_MPS2 == 9.80665                      # exact by definition (CGPM 1901)
    assert tm.EARTH_GRAVITY_MPS2 == G0_MPS2
    assert tm.shipped_model("bb2_sand").gravity_mps2 == G0_MPS2
    # Moon and Mars against g0: 0.165 g and 0.378 g (NASA fact sheets)
    assert MOON_GRAVITY_MPS2 / G0_MPS2 == pytest.approx(0.165, abs=0.001)
    assert MARS_GRAVITY_MPS2 / G0_MPS2 == pytest.approx(0.378, abs=0.001)


@pytest.mark.parametrize("fields, message", [
    ({"radius_m": 0.0}, "radius_m 0 must be > 0"),
    ({"width_m": math.nan}, "width_m nan must be a finite number"),
    ({"grouser_count": 2.5}, "grouser_count 2.5 must be an integer >= 0"),
    ({"grouser_height_m": -0.001}, "grouser_height_m -0.001 must be >= 0"),
    ({"stiffness_n_per_mm": 0.0}, "stiffness_n_per_mm 0 must be > 0"),
])
def test_a_bad_wheel_is_refused_with_one_line(fields, message):
    with pytest.raises(ValueError, match=message):
        Wheel(**{"radius_m": 0.125, "width_m": 0.112, **fields})


def test_wheels_agree_within_the_tolerances():
    bb2 = Wheel(0.125, 0.112, 12, 0.0092, name="bb2")
    assert bb2.mismatches(Wheel(0.1245, 0.113, 12, 0.0095)) == []   # 0.4 %, 0.9 %, 0.3 mm
    assert bb2.mismatches(Wheel(0.130, 0.112, 10, 0.0092)) == [
        "radius_m 0.125 vs 0.13 (tolerance 2 %)", "grouser_count 12 vs 10"]


def test_test_condition_and_soil_are_validated():
    c = TestCondition("speed_control", 180.0, 1, 0.0111, slip_setpoint=0.2)
    assert c.gravity_mps2 == G0_MPS2
    with pytest.raises(ValueError, match="mode 'driving'"):
        TestCondition("driving", 180.0, 0, 0.01)
    with pytest.raises(ValueError, match="load_set_n -1 must be > 0"):
        TestCondition("towed", -1, 0, 0.01)
    with pytest.raises(ValueError, match="soil name"):
        Soil(" ")


def _row(**changes) -> dict:
    wheel = Wheel(0.125, 0.112, 12, 0.0092, 30.0, name="bb2")
    row = {c: None for c in COLUMNS}
    row.update(campaign="c", run_id="r1", **wheel_columns(wheel), soil="sand",
               mode="speed_control", multipass=0, load_set_n=180.0, velocity_set_mps=0.01,
               gravity_mps2=G0_MPS2, status="ok", flags="", dp_n_mean=40.0, dp_n_se=0.1)
    row.update(changes)
    return row


def test_the_results_schema_is_checked():
    good = pd.DataFrame([_row(), _row(run_id="r2")])
    assert check_results(good) is good
    assert wheels_of(good)["bb2"].stiffness_n_per_mm == 30.0
    with pytest.raises(ValueError, match=r"lacks column\(s\) \['gravity_mps2'\]"):
        check_results(good.drop(columns="gravity_mps2"))
    with pytest.raises(ValueError, match="status .*'done'.* load_set_n must be > 0"):
        check_results(pd.DataFrame([_row(status="done", load_set_n=0.0)]))
    with pytest.raises(ValueError, match="dp_n_se has a negative"):
        check_results(pd.DataFrame([_row(dp_n_se=-1.0)]))
    with pytest.raises(ValueError, match="wheel 'bb2' has two geometries"):
        wheels_of(pd.DataFrame([_row(), _row(run_id="r2", wheel_radius_m=0.1)]))
