"""Every format ingests a virtual-testbed run to the same canonical table as its MCAP form.

Each file is written by that format's own library (bench/format_files.py) from the samples
of a committed sample-campaign MCAP; the reference is ``read_run`` of that MCAP.
"""

from __future__ import annotations

import json
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

import ingest
from ingest.formats import sniff
from bench import format_files as fw

SAMPLE = Path(__file__).resolve().parents[1] / "sample_data" / "campaign" / "L070_MP0_SC_s+010.mcap"


@pytest.fixture(scope="module")
def spec_run() -> fw.SpecRun:
    return fw.read_spec_mcap(SAMPLE)


@pytest.fixture(scope="module")
def reference():
    return ingest.read_run(SAMPLE)


def _assert_same_table(run, reference):
    got, want = run.channels, reference.channels
    assert list(got.columns) == list(want.columns)
    np.testing.assert_array_equal(got["t_s"].to_numpy(), want["t_s"].to_numpy())
    for column in want.columns[1:]:
        np.testing.assert_allclose(got[column].to_numpy(), want[column].to_numpy(),
                                   rtol=1e-9, atol=0, equal_nan=True, err_msg=column)
    for topic, frame in reference.streams.items():
        np.testing.assert_array_equal(run.streams[topic]["t_s"].to_numpy(),
                                      frame["t_s"].to_numpy(), err_msg=topic)
    # calibration is keyed by source field, which a ROS map names by message path
    assert replace(run.metadata, calibration={}) == replace(reference.metadata, calibration={})
    assert sorted(run.metadata.calibration.values()) == \
        sorted(reference.metadata.calibration.values())
    assert len(reference.metadata.calibration) > 0
    assert run.derivation["time_base"] == reference.derivation["time_base"]


CASES = {**fw.WRITERS, "mcap_cdr": (
    lambda r, d: fw.write_ros2(r, d / "bag3", storage="mcap") / "bag3.mcap", "spec_ros")}


@pytest.mark.parametrize("fmt", list(CASES))
def test_format_round_trips_to_the_mcap_table(fmt, tmp_path, spec_run, reference):
    write, cmap = CASES[fmt]
    path = write(spec_run, tmp_path)
    if fmt == "mcap_cdr":  # the bare CDR MCAP file, with its sidecar, out of its bag folder
        bare = tmp_path / "cdr.mcap"
        path.rename(bare)
        (tmp_path / "bag3.run.json").rename(tmp_path / "cdr.run.json")
        path = bare
    assert sniff(path) == fmt
    _assert_same_table(ingest.read_run(path, cmap), reference)


def test_tdms_waveform_timing_gives_the_same_time_base(tmp_path, spec_run):
    """A fixed-rate topic stored as waveform channels (wf_start_offset + i * wf_increment)
    reads on the same time stamps as its t_ns channel (within float rounding of the step)."""
    topic = "/tether/force"
    dp = spec_run.topics[topic]["dp"]
    t_ns = 7_000_000 + 25_000_000 * np.arange(len(dp), dtype=np.int64)  # 40 Hz from 7 ms
    run = fw.SpecRun({topic: {"t_ns": t_ns, "dp": dp}}, {})
    cmap = ingest.load_channel_map("spec")
    from ingest.tdms_reader import read_tdms

    raw = read_tdms(fw.write_tdms(run, tmp_path / "w.tdms", waveform=True), cmap)
    np.testing.assert_allclose(raw.topics[topic].t_s, t_ns * 1e-9, rtol=0, atol=1e-12)
    np.testing.assert_array_equal(raw.topics[topic].fields["dp"], dp)


@pytest.mark.parametrize("fmt", ["hdf5", "mat5", "tdms", "rosbag1"])
def test_format_is_recognised_by_content_not_extension(fmt, tmp_path, spec_run):
    path = CASES[fmt][0](spec_run, tmp_path)
    renamed = path.rename(tmp_path / "run_file.dat")
    assert sniff(renamed) == fmt


def _error(path, cmap=None) -> ingest.IngestError:
    with pytest.raises(ingest.IngestError) as caught:
        ingest.read_run(path, cmap)
    message = str(caught.value)
    assert "\n" not in message and str(path) in message
    return caught.value


@pytest.mark.parametrize("fmt", ["hdf5", "mat5", "mat73", "tdms"])  # bags: test_ingest_cut_short
def test_truncated_file_is_one_line_error(fmt, tmp_path, spec_run):
    write, cmap = CASES[fmt]
    path = write(spec_run, tmp_path)
    data = path.read_bytes()
    path.write_bytes(data[: len(data) // 3])
    err = _error(path, cmap)
    assert err.path == path


def test_hdf5_channel_problems_name_the_channel(tmp_path, spec_run):
    import h5py

    path = fw.write_hdf5(spec_run, tmp_path / "run.h5")
    with h5py.File(path, "a") as f:
        del f["/tether/force/dp"]
        f["/tether/force/dp"] = np.zeros(3)
    err = _error(path)
    assert err.channel == "/tether/force.dp" and "3 samples" in err.problem
    with h5py.File(path, "a") as f:
        del f["/tether/force/dp"]
        f["/tether/force/dp"] = np.array([b"x"] * len(f["/tether/force/t_ns"]))
    assert _error(path).channel == "/tether/force.dp"
    with h5py.File(path, "a") as f:
        del f["/tether/force/dp"]
    err = _error(path)
    assert err.channel == "/tether/force.dp" and "required channel missing" in err.problem


def test_ros_field_path_errors_name_topic_and_field(tmp_path, spec_run):
    path = fw.write_ros1(spec_run, tmp_path / "run.bag")
    err = _error(path)  # the spec map's fields are not message paths
    assert err.channel == "/hub/wrench.fx" and "has no field 'fx'" in err.problem
    cmap = tmp_path / "joint.toml"
    text = (Path(ingest.load_channel_map("spec_ros").path).read_text()
            .replace("position[wheel]", "position[left]"))
    cmap.write_text(text)
    err = _error(path, cmap)
    assert err.channel == "/wheel/encoder.position[left]" and "no joint 'left'" in err.problem


def test_unknown_bytes_and_folders(tmp_path):
    (tmp_path / "x.dat").write_bytes(b"\x00\x01garbage")
    assert "not a run: unknown format" in _error(tmp_path / "x.dat").problem
    (tmp_path / "empty").mkdir()
    assert "not a run" in _error(tmp_path / "empty").problem


def test_cmu_log_as_a_ros1_bag_reads_to_the_text_logs_channels(tmp_path, ingest_cmu_root):
    """A CMU motion log recorded as a ROS 1 bag (rosbags writer; /cmu/motion,
    std_msgs/Float64MultiArray, one row per message, log time from the host clock) through the
    shipped CMU map gives the text log's channel table and metadata exactly."""
    from rosbags.rosbag1 import Writer
    from rosbags.typesys import Stores, get_typestore

    text = sorted((ingest_cmu_root / "raw").rglob("10_*_0_*.txt"))[0]
    rows = np.loadtxt(text, delimiter=",", ndmin=2)
    store = get_typestore(Stores.ROS1_NOETIC)
    msgtype = "std_msgs/msg/Float64MultiArray"
    Array = store.types[msgtype]
    layout = store.types["std_msgs/msg/MultiArrayLayout"](dim=[], data_offset=0)
    bag = tmp_path / text.parent.name / text.with_suffix(".bag").name
    bag.parent.mkdir()
    with Writer(bag) as writer:
        connection = writer.add_connection("/cmu/motion", msgtype, typestore=store)
        for row in rows:
            writer.write(connection, int(round(row[6] * 1e9)),
                         store.serialize_ros1(Array(layout=layout, data=row), msgtype))
    assert sniff(bag) == "rosbag1"
    from_text = ingest.read_run(text, "cmu_3d_terramechanics")
    from_bag = ingest.read_run(bag, "cmu_3d_terramechanics")
    assert from_bag.run_id.split("/")[-2:] == from_text.run_id.split("/")[-2:]
    assert replace(from_bag.metadata, run=replace(from_bag.metadata.run, run_id="")) == \
        replace(from_text.metadata, run=replace(from_text.metadata.run, run_id=""))
    assert len(from_text.channels) > 1000
    import pandas as pd

    pd.testing.assert_frame_equal(from_bag.channels, from_text.channels, check_exact=True)


def test_hdf5_root_attributes_and_sidecar_give_the_records(tmp_path, spec_run):
    """Records as root attributes ``"<record>.<key>"``; the sidecar overrides the file."""
    import h5py

    run = fw.SpecRun(spec_run.topics, {})
    path = fw.write_hdf5(run, tmp_path / "attrs.h5")
    with h5py.File(path, "a") as f:
        for name, record in spec_run.records.items():
            if name != "calibration":
                f.attrs.update({f"{name}.{k}": v for k, v in record.items()})
        f.attrs["wheel.radius_m"] = 0.2  # a number, not text: read as a number
    fw.write_sidecar(fw.SpecRun({}, {"run": {"load_N": "99.5"},
                                     "calibration": spec_run.records["calibration"]}), path)
    meta = ingest.read_run(path).metadata
    assert meta.wheel.radius_m == 0.2 and meta.run.condition.load_set_n == 99.5
    assert meta.run.run_id == spec_run.records["run"]["run_id"]


def test_tdms_without_time_or_waveform_names_the_channel(tmp_path, spec_run):
    from nptdms import ChannelObject, GroupObject, RootObject, TdmsWriter

    path = tmp_path / "bare.tdms"
    with TdmsWriter(path) as writer:
        writer.write_segment([RootObject(), GroupObject("/tether/force"),
                              ChannelObject("/tether/force", "dp", np.arange(5.0))])
    err = _error(path)
    assert err.channel == "/tether/force.dp" and "wf_increment" in err.problem


def test_mat_topic_that_is_not_a_struct(tmp_path):
    from scipy.io import savemat

    savemat(tmp_path / "flat.mat", {"hub_wrench": np.arange(4.0)})
    err = _error(tmp_path / "flat.mat")
    assert err.channel == "/hub/wrench" and "must be a struct" in err.problem


@pytest.mark.parametrize("fmt", ["hdf5", "mat73", "tdms", "rosbag2"])
def test_swtlab_inspect_takes_the_format(fmt, tmp_path, spec_run, capsys):
    from swtlab_cli.main import main

    write, cmap = CASES[fmt]
    path = write(spec_run, tmp_path)
    assert main(["inspect", str(path), *(["--channel-map", cmap] if cmap else [])]) == 0
    assert spec_run.records["run"]["run_id"] in capsys.readouterr().out


def test_same_stem_runs_need_their_own_sidecars(tmp_path, spec_run, reference):
    """run7.h5 and run7.bag in one folder: the stem sidecar run7.run.json would feed both, so
    it is refused; ``<file name>.run.json`` gives each its own."""
    h5 = fw.write_hdf5(fw.SpecRun(spec_run.topics, {}), tmp_path / "run7.h5")
    bag = fw.write_ros1(spec_run, tmp_path / "run7.bag")  # writes run7.run.json
    for path, cmap in ((h5, None), (bag, "spec_ros")):
        err = _error(path, cmap)
        assert err.channel == "sidecar" and "run7.run.json is ambiguous" in err.problem
    (tmp_path / "run7.run.json").rename(tmp_path / "run7.bag.run.json")
    records = {**spec_run.records, "run": {**spec_run.records["run"], "load_N": "99.5"}}
    (tmp_path / "run7.h5.run.json").write_text(json.dumps(records), encoding="utf-8")
    assert ingest.read_run(h5).metadata.run.condition.load_set_n == 99.5
    assert ingest.read_run(bag, "spec_ros").metadata.run.condition.load_set_n \
        == reference.metadata.run.condition.load_set_n
    assert reference.metadata.run.condition.load_set_n != 99.5
