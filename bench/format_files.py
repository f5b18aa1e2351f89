"""Writers of one virtual-testbed run in each format, each with that format's own library
(h5py, scipy.io.savemat, npTDMS, rosbags): inputs of the round-trip tests and of the
reliability bench's ``format_file`` cases."""

from __future__ import annotations

import json
from dataclasses import dataclass
from datetime import datetime
from pathlib import Path

import numpy as np

from ingest.structured import variable_name


@dataclass
class SpecRun:
    """A spec MCAP run's content: per topic ``t_ns`` (int64) and fields; text records."""

    topics: dict[str, dict[str, np.ndarray]]
    records: dict[str, dict[str, str]]


def read_spec_mcap(path: Path) -> SpecRun:
    """The JSON blocks and ``swt.*`` records of a spec MCAP file, as arrays (the mcap library)."""
    from mcap.reader import make_reader

    parts: dict[str, dict[str, list]] = {}
    with open(path, "rb") as stream:
        reader = make_reader(stream)
        records = {m.name[4:]: dict(m.metadata) for m in reader.iter_metadata()
                   if m.name.startswith("swt.")}
        for _, channel, message in reader.iter_messages(log_time_order=True):
            if channel.topic.startswith("/camera"):
                continue
            block = json.loads(message.data)
            topic = parts.setdefault(channel.topic, {k: [] for k in block})
            for k, v in block.items():
                topic[k].extend(v)
    topics = {t: {k: np.array(v, dtype=np.int64 if k == "t_ns" else np.float64)
                  for k, v in fields.items()} for t, fields in parts.items()}
    return SpecRun(topics=topics, records=records)


def write_hdf5(run: SpecRun, path: Path) -> Path:
    import h5py

    with h5py.File(path, "w") as f:
        for topic, fields in run.topics.items():
            group = f.create_group(topic)
            for k, v in fields.items():
                group.create_dataset(k, data=v)
        for name, record in run.records.items():
            f.create_group(f"swt/{name}").attrs.update(record)
    return path


def _mat_variables(run: SpecRun, path: Path) -> dict:
    """Structs per topic and ``swt``; the calibration record, whose keys (``/hub/wrench.fz.gain``)
    cannot be MATLAB field names, goes to the sidecar ``<name>.run.json``."""
    out = {variable_name(t): {k: v.reshape(1, -1) for k, v in fields.items()}
           for t, fields in run.topics.items()}
    out["swt"] = {k: v for k, v in run.records.items() if k != "calibration"}
    if "calibration" in run.records:
        write_sidecar(SpecRun({}, {"calibration": run.records["calibration"]}), path)
    return out


def write_mat5(run: SpecRun, path: Path) -> Path:
    from scipy.io import savemat

    savemat(path, _mat_variables(run, path), format="5")
    return path


def write_mat73(run: SpecRun, path: Path) -> Path:
    """MATLAB v7.3 as MATLAB lays it out: a 512-byte text header (HDF5 user block), structs as
    groups, column-major Nx1 matrices, text as uint16 with MATLAB_class 'char'."""
    import h5py

    with h5py.File(path, "w", userblock_size=512) as f:
        for name, struct in _mat_variables(run, path).items():
            group = f.create_group(name)
            group.attrs["MATLAB_class"] = np.bytes_("struct")
            for key, value in struct.items():
                if isinstance(value, dict):
                    sub = group.create_group(key)
                    sub.attrs["MATLAB_class"] = np.bytes_("struct")
                    for k, text in value.items():
                        ds = sub.create_dataset(k, data=np.array(
                            [ord(c) for c in text], dtype=np.uint16).reshape(-1, 1))
                        ds.attrs["MATLAB_class"] = np.bytes_("char")
                else:
                    ds = group.create_dataset(key, data=value.T)
                    ds.attrs["MATLAB_class"] = np.bytes_(str(value.dtype).replace("float64",
                                                                                   "double"))
    header = b"MATLAB 7.3 MAT-file, Platform: GLNXA64, Created on: Tue Dec  1 00:00:00 2026 HDF5"
    with open(path, "r+b") as stream:
        stream.write(header.ljust(116) + b"\x00" * 8 + b"\x00\x02IM")
    return path


def write_tdms(run: SpecRun, path: Path, waveform: bool = False) -> Path:
    """Groups named as the topics; a ``t_ns`` channel, or (``waveform``) the ``wf_*`` timing of
    a topic sampled at a fixed rate."""
    from nptdms import ChannelObject, GroupObject, RootObject, TdmsWriter

    props = {f"{r}.{k}": v for r, rec in run.records.items() for k, v in rec.items()}
    objects = [RootObject(properties=props)]
    for topic, fields in run.topics.items():
        objects.append(GroupObject(topic))
        t_ns = fields["t_ns"]
        for k, v in fields.items():
            if waveform and k == "t_ns":
                continue
            timing = {}
            if waveform:
                timing = {"wf_start_time": np.datetime64("2026-11-20T10:00:00", "ns"),
                          "wf_start_offset": t_ns[0] * 1e-9,
                          "wf_increment": float(t_ns[1] - t_ns[0]) * 1e-9}
            objects.append(ChannelObject(topic, k, v, properties=timing))
    with TdmsWriter(path) as writer:
        writer.write_segment(objects)
    return path


def _ros_messages(run: SpecRun, typestore, ros2: bool):
    """(topic, msgtype, t_ns, message) of every sample, as standard messages (spec_ros map)."""
    types = typestore.types
    started = datetime.fromisoformat(run.records["run"]["started_at"].replace("Z", "+00:00"))
    epoch_ns = int(started.timestamp()) * 1_000_000_000
    Time = types["builtin_interfaces/msg/Time"]
    Header = types["std_msgs/msg/Header"]

    def header(ns):
        stamp = Time(sec=ns // 10**9, nanosec=ns % 10**9)
        return Header(stamp=stamp, frame_id="hub") if ros2 else \
            Header(seq=0, stamp=stamp, frame_id="hub")

    vec, wrench = types["geometry_msgs/msg/Vector3"], types["geometry_msgs/msg/Wrench"]
    out = []
    for topic, fields in run.topics.items():
        t = fields["t_ns"] + epoch_ns
        for i, ns in enumerate(t.tolist()):
            if topic == "/hub/wrench":
                msgtype = "geometry_msgs/msg/WrenchStamped"
                msg = types[msgtype](header=header(ns), wrench=wrench(
                    force=vec(x=fields["fx"][i], y=fields["fy"][i], z=fields["fz"][i]),
                    torque=vec(x=fields["tx"][i], y=fields["ty"][i], z=fields["tz"][i])))
            elif topic == "/tether/force":
                msgtype = "std_msgs/msg/Float64"
                msg = types[msgtype](data=fields["dp"][i])
            elif topic in ("/wheel/encoder", "/suspension/angle"):
                msgtype = "sensor_msgs/msg/JointState"
                joint = "wheel" if topic == "/wheel/encoder" else "suspension"
                msg = types[msgtype](header=header(ns), name=[joint],
                                     position=np.array([fields["angle"][i]]),
                                     velocity=np.array([], dtype=np.float64),
                                     effort=np.array([], dtype=np.float64))
            elif topic == "/sled/encoder":
                msgtype = "geometry_msgs/msg/PointStamped"
                msg = types[msgtype](header=header(ns), point=types["geometry_msgs/msg/Point"](
                    x=fields["position"][i], y=0.0, z=0.0))
            else:
                msgtype = "std_msgs/msg/Float64MultiArray"
                layout = types["std_msgs/msg/MultiArrayLayout"](dim=[], data_offset=0)
                msg = types[msgtype](layout=layout, data=np.array([fields["position"][i]]))
            out.append((topic, msgtype, ns, msg))
    return sorted(out, key=lambda m: m[2])


def write_sidecar(run: SpecRun, path: Path) -> None:
    from ingest.structured import sidecar_path

    sidecar_path(path).write_text(json.dumps(run.records), encoding="utf-8")


def _ros_records(run: SpecRun) -> SpecRun:
    """The run's records with calibration keys naming the ROS message fields of the spec_ros
    map (``/tether/force.dp.gain`` -> ``/tether/force.data.gain``)."""
    from ingest import load_channel_map

    ros = {c.column: c.field for c in load_channel_map("spec_ros").channels}
    rename = {f"{c.topic}.{c.field}.": f"{c.topic}.{ros[c.column]}."
              for c in load_channel_map("spec").channels}
    records = {k: dict(v) for k, v in run.records.items()}
    calibration = {}
    for key, value in records.get("calibration", {}).items():
        prefix = next(p for p in rename if key.startswith(p))
        calibration[rename[prefix] + key[len(prefix):]] = value
    if calibration:
        records["calibration"] = calibration
    return SpecRun({}, records)


def write_ros1(run: SpecRun, path: Path) -> Path:
    from rosbags.rosbag1 import Writer
    from rosbags.typesys import Stores, get_typestore

    store = get_typestore(Stores.ROS1_NOETIC)
    with Writer(path) as writer:
        connections = {}
        for topic, msgtype, ns, msg in _ros_messages(run, store, ros2=False):
            if topic not in connections:
                connections[topic] = writer.add_connection(topic, msgtype, typestore=store)
            writer.write(connections[topic], ns, store.serialize_ros1(msg, msgtype))
    write_sidecar(_ros_records(run), path)
    return path


def write_ros2(run: SpecRun, folder: Path, storage: str = "sqlite3") -> Path:
    from rosbags.rosbag2 import StoragePlugin, Writer
    from rosbags.typesys import Stores, get_typestore

    store = get_typestore(Stores.ROS2_HUMBLE)
    plugin = StoragePlugin.MCAP if storage == "mcap" else StoragePlugin.SQLITE3
    with Writer(folder, version=9, storage_plugin=plugin) as writer:
        connections = {}
        for topic, msgtype, ns, msg in _ros_messages(run, store, ros2=True):
            if topic not in connections:
                connections[topic] = writer.add_connection(topic, msgtype, typestore=store)
            writer.write(connections[topic], ns, store.serialize_cdr(msg, msgtype))
    write_sidecar(_ros_records(run), folder)
    return folder


#: format -> (writer of a run to a file or folder under ``folder``, channel map)
WRITERS = {
    "hdf5": (lambda run, folder: write_hdf5(run, folder / "run.h5"), None),
    "mat5": (lambda run, folder: write_mat5(run, folder / "run.mat"), None),
    "mat73": (lambda run, folder: write_mat73(run, folder / "run.mat"), None),
    "tdms": (lambda run, folder: write_tdms(run, folder / "run.tdms"), None),
    "rosbag1": (lambda run, folder: write_ros1(run, folder / "run.bag"), "spec_ros"),
    "rosbag2": (lambda run, folder: write_ros2(run, folder / "bag2"), "spec_ros"),
}
