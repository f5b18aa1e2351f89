"""Every way a run can be unusable gives one IngestError line: file, channel, problem."""

from __future__ import annotations

import json

import numpy as np
import pytest

import ingest
from ingest import IngestError


def _error(path, channel_map=None) -> IngestError:
    with pytest.raises(IngestError) as info:
        ingest.read_run(path, channel_map)
    err = info.value
    assert "\n" not in str(err)
    assert str(err) == f"{err.path}: {err.channel or '-'}: {err.problem}"
    return err


def _write(tmp_path, tools, spec, name="bad.mcap"):
    return tools.write_mcap(tmp_path / name, spec)


def test_error_line_format():
    err = IngestError("/data/r.mcap", "/hub/wrench.fz", "3 NaN/inf samples,\n first at t=1 s")
    assert str(err) == "/data/r.mcap: /hub/wrench.fz: 3 NaN/inf samples, first at t=1 s"
    assert err.channel == "/hub/wrench.fz" and err.path.name == "r.mcap"


def test_truncated_mcap(tmp_path, ingest_good_mcap):
    data = ingest_good_mcap.read_bytes()
    cut = tmp_path / "cut.mcap"
    cut.write_bytes(data[: len(data) // 2])
    err = _error(cut)  # its metadata records, written last, are gone with the cut
    assert err.path == cut and err.channel == "swt.wheel"
    assert "file ends at t = " in err.problem and "(cut short?): truncated MCAP" in err.problem


@pytest.mark.parametrize("where", [0.3, 0.5, 0.7])
def test_flipped_bytes(tmp_path, ingest_good_mcap, where):
    data = bytearray(ingest_good_mcap.read_bytes())
    i = int(len(data) * where)
    data[i:i + 8] = bytes(b ^ 0xFF for b in data[i:i + 8])
    bad = tmp_path / "flipped.mcap"
    bad.write_bytes(bytes(data))
    assert "MCAP" in _error(bad).problem or "JSON" in _error(bad).problem


def test_not_an_mcap(tmp_path):
    bad = tmp_path / "text.mcap"
    bad.write_text("hello")
    assert "corrupt or truncated MCAP" in _error(bad).problem


@pytest.mark.parametrize("topic", ["/hub/wrench", "/tether/force", "/wheel/encoder",
                                   "/sled/encoder", "/suspension/angle"])
def test_missing_required_topic(tmp_path, ingest_tools, ingest_spec, topic):
    del ingest_spec.topics[topic]
    err = _error(_write(tmp_path, ingest_tools, ingest_spec))
    assert err.channel.startswith(topic + ".") and "required channel missing" in err.problem


def test_missing_required_field(tmp_path, ingest_tools, ingest_spec):
    del ingest_spec.topics["/hub/wrench"]["tz"]
    err = _error(_write(tmp_path, ingest_tools, ingest_spec))
    assert err.channel == "/hub/wrench.tz" and "field 'tz' absent" in err.problem


def test_non_monotonic_time(tmp_path, ingest_tools, ingest_spec):
    t = ingest_spec.topics["/sled/encoder"]["t_ns"]
    t[[10, 11]] = t[[11, 10]]
    err = _error(_write(tmp_path, ingest_tools, ingest_spec))
    assert err.channel == "/sled/encoder" and "go backwards 1 times" in err.problem


def test_duplicate_time(tmp_path, ingest_tools, ingest_spec):
    t = ingest_spec.topics["/tether/force"]["t_ns"]
    t[51] = t[50]
    err = _error(_write(tmp_path, ingest_tools, ingest_spec))
    assert err.channel == "/tether/force" and "1 duplicate time stamps" in err.problem


def test_stream_on_another_clock(tmp_path, ingest_tools, ingest_spec):
    """Absolute (epoch) t_ns on one topic: refused before a gigantic time base is built."""
    ingest_spec.topics["/sled/encoder"]["t_ns"] += 1_763_700_000 * 10**9
    err = _error(_write(tmp_path, ingest_tools, ingest_spec))
    assert err.channel == "/sled/encoder" and "t_ns must count from the run start" in err.problem


def test_nan_and_inf_samples_counted_with_first_time(tmp_path, ingest_tools, ingest_spec):
    wrench = ingest_spec.topics["/hub/wrench"]
    wrench["fz"][[400, 900, 901]] = [np.nan, np.inf, np.nan]
    err = _error(_write(tmp_path, ingest_tools, ingest_spec))
    first = wrench["t_ns"][400] * 1e-9
    assert err.channel == "/hub/wrench.fz"
    assert err.problem.startswith(f"3 NaN/inf samples, first at t={first:.6f} s")


def test_null_samples_count_as_nan(tmp_path, ingest_tools, ingest_spec):
    ingest_spec.extra_blocks = [("/tether/force", b'{"t_ns": [9000000000], "dp": [null]}')]
    err = _error(_write(tmp_path, ingest_tools, ingest_spec))
    assert err.channel == "/tether/force.dp" and "1 NaN/inf samples" in err.problem


def test_block_fields_of_different_lengths(tmp_path, ingest_tools, ingest_spec):
    block = b'{"t_ns": [9000000000, 9001000000], "dp": [1.0]}'
    ingest_spec.extra_blocks = [("/tether/force", block)]
    err = _error(_write(tmp_path, ingest_tools, ingest_spec))
    assert err.channel == "/tether/force" and "different lengths (t_ns 2, dp 1)" in err.problem


def test_block_without_t_ns(tmp_path, ingest_tools, ingest_spec):
    ingest_spec.extra_blocks = [("/tether/force", b'{"dp": [1.0]}')]
    assert "not a block with t_ns" in _error(_write(tmp_path, ingest_tools, ingest_spec)).problem


def test_block_not_json(tmp_path, ingest_tools, ingest_spec):
    ingest_spec.extra_blocks = [("/tether/force", b'{"t_ns": [1], "dp": [1.0')]
    err = _error(_write(tmp_path, ingest_tools, ingest_spec))
    assert err.channel == "/tether/force" and "not valid JSON" in err.problem


@pytest.mark.parametrize("changes, channel, words", [
    ({"run": {"mode": "drifting"}}, "swt.run.mode", "unknown mode 'drifting'"),
    ({"run": {"load_N": "-40"}}, "swt.run.load_N", "must be > 0"),
    ({"run": {"mode": "towed"}}, "swt.run.slip_setpoint", "a towed run has no slip set-point"),
    ({"run": {"mode": "free_sled"}}, "swt.run.slip_setpoint", "free_sled run has no slip"),
    ({"run": {"slip_setpoint": None}}, "swt.run.slip_setpoint", "needs its slip set-point"),
    ({"run": {"steer_deg": "10"}}, "swt.run.steer_deg", "only steered runs have one"),
    ({"run": {"mode": "steered", "slip_setpoint": None}}, "swt.run.steer_deg",
     "steered run needs its steering angle"),
    ({"run": {"slip_setpoint": "25"}}, "swt.run.slip_setpoint", "outside [-1, 1]"),
    ({"run": {"multipass": "1.5"}}, "swt.run.multipass", "not a whole number"),
    ({"run": {"velocity_mps": "fast"}}, "swt.run.velocity_mps", "is not a number"),
    ({"run": {"velocity_mps": "-0.1"}}, "swt.run.velocity_mps", "must be >= 0"),
    ({"run": {"started_at": "yesterday"}}, "swt.run.started_at", "not an ISO 8601"),
    ({"run": {"campaign": None}}, "swt.run.campaign", "missing"),
    ({"wheel": {"radius_m": "0"}}, "swt.wheel.radius_m", "must be > 0"),
    ({"wheel": {"radius_m": "-0.1"}}, "swt.wheel.radius_m", "must be > 0"),
    ({"wheel": {"grouser_count": "-2"}}, "swt.wheel.grouser_count", "must be >= 0"),
    ({"wheel": {"stiffness_N_per_mm": "0"}}, "swt.wheel.stiffness_N_per_mm", "must be > 0"),
    ({"suspension": {"arm_length_m": None}}, "swt.suspension.arm_length_m", "missing"),
    ({"zero": {"fq": "1"}}, "swt.zero.fq", "not a wrench field"),
    ({"calibration": {"/hub/wrench.fz.scale": "2"}}, "swt.calibration./hub/wrench.fz.scale",
     "expected '<topic>.<field>.' followed by one of gain, offset, gain_rel_u, offset_u"),
    ({"calibration": {"/hub/wrench.fz.gain_rel_u": "-0.01"}},
     "swt.calibration./hub/wrench.fz.gain_rel_u", "standard uncertainty must be >= 0"),
    ({"calibration": {"/hub/wrench.fz.gain": "0"}}, "swt.calibration./hub/wrench.fz.gain",
     "gain of 0"),
    ({"camera": {"px_per_m": "-5"}}, "swt.camera.px_per_m", "must be > 0"),
])
def test_bad_metadata(tmp_path, ingest_tools, ingest_spec, changes, channel, words):
    ingest_spec.records = ingest_tools.records(**changes)
    err = _error(_write(tmp_path, ingest_tools, ingest_spec))
    assert err.channel == channel and words in err.problem


def test_missing_metadata_records(tmp_path, ingest_tools, ingest_spec):
    del ingest_spec.records["wheel"]
    err = _error(_write(tmp_path, ingest_tools, ingest_spec))
    assert err.channel == "swt.wheel" and "metadata record missing" in err.problem
    ingest_spec.records = ingest_tools.records()
    del ingest_spec.records["suspension"]
    err = _error(_write(tmp_path, ingest_tools, ingest_spec, "b.mcap"))
    assert err.channel == "swt.suspension"


def test_not_a_run(tmp_path):
    (tmp_path / "notes.txt").write_text("1,2,3\n")
    assert "not a run" in _error(tmp_path / "notes.txt").problem
    assert "no such file" in _error(tmp_path / "absent.mcap").problem


def test_csv_form_errors(tmp_path, ingest_tools, ingest_spec):
    folder = ingest_tools.write_csv_run(tmp_path / "run", ingest_spec.topics, ingest_spec.records)
    (folder / "run.json").write_text("{not json")
    assert "not valid JSON" in _error(folder).problem
    folder = ingest_tools.write_csv_run(tmp_path / "run2", ingest_spec.topics, ingest_spec.records)
    text = (folder / "tether_force.csv").read_text().splitlines()
    text[5] = text[5].split(",")[0] + ",abc"
    (folder / "tether_force.csv").write_text("\n".join(text))
    err = _error(folder)
    assert err.channel == "dp" and "1 non-numeric values, first in line 6: 'abc'" in err.problem
    folder = ingest_tools.write_csv_run(tmp_path / "run3", ingest_spec.topics, ingest_spec.records)
    text = (folder / "sled_encoder.csv").read_text().replace("t_s,", "time,", 1)
    (folder / "sled_encoder.csv").write_text(text)
    err = _error(folder)
    assert err.channel == "t_s" and "first column must be 't_s'" in err.problem
    meta = json.loads((folder / "run.json").read_text())
    assert meta["run"]["load_N"] == 150  # numbers as JSON numbers, per the spec
