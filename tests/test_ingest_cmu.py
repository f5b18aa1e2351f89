"""The shipped CMU channel map on the real CMU 3d-terramechanics motion logs."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

import ingest

FORCE_COLUMNS = ["fx_n", "fy_n", "fz_n", "tx_nm", "ty_nm", "tz_nm", "dp_n"]
# Tolerances against the authors' 70-75 s window means (smooth_runs.csv). Their window
# starts at the ROS bag's start, ours at the log's first sample, so means differ slightly.
TOL_HUB_Z_MM = 0.02
TOL_CARRIAGE_MM_S = 0.02
TOL_WHEEL_MM_S = 0.12
TOL_SLIP = 0.005
# Vry = 0 runs: the authors report Vry = 0 and slip = -1 exactly; the logged locked wheel
# reads -1.25 mm/s for part of the window (and has single-sample spikes), so slip differs.
TOL_SLIP_LOCKED = 0.05


@pytest.fixture(scope="module")
def cmu_campaign(ingest_cmu_root):
    return ingest.read_campaign(ingest_cmu_root / "raw", "cmu_3d_terramechanics")


@pytest.fixture(scope="module")
def authors(ingest_cmu_root):
    table = pd.read_csv(ingest_cmu_root / "smooth_runs.csv").dropna(subset=["run_file"])
    return table.set_index(table["run_file"].str.removesuffix(".txt"))


def test_all_cmu_logs_ingest(cmu_campaign):
    assert len(cmu_campaign.runs) == 27 and cmu_campaign.failures == []


def test_problems_list_exactly_the_missing_force_channels(cmu_campaign):
    for run in cmu_campaign.runs:
        assert [(p.severity, p.channel) for p in run.problems] == [
            ("error", c) for c in FORCE_COLUMNS]
        assert run.channels[FORCE_COLUMNS].isna().all().all()


def test_slip_and_hub_height_on_the_common_time_base(cmu_campaign):
    run = next(r for r in cmu_campaign.runs if r.run_id == "gr810_vx_10/12-7-20/10_20_0_1")
    ch = run.channels
    assert np.allclose(np.diff(ch["t_s"]), 1 / run.derivation["time_base"]["rate_hz"])
    assert ch["slip"].notna().mean() > 0.95 and ch["hub_height_m"].notna().all()
    assert run.channels["hub_height_m"].iloc[0] == pytest.approx(0.0315)  # authors' zeroing
    meta = run.metadata
    assert meta.run.condition.mode == "speed_control"
    assert meta.run.condition.slip_setpoint == pytest.approx(0.5)
    assert meta.run.condition.velocity_set_mps == pytest.approx(0.010)
    assert meta.wheel.radius_m == 0.058 and meta.wheel.grouser_count == 0
    assert run.derivation["slip"]["method"].startswith("spec")


def test_window_means_agree_with_the_authors(cmu_campaign, authors):
    checked = 0
    for run in cmu_campaign.runs:
        row = authors.loc[run.run_id]
        ch = run.channels
        window = ch[(ch["t_s"] >= 70) & (ch["t_s"] <= 75)]
        assert abs(window["hub_height_m"].mean() * 1e3 - row["hub_z_mm"]) < TOL_HUB_Z_MM
        assert abs(window["sled_velocity_mps"].mean() * 1e3
                   - row["carriage_speed_mm_s"]) < TOL_CARRIAGE_MM_S
        assert abs(window["wheel_surface_speed_mps"].mean() * 1e3
                   - row["wheel_surface_speed_mm_s"]) < TOL_WHEEL_MM_S
        tol = TOL_SLIP_LOCKED if row["wheel_surface_speed_mm_s"] == 0 else TOL_SLIP
        assert abs(window["slip"].mean() - row["slip"]) < tol
        checked += 1
    assert checked == 27


def test_file_name_gives_steering_and_slip_set_point(tmp_path, ingest_cmu_root):
    """A beta = 30 deg log (name 10_40_30_1.txt) becomes a steered run with its set-points."""
    source = ingest_cmu_root / "raw" / "gr630_vx_10" / "11-19-20" / "10_40_0_1.txt"
    target = tmp_path / "gr630_vx_10" / "11-19-20" / "10_40_30_1.txt"
    target.parent.mkdir(parents=True)
    target.write_bytes(source.read_bytes())
    run = ingest.read_run(target, "cmu_3d_terramechanics")
    assert run.run_id == "gr630_vx_10/11-19-20/10_40_30_1"
    condition = run.metadata.run.condition
    assert condition.mode == "steered" and condition.steer_deg == 30.0
    assert run.metadata.run.condition.slip_setpoint == pytest.approx(0.75)
    assert run.metadata.run.wheel_surface_speed_setpoint_mps == pytest.approx(0.040)


def test_file_name_that_does_not_match_the_map(tmp_path, ingest_cmu_root):
    source = ingest_cmu_root / "raw" / "gr630_vx_10" / "11-19-20" / "10_40_0_1.txt"
    target = tmp_path / "run_a.txt"
    target.write_bytes(source.read_bytes())
    with pytest.raises(ingest.IngestError, match="does not match the channel map's regex"):
        ingest.read_run(target, "cmu_3d_terramechanics")
