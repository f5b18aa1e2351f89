"""The CMU rig as a ROS bag: a real CMU motion log written with rosbags' writers on the rig's
force/torque topic (/rokubimini_cosmo/forcetorque_readings, rokubimini_msgs/Reading, per the
authors' read_ft_speed_data.m) plus the log's rows (/cmu/motion), read through the shipped
CMU map, gives the text log's table and the force/torque written.

The test is the generator: it builds the messages with rosbags' own type store (the Reading
type from the shipped .msg, whose ROS 1 md5sum must be the public one) and never imports the
reader.
"""

from __future__ import annotations

import sqlite3
from dataclasses import replace
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

import ingest

CMU_MAP = "cmu_3d_terramechanics"
FT_TOPIC = "/rokubimini_cosmo/forcetorque_readings"
READING = "rokubimini_msgs/msg/Reading"
ARRAY = "std_msgs/msg/Float64MultiArray"
#: md5sum of rokubimini_msgs/Reading in the rokubimini ROS 1 driver's generated code
#: (genjs / genlisp output, public)
READING_MD5 = "f632d7286fac45ac13e8083c2bf7f237"
READING_MSG = Path(__file__).resolve().parents[1] / "ingest" / "ros_msgs" / \
    "rokubimini_msgs" / "msg" / "Reading.msg"
RUN = "gr810_vx_10/11-16-20/10_5_0_1"
#: the outer header is stamped later than the wrench's: the map must read wrench.header.stamp
OUTER_HEADER_LAG_NS = 3_000_000


def _store(ros2: bool):
    from rosbags.typesys import Stores, get_typestore, get_types_from_msg

    store = get_typestore(Stores.ROS2_HUMBLE if ros2 else Stores.ROS1_NOETIC)
    store.register(get_types_from_msg(READING_MSG.read_text(), READING))
    return store


def test_reading_msg_is_the_public_definition():
    assert _store(ros2=False).generate_msgdef(READING)[1] == READING_MD5


class _Messages:
    """rosbags message objects of the rig's types in one type store."""

    def __init__(self, store):
        self.store, self.t = store, store.types
        self.has_seq = "seq" in dict(store.fielddefs["std_msgs/msg/Header"][1])

    def header(self, ns: int):
        stamp = self.t["builtin_interfaces/msg/Time"](sec=ns // 1_000_000_000,
                                                      nanosec=ns % 1_000_000_000)
        extra = {"seq": 0} if self.has_seq else {}
        return self.t["std_msgs/msg/Header"](**extra, stamp=stamp, frame_id="ft")

    def vector(self, x=0.0, y=0.0, z=0.0):
        return self.t["geometry_msgs/msg/Vector3"](x=x, y=y, z=z)

    def imu(self, ns: int):
        zeros = np.zeros(9)
        return self.t["sensor_msgs/msg/Imu"](
            header=self.header(ns), orientation=self.t["geometry_msgs/msg/Quaternion"](
                x=0.0, y=0.0, z=0.0, w=1.0),
            orientation_covariance=zeros, angular_velocity=self.vector(),
            angular_velocity_covariance=zeros, linear_acceleration=self.vector(z=9.81),
            linear_acceleration_covariance=zeros)

    def wrench(self, ns: int, force):
        return self.t["geometry_msgs/msg/WrenchStamped"](
            header=self.header(ns),
            wrench=self.t["geometry_msgs/msg/Wrench"](force=self.vector(*force),
                                                     torque=self.vector(0.1, 0.2, 0.3)))

    def reading(self, ns: int, force):
        outer = ns + OUTER_HEADER_LAG_NS
        return self.t[READING](
            header=self.header(outer), statusword=0, imu=self.imu(outer),
            wrench=self.wrench(ns, force), externalImu=self.imu(outer),
            isForceTorqueSaturated=False,
            temperature=self.t["sensor_msgs/msg/Temperature"](
                header=self.header(outer), temperature=25.0, variance=0.0))

    def row(self, row):
        layout = self.t["std_msgs/msg/MultiArrayLayout"](dim=[], data_offset=0)
        return self.t[ARRAY](layout=layout, data=np.asarray(row, dtype=np.float64))


def _rig_samples(root: Path):
    """The real text log, and per row a force in the sensor frame (Fx, Fy, Fz) built from
    the authors' window means of that run (smooth_runs.csv: tractive = -Fy, load = -Fz) with
    a ripple, stamped on the ROS clock at the row's Arduino time."""
    text = root / "raw" / f"{RUN}.txt"
    rows = np.loadtxt(text, delimiter=",", ndmin=2)
    authors = pd.read_csv(root / "smooth_runs.csv").set_index("run_file").loc[f"{RUN}.txt"]
    ripple = np.sin(2 * np.pi * np.arange(len(rows)) / 50.0)
    tractive = authors["tractive_force_n"] + authors["tractive_force_std_n"] * ripple
    side = authors["lateral_force_n"] + authors["lateral_force_std_n"] * ripple
    load = authors["wheel_load_n"] + authors["wheel_load_std_n"] * ripple
    force = np.column_stack([side, -tractive, -load])  # sensor Fx, Fy, Fz
    row_log_ns = np.round(rows[:, 6] * 1e9).astype(np.int64)  # host clock
    ft_ns = row_log_ns[0] + (rows[:, 5] - rows[0, 5]).astype(np.int64) * 1_000_000
    return text, rows, force, row_log_ns, ft_ns


def _records(rows, force, row_log_ns, ft_ns, ft_type=READING):
    """(log ns, topic, msgtype, builder) in log time order."""
    out = [(int(ns), "/cmu/motion", ARRAY, lambda m, r=r: m.row(r))
           for ns, r in zip(row_log_ns, rows)]
    if ft_type == READING:
        out += [(int(ns), FT_TOPIC, READING, lambda m, ns=int(ns), f=f: m.reading(ns, f))
                for ns, f in zip(ft_ns, force)]
    elif ft_type is not None:
        out += [(int(ns), FT_TOPIC, ft_type, lambda m, ns=int(ns), f=f: m.wrench(ns, f))
                for ns, f in zip(ft_ns, force)]
    return sorted(out, key=lambda x: (x[0], x[1]))


def _write_records(writer, messages, records, serialize) -> None:
    """Each ``(ns, topic, msgtype, build)`` record through a rosbags ``writer``, one
    connection per topic, serialised by ``serialize`` (ROS 1 or CDR)."""
    connections = {}
    for ns, topic, msgtype, build in records:
        if topic not in connections:
            connections[topic] = writer.add_connection(topic, msgtype,
                                                       typestore=messages.store)
        writer.write(connections[topic], ns, serialize(build(messages), msgtype))


def _write_ros1(path: Path, records) -> Path:
    from rosbags.rosbag1 import Writer

    messages = _Messages(_store(ros2=False))
    path.parent.mkdir(parents=True, exist_ok=True)
    with Writer(path) as writer:
        _write_records(writer, messages, records, messages.store.serialize_ros1)
    return path


def _write_ros2_without_definitions(folder: Path, records, store=None) -> Path:
    """A ROS 2 sqlite3 bag as ROS 2 Humble records it: no message definitions stored."""
    from rosbags.rosbag2 import StoragePlugin, Writer

    messages = _Messages(store or _store(ros2=True))
    folder.parent.mkdir(parents=True, exist_ok=True)
    with Writer(folder, version=9, storage_plugin=StoragePlugin.SQLITE3) as writer:
        _write_records(writer, messages, records, messages.store.serialize_cdr)
    for db in folder.glob("*.db3"):
        with sqlite3.connect(db) as con:
            con.execute("DELETE FROM message_definitions")
    return folder


def _assert_rig_bag_reads_like_the_text(bag: Path, text: Path, force, rows):
    from_text = ingest.read_run(text, CMU_MAP)
    from_bag = ingest.read_run(bag, CMU_MAP)
    got, want = from_bag.channels, from_text.channels
    assert len(want) > 1000 and list(got.columns) == list(want.columns)
    np.testing.assert_array_equal(got["t_s"].to_numpy(), want["t_s"].to_numpy())
    assert from_bag.derivation["time_base"] == from_text.derivation["time_base"]
    forces = ["fx_n", "fy_n", "fz_n", "dp_n"]
    assert want[forces].isna().all().all()
    for column in want.columns[1:]:
        if column not in forces:
            np.testing.assert_allclose(got[column].to_numpy(), want[column].to_numpy(),
                                       rtol=1e-9, atol=0, equal_nan=True, err_msg=column)
    assert from_bag.run_id == from_text.run_id == RUN
    assert replace(from_bag.metadata, run=replace(from_bag.metadata.run, run_id="")) == \
        replace(from_text.metadata, run=replace(from_text.metadata.run, run_id=""))
    # force/torque: at the rows' Arduino times (the wrench's stamp), in the hub frame
    stream = from_bag.streams[FT_TOPIC]
    t_rows = (rows[:, 5] - rows[0, 5]) * 1e-3
    np.testing.assert_allclose(stream["t_s"].to_numpy(), t_rows, rtol=0, atol=1e-12)
    hub = {"fx_n": -force[:, 1], "dp_n": -force[:, 1], "fy_n": force[:, 0],
           "fz_n": -force[:, 2]}
    for column, values in hub.items():
        np.testing.assert_allclose(stream[column].to_numpy(), values, rtol=1e-9, atol=0,
                                   err_msg=column)
        np.testing.assert_allclose(got[column].to_numpy(),
                                   np.interp(got["t_s"].to_numpy(), t_rows, values),
                                   rtol=1e-9, atol=1e-12, err_msg=column)
    assert [p.channel for p in from_bag.problems] == ["tx_nm", "ty_nm", "tz_nm"]
    assert got["fz_n"].mean() == pytest.approx(22.9927, abs=0.01)  # the authors' load


def test_cmu_rig_ros1_bag_reads_to_the_text_logs_channels(tmp_path, ingest_cmu_root):
    text, rows, force, row_log_ns, ft_ns = _rig_samples(ingest_cmu_root)
    bag = _write_ros1(tmp_path / "gr810_vx_10" / "11-16-20" / "10_5_0_1.bag",
                      _records(rows, force, row_log_ns, ft_ns))
    from rosbags.rosbag1 import Reader

    with Reader(bag) as reader:  # the bag carries the public definition
        assert {c.msgtype: c.digest for c in reader.connections}[READING] == READING_MD5
    _assert_rig_bag_reads_like_the_text(bag, text, force, rows)


def test_cmu_rig_ros2_bag_without_definitions_decodes_with_the_shipped_msg(
        tmp_path, ingest_cmu_root):
    text, rows, force, row_log_ns, ft_ns = _rig_samples(ingest_cmu_root)
    bag = _write_ros2_without_definitions(tmp_path / "gr810_vx_10" / "11-16-20" / "10_5_0_1",
                                          _records(rows, force, row_log_ns, ft_ns))
    _assert_rig_bag_reads_like_the_text(bag, text, force, rows)


def _error(path) -> ingest.IngestError:
    with pytest.raises(ingest.IngestError) as caught:
        ingest.read_run(path, CMU_MAP)
    message = str(caught.value)
    assert "\n" not in message and str(path) in message
    return caught.value


@pytest.fixture()
def short_log(ingest_cmu_root):
    _, rows, force, row_log_ns, ft_ns = _rig_samples(ingest_cmu_root)
    return rows[:200], force[:200], row_log_ns[:200], ft_ns[:200]


def test_wrong_message_type_on_the_force_topic_names_the_channel(tmp_path, short_log):
    bag = _write_ros1(tmp_path / "10_5_0_1.bag",
                      _records(*short_log, ft_type="geometry_msgs/msg/WrenchStamped"))
    err = _error(bag)
    assert err.channel == f"{FT_TOPIC}.wrench.header.stamp"
    assert "(geometry_msgs/msg/WrenchStamped) has no field 'header'" in err.problem


def test_rig_bag_cut_short_reads_its_whole_records(tmp_path, short_log):
    """A bag cut in half has lost its index: its whole records are read (the motion rows the
    whole bag holds up to there) and the run says where the file ends."""
    whole = ingest.read_run(_write_ros1(tmp_path / "whole" / "10_5_0_1.bag",
                                        _records(*short_log)), CMU_MAP)
    bag = _write_ros1(tmp_path / "10_5_0_1.bag", _records(*short_log))
    data = bag.read_bytes()
    bag.write_bytes(data[: len(data) // 2])
    run = ingest.read_run(bag, CMU_MAP)
    want, got = whole.streams["/cmu/motion"], run.streams["/cmu/motion"]
    assert 0 < len(got) < len(want)
    pd.testing.assert_frame_equal(got, want.iloc[:len(got)])
    assert run.cut_short == (f"10_5_0_1.bag: file ends at t = {got['t_s'].iloc[-1]:.3f} s "
                             "(cut short?): ROS 1 bag without its index (the recorder stopped "
                             "mid-write); the messages of its whole chunks and records are read")


def test_unknown_message_type_is_refused_naming_the_topic(tmp_path, short_log):
    from rosbags.typesys import get_types_from_msg

    store = _store(ros2=True)
    store.register(get_types_from_msg("float64 x", "acme_msgs/msg/Force"))
    records = [r for r in _records(*short_log) if r[1] != FT_TOPIC]
    records += [(int(ns), FT_TOPIC, "acme_msgs/msg/Force",
                 lambda m, f=f: m.t["acme_msgs/msg/Force"](x=float(f[0])))
                for ns, f in zip(short_log[3], short_log[1])]
    bag = _write_ros2_without_definitions(tmp_path / "10_5_0_1",
                                          sorted(records, key=lambda r: (r[0], r[1])), store)
    err = _error(bag)
    assert err.channel == FT_TOPIC
    assert "message type acme_msgs/msg/Force unknown" in err.problem


def test_force_only_bag_needs_the_motion_rows(tmp_path, short_log):
    """The rig's own bags hold force/torque only (its motion is the text log): reading one
    alone names the missing motion channel."""
    records = [r for r in _records(*short_log) if r[1] == FT_TOPIC]
    err = _error(_write_ros1(tmp_path / "10_5_0_1.bag", records))
    assert err.channel == "/cmu/motion.x" and "required channel missing" in err.problem
