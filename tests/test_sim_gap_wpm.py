"""WPM CSV on either side: a simulator's curves with effects added as the built-in model's
correction; WPM and CMU measured-side readers."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd
import pytest

import terramechanics as tm
from sim_gap.diagnose import Settings, diagnose
from sim_gap.measured import from_cmu_smooth_runs, from_wpm_csv, load_measured
from sim_gap.simulated import load_simulated
from tests.test_sim_gap_decide import BASE, synthetic_points

CMU = Path(__file__).resolve().parents[2] / "shared/data/cmu-3d-terramechanics/smooth_runs.csv"
QUANTITIES = (("dp_n", "N"), ("torque_nm", "N*m"), ("sinkage_m", "m"), ("resistance_n", "N"))


def write_wpm(model: tm.WheelModel, path: Path, loads=(80.0, 180.0, 300.0), mps=(0, 1),
              rmse: float = 0.2, geometry: bool = True) -> Path:
    """A simulator's WPM CSV: degree-5 polynomials of the model's curves on slip 0-0.8, with
    the model's wheel in the ``wheel_geometry`` header (or, as older files, without it)."""
    slips = np.linspace(0.0, 0.8, 33)
    w = model.wheel
    lines = ["# format: swtlab-wpm/1", "# generator: test simulator"]
    if geometry:
        lines.append(f'# wheel_geometry: {{"bb2": {{"radius_m": {w.radius_m}, "width_m": '
                     f'{w.width_m}, "grouser_count": {w.grouser_count}, "grouser_height_m": '
                     f'{w.grouser_height_m}, "stiffness_n_per_mm": null}}}}')
    lines.append("soil,wheel,multipass,load_n,quantity,unit,degree,slip_min,slip_max,"
                 "a0,a1,a2,a3,a4,a5,a6,a7,n_points,rmse")
    for mp in mps:
        for load in loads:
            c = model.curves(load, slips, mp)
            for q, unit in QUANTITIES:
                a = np.polynomial.polynomial.polyfit(slips, c[q], 5)
                coef = ",".join(repr(float(v)) for v in a) + ",,"
                lines.append(f"sand,bb2,{mp},{load},{q},{unit},5,0.0,0.8,{coef},33,{rmse}")
    path.write_text("\n".join(lines) + "\n")
    return path


def test_wpm_simulation_adds_effects_as_model_corrections(tmp_path):
    sim_model = BASE.with_soil(kphi=2.5e7)           # the "simulator" is not the reference
    sim = load_simulated(write_wpm(sim_model, tmp_path / "sim.csv"))
    assert sim.wpm is not None and sim.missing_effects() == list(tm.EFFECTS)
    points = synthetic_points(BASE, loads=(180.0,), slips=(0.2, 0.5), multipass=(0,))
    plain = sim.predict(points, {})
    direct = sim_model.curves(points["wheel_load_n"], points["slip"], points["multipass"])
    np.testing.assert_allclose(plain["dp_n"], direct["dp_n"], atol=0.05)
    values = {"effects.bulldozing.coefficient": 1.0}
    with_effect = sim.predict(points, values)
    load, slip = points["wheel_load_n"], points["slip"]
    correction = (BASE.with_parameters(values).curves(load, slip)["dp_n"]
                  - BASE.curves(load, slip)["dp_n"])
    np.testing.assert_allclose(with_effect["dp_n"] - plain["dp_n"], correction, atol=1e-9)
    assert np.all(correction < -1.0)                 # bulldozing costs drawbar pull


def test_gap_against_a_wpm_simulation_finds_the_injected_effect(tmp_path):
    """On the smooth BB2 rim (on the lugged one slip-sinkage is aliased with the lugs').
    Slip-sinkage is found (probability >= 0.9 that it is part of the explanation, and it
    alone leads); 24 points cannot rule out a weak bulldozing beside it, which its prior
    falling from zero keeps possible (docs/gap-report.md), so the set itself need not reach
    a call."""
    smooth = BASE.with_wheel(grouser_count=0, grouser_height_m=0.0)
    sim = load_simulated(write_wpm(smooth, tmp_path / "sim.csv"))
    truth = smooth.with_soil(kphi=1.8e7 * 1.3).with_effects(slip_sinkage={"n1": 0.6})
    report = diagnose(synthetic_points(truth, slips=(0.1, 0.3, 0.5, 0.7)), sim,
                      ["slip_sinkage", "bulldozing"],
                      Settings(max_nfev=25, fold_nfev=8, n_boot=20))
    assert report["effect_sets"][0]["label"] == "slip_sinkage"
    assert report["effect_probabilities"]["slip_sinkage"] >= 0.9
    assert report["effect_probabilities"]["bulldozing"] < 0.5
    assert report["verdict"] in (["slip_sinkage"], "inconclusive")
    assert report["shrink"]["shrink_pct"]["sinkage_m"] > 50.0


def test_measured_from_wpm_csv_samples_curves_with_rmse_as_se(tmp_path):
    path = write_wpm(BASE, tmp_path / "meas.csv", loads=(80.0, 180.0), mps=(0,), rmse=0.3)
    points = load_measured(str(path))
    assert len(points) == 2 * 9 and points["dp_n_se"].eq(0.3).all()
    assert points["slip"].min() == 0.0 and points["slip"].max() == pytest.approx(0.8)
    ref = BASE.curves(points["wheel_load_n"], points["slip"])["dp_n"]
    np.testing.assert_allclose(points["dp_n"], ref, atol=0.1)
    assert from_wpm_csv(path, gravity_mps2=3.71)["gravity_mps2"].eq(3.71).all()


@pytest.mark.skipif(not CMU.exists(), reason="CMU data not present")
def test_cmu_smooth_runs_adapter():
    points = from_cmu_smooth_runs(CMU)
    assert len(points) == 27 and points.attrs["sinkage_relative"]
    assert set(points.columns) >= {"dp_n", "dp_n_se", "sinkage_m", "sinkage_m_se"}
    assert "torque_nm" not in points
    row = points[points["slip"].between(-0.20039, -0.20038)].iloc[0]
    assert row["dp_n"] == pytest.approx(-7.63951) and row["sinkage_m"] == pytest.approx(0.01457)
    # noise from the replicate runs, pooled by hand over the set wheel speed of each file
    # name (10_<speed>_0_<trial>.txt), not from the window standard deviations
    assert np.isnan(row["dp_n_se"])
    raw = pd.read_csv(CMU)
    raw = raw[raw["slip_angle_deg"] == 0]
    speed = raw["run_file"].str.extract(r"/10_(\d+)_0_\d\.txt$")[0]
    groups = raw.groupby(speed)["tractive_force_n"]
    dof = groups.count() - 1
    pooled = np.sqrt((dof * groups.var()).sum() / dof.sum())
    assert points["dp_n_repeat_sd"].iloc[0] == pytest.approx(pooled)
    assert pooled < 0.2 * raw["tractive_force_std_n"].median()


def test_a_wpm_file_without_wheel_geometry_cannot_stand_for_a_wheel(tmp_path):
    path = write_wpm(BASE, tmp_path / "old.csv", geometry=False)
    with pytest.raises(ValueError, match="no wheel geometry.*'bb2'.*radius"):
        load_simulated(path)
    with pytest.raises(ValueError, match="no wheel geometry"):
        load_measured(str(path))


def test_the_wpm_simulation_models_the_wheel_of_its_file(tmp_path):
    small = BASE.with_wheel(radius_m=0.09, width_m=0.08, grouser_count=0, grouser_height_m=0.0)
    sim = load_simulated(write_wpm(small, tmp_path / "sim.csv"))
    assert (sim.radius_m, sim.wheel.width_m, sim.wheel.grouser_count) == (0.09, 0.08, 0)
    points = synthetic_points(BASE, loads=(180.0,), slips=(0.2,), multipass=(0,))
    values = {"effects.bulldozing.coefficient": 1.0}
    correction = sim.predict(points, values)["dp_n"] - sim.predict(points, {})["dp_n"]
    direct = (small.with_parameters(values).curves(180.0, 0.2)["dp_n"]
              - small.curves(180.0, 0.2)["dp_n"])
    np.testing.assert_allclose(correction, direct, rtol=1e-9)
