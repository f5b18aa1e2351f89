"""Spec CSV form: run.json + <topic>.csv gives the same run as the MCAP form; frames on disk."""

from __future__ import annotations

import json

import numpy as np

import ingest


def test_csv_form_equals_mcap_form(tmp_path, ingest_tools, ingest_spec, ingest_good_mcap):
    folder = ingest_tools.write_csv_run(tmp_path / "run_csv", ingest_spec.topics,
                                        ingest_spec.records)
    from_csv = ingest.read_run(folder)
    from_mcap = ingest.read_run(ingest_good_mcap)
    assert from_csv.metadata == from_mcap.metadata
    assert list(from_csv.channels.columns) == list(from_mcap.channels.columns)
    np.testing.assert_allclose(from_csv.channels.to_numpy(), from_mcap.channels.to_numpy(),
                               rtol=1e-12, atol=1e-12, equal_nan=True)
    assert from_csv.problems == from_mcap.problems == []


def test_csv_calibration_and_zero_from_run_json(tmp_path, ingest_tools, ingest_spec):
    truth = ingest_spec.topics["/hub/wrench"]["fx"].copy()
    ingest_spec.topics["/hub/wrench"]["fx"] = (truth + 2.0 - 1.0) / 10.0
    records = dict(ingest_spec.records)
    records["calibration"] = {"/hub/wrench.fx.gain": "10", "/hub/wrench.fx.offset": "1"}
    records["zero"] = {"fx": "2.0"}
    run = ingest.read_run(ingest_tools.write_csv_run(tmp_path / "r", ingest_spec.topics, records))
    np.testing.assert_allclose(run.streams["/hub/wrench"]["fx_n"], truth, atol=1e-9)


def test_csv_frames_from_image_files(tmp_path, ingest_tools, ingest_spec):
    folder = ingest_tools.write_csv_run(tmp_path / "r", ingest_spec.topics, ingest_spec.records)
    (folder / "camera_side").mkdir()
    for t_ns in (0, 40_000_000, 80_000_000):
        (folder / "camera_side" / f"{t_ns}.png").write_bytes(b"png%d" % t_ns)
    (folder / "camera_track").mkdir()
    (folder / "camera_track" / "after.jpg").write_bytes(b"jpg")
    run = ingest.read_run(folder)
    side = run.frames["/camera/side"]
    np.testing.assert_allclose(side.t_s, [0.0, 0.04, 0.08])
    assert side.data(1) == b"png40000000"
    assert run.frames["/camera/track"].count == 1
    assert {p.channel for p in run.problems} == {"/camera/side", "/camera/track"}  # no px_per_m


def test_csv_frames_from_video_index(tmp_path, ingest_tools, ingest_spec):
    records = dict(ingest_spec.records, camera={"px_per_m": "1500"})
    folder = ingest_tools.write_csv_run(tmp_path / "r", ingest_spec.topics, records)
    (folder / "camera_side.mp4").write_bytes(b"\x00")
    (folder / "camera_side.csv").write_text("frame,t_s\n1,0.02\n0,0.0\n2,0.04\n")
    run = ingest.read_run(folder)
    np.testing.assert_allclose(run.frames["/camera/side"].t_s, [0.0, 0.02, 0.04])
    assert run.metadata.camera.px_per_m == 1500.0
    assert run.problems == []


def test_csv_empty_records_and_json_nulls_count_as_absent(tmp_path, ingest_tools, ingest_spec):
    records = ingest_tools.records(run={"mode": "towed", "slip_setpoint": None})
    records["camera"] = {}
    folder = ingest_tools.write_csv_run(tmp_path / "r", ingest_spec.topics, records)
    meta = json.loads((folder / "run.json").read_text())
    meta["run"]["slip_setpoint"] = None
    meta["run"]["steer_deg"] = None
    (folder / "run.json").write_text(json.dumps(meta))
    run = ingest.read_run(folder)
    condition = run.metadata.run.condition
    assert condition.mode == "towed" and condition.slip_setpoint is None
    assert run.metadata.camera is None
