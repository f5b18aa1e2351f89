"""The general campaign API: forms, rates, durations, determinism and validation."""

from __future__ import annotations

import json

import numpy as np
import pytest
from mcap.reader import make_reader

from swtlab_base.domain import TestCondition
from virtual_testbed import RunCondition, generate_campaign
from virtual_testbed.rig import Timeline
from virtual_testbed.sensors import Rates

CONDITIONS = [RunCondition.of("a", "speed_control", 150.0, 0, 0.25),
              RunCondition.of("b", "free_sled", 150.0, 1)]
FAST = Rates(1000.0, 1000.0, 1000.0, 1000.0, 1000.0, 1000.0)


def test_one_khz_campaign_in_both_forms(tmp_path):
    paths = generate_campaign(tmp_path, CONDITIONS, 7, rates=FAST, duration_s=35.0,
                              form={"a": "mcap", "b": "csv"})
    assert [p.relative_to(tmp_path).as_posix() for p in paths] == ["campaign/a.mcap", "campaign/b"]
    truth = json.loads((tmp_path / "truth" / "a.json").read_text())
    assert truth["timeline"]["duration_s"] == 35.0 and truth["rates_hz"]["wrench_hz"] == 1000.0
    assert truth["stable_window"] == {"start_s": 29.0, "end_s": 32.0}
    with open(paths[0], "rb") as stream:
        t_ns = np.concatenate([json.loads(m.data)["t_ns"] for _, _, m in
                               make_reader(stream).iter_messages(topics=["/hub/wrench"])])
    assert 0.97 * 35000 < t_ns.size <= 35000
    assert np.median(np.diff(t_ns)) == pytest.approx(1e6, rel=1e-3)
    rows = (paths[1] / "hub_wrench.csv").read_text().count("\n") - 1
    assert 0.97 * 35000 < rows <= 35000
    assert not (paths[1] / "tether_encoder.csv").exists()


def test_same_seed_same_bytes_other_seed_other_bytes(tmp_path):
    first = generate_campaign(tmp_path / "1", CONDITIONS[:1], 3, duration_s=34.0)[0].read_bytes()
    again = generate_campaign(tmp_path / "2", CONDITIONS[:1], 3, duration_s=34.0)[0].read_bytes()
    other = generate_campaign(tmp_path / "3", CONDITIONS[:1], 4, duration_s=34.0)[0].read_bytes()
    assert first == again and first != other


def test_rejects_bad_input(tmp_path):
    with pytest.raises(ValueError):
        RunCondition.of("x", "speed_control", 100.0)
    with pytest.raises(ValueError):
        RunCondition.of("x", "towed", 100.0, slip_setpoint=0.1)
    with pytest.raises(ValueError):
        generate_campaign(tmp_path, CONDITIONS[:1] * 2, 1)
    with pytest.raises(ValueError):
        Timeline().with_duration(20.0)
    with pytest.raises(ValueError):
        generate_campaign(tmp_path, CONDITIONS[:1], 1, form="hdf5")


def test_a_run_condition_is_the_domain_set_point(tmp_path):
    """One TestCondition (swtlab_base.domain): the generator adds the run id and the cameras'
    share, the domain's checks hold, and the truth file keeps its own key names."""
    condition = CONDITIONS[1]
    assert isinstance(condition, TestCondition)
    assert (condition.mode, condition.load_set_n, condition.multipass,
            condition.velocity_set_mps) == ("free_sled", 150.0, 1, 40.0 / 3600.0)
    with pytest.raises(ValueError, match="load_set_n"):
        RunCondition.of("x", "towed", 0.0)
    generate_campaign(tmp_path, CONDITIONS[1:], 7, rates=FAST, duration_s=35.0, form="csv")
    truth = json.loads((tmp_path / "truth" / "b.json").read_text())
    assert truth["condition"] == {
        "run_id": "b", "mode": "free_sled", "load_n": 150.0, "multipass": 1,
        "slip_setpoint": None, "velocity_mps": 40.0 / 3600.0, "gravity_mps2": 9.80665,
        "steer_deg": None, "track_photos": 0, "side_camera_frames": 0}
