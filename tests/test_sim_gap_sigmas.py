"""The gap diagnosis' sigma per point (sim_gap.fit.sigmas): the measured repeatability where
a source has it (replicate runs, a points CSV row's repeats), the assumed one elsewhere."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from sim_gap.fit import sigmas
from sim_gap.measured import pooled_repeatability
from sim_gap.points_csv import read_points_csv
from sim_gap.vocabulary import model_error_floor


def _results(dp, u, slips, loads):
    n = len(dp)
    return pd.DataFrame({"run_id": [f"r{i}" for i in range(n)], "wheel": "w", "soil": "s",
                         "mode": "speed_control", "multipass": 0, "load_set_n": loads,
                         "slip_setpoint": slips, "velocity_set_mps": 0.01,
                         "gravity_mps2": 9.81, "steer_deg": np.nan, "status": "ok",
                         "dp_n_mean": dp, "dp_n_u": u})


def test_pooled_repeatability_by_hand():
    # 10, 11, 12 N at one condition (sd 1, 2 dof), 20 and 23 N at another (sd 2.1213, 1 dof),
    # one lone run: pooled sqrt((2 * 1 + 1 * 4.5) / 3) = 1.4720 N
    table = _results([10.0, 11.0, 12.0, 20.0, 23.0, 30.0], [0.5] * 6,
                     [0.2, 0.2, 0.2, 0.4, 0.4, 0.6], [180.0] * 6)
    assert pooled_repeatability(table) == {"dp_n_repeat_sd": pytest.approx(np.sqrt(6.5 / 3))}
    # no two runs share a condition: nothing measured
    assert pooled_repeatability(table.assign(slip_setpoint=[0.1, 0.2, 0.3, 0.4, 0.5, 0.6])) == {}


def test_measured_repeatability_replaces_the_assumed_floor(tmp_path):
    path = tmp_path / "p.csv"
    path.write_text("source,wheel_radius_m,wheel_width_m,load_set_n,slip,n_repeats,dp_n,dp_n_sd,"
                    "wheel_load_n\nlab,0.1,0.05,50,0.2,4,10,2.0,\nlab,0.1,0.05,50,0.4,,12,2.0,\n")
    table = read_points_csv(path)
    # four repeats: their spread over sqrt(4) is the measured uncertainty of the mean; the
    # lone row gets the assumed repeatability (1 % of 50 N + 0.3 N) in quadrature
    sig = sigmas(table, 0.1)["dp_n"]
    floor = float(model_error_floor("dp_n", np.array([50.0]), 0.1)[0])
    assert sig == pytest.approx([1.0, np.hypot(2.0, floor)])
    # a run whose own budget exceeds its source's repeatability keeps its budget
    points = pd.DataFrame({"wheel_load_n": [180.0, 180.0], "dp_n": [10.0, 11.0],
                           "dp_n_se": [0.4, 3.0], "dp_n_repeat_sd": [1.47, 1.47]})
    assert sigmas(points, 0.1)["dp_n"] == pytest.approx([1.47, 3.0])
