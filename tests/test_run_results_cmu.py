"""The automatic window on the real CMU 3d-terramechanics logs against the authors' own
70-75 s means (smooth_runs.csv). The logs have no force channels: the window is found from
the speeds and hub height alone and the lack of forces is flagged.

Measured differences (ours - authors), 27 logs: wheel surface speed within 0.09 mm/s (0.23 %) and
slip within 0.0026 (median 0.0003; slip from the window's displacements, here the logged
speeds' time integrals) except the locked wheel (Vry = 0: 0.16 mm/s, slip 0.015, the logged
wheel creeps at about +-1 mm/s; 0.062 from the mean of per-sample slips); hub height within
0.10 mm (the hub still creeps by 0.1-0.3 mm after 50 s on some runs; our windows are 13-41 s
long, theirs 5 s).
"""

from __future__ import annotations

import json

import numpy as np
import pandas as pd
import pytest

import ingest
from run_results import process_run

TOL_WHEEL_SPEED_MM_S = 0.12   # as ingest's own 70-75 s check (tests/test_ingest_cmu.py)
TOL_WHEEL_SPEED_LOCKED_MM_S = 0.2
TOL_SLIP = 0.005
TOL_SLIP_LOCKED = 0.07
TOL_HUB_Z_MM = 0.15
RADIUS_M = 0.058


@pytest.fixture(scope="module")
def results(ingest_cmu_root):
    campaign = ingest.read_campaign(ingest_cmu_root / "raw", "cmu_3d_terramechanics")
    return {run.run_id: process_run(run) for run in campaign.runs}


@pytest.fixture(scope="module")
def authors(ingest_cmu_root):
    table = pd.read_csv(ingest_cmu_root / "smooth_runs.csv").dropna(subset=["run_file"])
    return table.set_index(table["run_file"].str.removesuffix(".txt"))


def test_every_log_gets_a_window_from_speeds_and_hub_height(results):
    assert len(results) == 27
    for run_id, result in results.items():
        w = result.window
        assert w.found, (run_id, w.reason)
        assert 40.0 <= w.start_s <= 70.0 and w.end_s >= 78.0, run_id
        assert w.diagnostics["signals"] == ["hub_height_m", "sinkage_m"]
        assert result.status == "flagged"
        assert any(f.startswith("no force channels") for f in result.flags)
        assert "dp_n" not in result.quantities and "torque_nm" not in result.quantities
        assert result.oscillation["grouser_expected_hz"] is None   # smooth wheel
        json.dumps(result.to_dict(), allow_nan=False)


def test_window_means_agree_with_the_authors(results, authors):
    rows = []
    for run_id, result in results.items():
        row = authors.loc[run_id]
        q = result.quantities
        locked = row["wheel_surface_speed_mm_s"] == 0
        d_speed = q["wheel_omega_radps"].mean * RADIUS_M * 1e3 - row["wheel_surface_speed_mm_s"]
        d_slip = q["slip"].mean - row["slip"]
        d_hub = q["hub_height_m"].mean * 1e3 - row["hub_z_mm"]
        assert abs(d_speed) < (TOL_WHEEL_SPEED_LOCKED_MM_S if locked else TOL_WHEEL_SPEED_MM_S)
        # slip at a few mm/s is noisy: our window's mean has an SE up to 0.002 (gr810
        # 12-7-20/10_10_0_1, slip 0: 0.0020 +- 0.0024 over 41.7-83.1 s, the authors' 70-75 s
        # gives -0.0006), so a window a few seconds apart moves it by about its SE
        tol = (TOL_SLIP_LOCKED if locked else TOL_SLIP) + 3 * q["slip"].se
        assert abs(d_slip) < tol, run_id
        assert abs(d_hub) < TOL_HUB_Z_MM, run_id
        rows.append((d_speed, d_slip, d_hub))
    d = np.abs(np.array(rows))
    assert np.median(d[:, 2]) < 0.03    # hub height: median difference (measured 0.012 mm)


def test_set_point_mismatch_is_reported(results):
    """The 10_12 logs ran at Vry = 13.0 mm/s, not the 12 mm/s of their name."""
    gate = results["gr810_vx_10/11-16-20/10_12_0_1"].window.diagnostics["gate"]
    surface = gate["wheel_surface_speed_mps"]
    assert surface["set_point"] == pytest.approx(0.012)
    assert surface["set_point_mismatch"] == pytest.approx(0.001, abs=1e-4)
