"""ROS reader (rosbags): ROS 1 bags, ROS 2 bags (sqlite3 or MCAP storage), CDR-encoded MCAP.

The map's topic is the ROS topic; its field is a path into the message: ``wrench.force.x``
(WrenchStamped), ``position[0]`` or ``position[wheel_joint]`` (JointState, by index or by
joint name), ``data`` (Float64), ``data[1]`` (Float64MultiArray), ``point.x`` (PointStamped).
Time: the stamp at the map's ``stamp`` path (``wrench.header.stamp``), else the message's
``header.stamp`` when it has one, else the bag's log time; counted
from ``run.started_at`` of the sidecar ``<name>.run.json`` when given, else from the
earliest time stamp read. Metadata: the sidecar.
"""

from __future__ import annotations

import re
import tempfile
from collections import defaultdict
from contextlib import contextmanager
from datetime import datetime, timezone
from pathlib import Path

import numpy as np

from ingest.channel_map import ChannelMap
from ingest.errors import IngestError
from ingest.formats import sniff
from ingest.raw import RawRun, RawTopic
from ingest.ros1_reindex import CUT_BAG, needs_reindex, reindexed
from ingest.structured import sidecar_records

_STEP = re.compile(r"([A-Za-z_]\w*)(?:\[([^\]]+)\])?")
_EPOCH = datetime(1970, 1, 1, tzinfo=timezone.utc)


def read_ros(path: Path, cmap: ChannelMap) -> RawRun:
    """The map's topics and message fields of one bag (file or ROS 2 folder); a ROS 1 bag cut
    short is read as far as its whole records go (``ingest.ros1_reindex``)."""
    path = Path(path)
    records = sidecar_records(path)
    samples = _Samples(path, cmap)
    with _readable(path) as (bag, cut):
        for topic, log_ns, message in _messages(path, bag, set(cmap.topics)):
            samples.add(topic, log_ns, message)
    if not samples.stamps:
        return RawRun(path=path, records={}, topics={}, cut_short=cut)
    return RawRun(path=path, records={},  # the sidecar's records: read_run merges them
                  topics=samples.raw_topics(_start_ns(path, records, samples.stamps)),
                  cut_short=cut)


@contextmanager
def _readable(path: Path):
    """``(bag, cut_short)``: the bag itself and None, or for a ROS 1 bag without its index an
    indexed copy of its whole records (removed afterwards) and why it looks cut short."""
    if not (path.is_file() and sniff(path) == "rosbag1" and needs_reindex(path)):
        yield path, None
        return
    with tempfile.TemporaryDirectory(prefix="swtlab-reindex-") as folder:
        yield reindexed(path, Path(folder) / path.name), CUT_BAG


def read_ros_rows(path: Path, cmap: ChannelMap) -> RawRun:
    """A delimited map's text log recorded in a bag: each message on the map's ``stream``
    topic carries one row in its ``data`` array (std_msgs/Float64MultiArray), the columns in
    the map's ``files.columns`` order; time from the map's time column, as for the text.
    The map's channels on other topics are message paths, as for :func:`read_ros`; their
    stamps count from the log time of the first row (the row the text's time counts from)."""
    path = Path(path)
    samples = _Samples(path, cmap)
    rows, first_row_ns = [], None
    with _readable(path) as (bag, cut):
        for topic, log_ns, message in _messages(path, bag, set(cmap.topics) | {cmap.stream}):
            if topic != cmap.stream:
                samples.add(topic, log_ns, message)
                continue
            row = np.asarray(getattr(message, "data", ()), dtype=np.float64).reshape(-1)
            if len(row) != len(cmap.columns):
                raise IngestError(path, cmap.stream, f"message {len(rows)} holds {len(row)} "
                                  f"values, the channel map {cmap.path.name} expects "
                                  f"{len(cmap.columns)} ({', '.join(cmap.columns)})")
            first_row_ns = log_ns if first_row_ns is None else first_row_ns
            rows.append(row)
    topics = {}
    if samples.stamps:
        start_ns = first_row_ns if first_row_ns is not None else \
            min(min(t) for t in samples.stamps.values())
        topics = samples.raw_topics(start_ns)
    if rows:
        table = np.vstack(rows)
        wanted = {cmap.time_column} | {c.field for c in cmap.channels_of(cmap.stream)}
        fields = {name: table[:, i] for i, name in enumerate(cmap.columns) if name in wanted}
        t = fields.pop(cmap.time_column)
        topics[cmap.stream] = RawTopic(t_s=(t - t[0]) * cmap.time_scale_s, fields=fields)
    return RawRun(path=path, records={}, topics=topics, cut_short=cut)  # sidecar: read_run


class _Samples:
    """Time stamps (ns) and the map's message fields of each topic, in reading order."""

    def __init__(self, path: Path, cmap: ChannelMap):
        self.path, self.cmap = path, cmap
        self.stamps: dict[str, list[int]] = defaultdict(list)
        self.values: dict[str, dict[str, list[float]]] = defaultdict(lambda: defaultdict(list))

    def add(self, topic: str, log_ns: int, message) -> None:
        index = len(self.stamps[topic])
        self.stamps[topic].append(
            _stamp_ns(self.path, topic, self.cmap.stamp_of(topic), message, log_ns, index))
        for spec in dict.fromkeys(c.field for c in self.cmap.channels_of(topic)):
            value = _walk(self.path, topic, spec, message, index)
            try:
                self.values[topic][spec].append(float(value))
            except (TypeError, ValueError):
                raise IngestError(self.path, f"{topic}.{spec}", f"message {index}: not a "
                                  f"number ({type(value).__name__})") from None

    def raw_topics(self, start_ns: int) -> dict[str, RawTopic]:
        """Each topic in time stamp order, its times in s from ``start_ns``."""
        topics = {}
        for topic, times in self.stamps.items():
            t_ns = np.array(times, dtype=np.int64)
            order = np.argsort(t_ns, kind="stable")
            topics[topic] = RawTopic(
                t_s=(t_ns[order] - start_ns) * 1e-9,
                fields={k: np.asarray(v, dtype=np.float64)[order]
                        for k, v in self.values[topic].items()})
        return topics


def _messages(path: Path, bag: Path, topics: set[str]):
    """(topic, log time ns, decoded message) of the messages on ``topics`` of ``bag`` (the
    run's ``path`` or its reindexed copy), in log time order; a damaged bag or a message type
    nobody defines is one IngestError."""
    from rosbags.highlevel import AnyReader

    from ingest.ros_types import default_typestore

    try:
        with AnyReader([bag], default_typestore=default_typestore()) as reader:
            wanted = [c for c in reader.connections if c.topic in topics]
            for connection in wanted:
                if connection.msgtype not in reader.typestore.fielddefs:
                    raise IngestError(path, connection.topic, f"message type "
                                      f"{connection.msgtype} unknown: the bag carries no "
                                      "definition of it and it is no ROS 2 standard type nor "
                                      "one of ingest/ros_msgs (record with definitions)")
            for connection, log_ns, data in reader.messages(connections=wanted):
                yield connection.topic, log_ns, reader.deserialize(data, connection.msgtype)
    except IngestError:
        raise
    except OSError as exc:
        raise IngestError(path, None, f"cannot read file: {exc.strerror or exc}") from None
    except Exception as exc:  # rosbags raises many types for damaged bags
        raise IngestError(path, None, f"corrupt or unreadable ROS bag ({type(exc).__name__}: "
                          f"{exc}); the bag is damaged or cut short (try `rosbag reindex`)") \
            from None


def _stamp_ns(path: Path, topic: str, stamp: str | None, message, log_ns: int,
              index: int) -> int:
    """The message's time stamp in ns: at the map's ``stamp`` path, else ``header.stamp``
    when the message has one, else the bag's log time."""
    if stamp is not None:
        value = _walk(path, topic, stamp, message, index)
    else:
        value = getattr(getattr(message, "header", None), "stamp", None)
        if value is None:
            return int(log_ns)
    nsec = getattr(value, "nanosec", getattr(value, "nsec", None))
    if not hasattr(value, "sec") or nsec is None:
        raise IngestError(path, f"{topic}.{stamp or 'header.stamp'}", f"message {index}: "
                          f"not a time stamp ({type(value).__name__}; a stamp has sec and nsec)")
    return int(value.sec) * 1_000_000_000 + int(nsec)


def _walk(path: Path, topic: str, spec: str, message, index: int):
    """The value at ``spec`` (``wrench.force.x``, ``position[wheel]``) in ``message``."""
    value = message
    for step in spec.split("."):
        match = _STEP.fullmatch(step)
        if match is None or not hasattr(value, match.group(1)):
            raise IngestError(path, f"{topic}.{spec}", f"message {index} "
                              f"({getattr(message, '__msgtype__', type(message).__name__)}) "
                              f"has no field {step!r} (a field is a message path such as "
                              "wrench.force.x; the shipped map spec_ros reads the spec topics)")
        value = getattr(value, match.group(1))
        key = match.group(2)
        if key is not None:
            value = _item(path, topic, spec, message, value, key, index)
    return value


def _item(path, topic, spec, message, array, key: str, index: int):
    """``array[key]``: by position, or by joint name (JointState's ``name`` list)."""
    if key.lstrip("-").isdigit():
        position = int(key)
    else:
        names = list(getattr(message, "name", []))
        if key not in names:
            raise IngestError(path, f"{topic}.{spec}", f"message {index}: no joint {key!r} "
                              f"(names: {', '.join(names) or 'none'})")
        position = names.index(key)
    if not -len(array) <= position < len(array):
        raise IngestError(path, f"{topic}.{spec}", f"message {index} holds {len(array)} "
                          f"values, no index {position}")
    return array[position]


def _start_ns(path: Path, records: dict, stamps: dict[str, list[int]]) -> int:
    """``run.started_at`` (sidecar) in ns since the epoch, else the earliest stamp."""
    started = records.get("run", {}).get("started_at")
    if started is None:
        return min(min(t) for t in stamps.values())
    try:
        when = datetime.fromisoformat(str(started).replace("Z", "+00:00"))
    except ValueError:
        raise IngestError(path, "run.started_at", f"{str(started)[:40]!r} is not an ISO 8601 "
                          "time") from None
    if when.tzinfo is None:
        when = when.replace(tzinfo=timezone.utc)
    delta = when - _EPOCH
    return (delta.days * 86400 + delta.seconds) * 1_000_000_000 + delta.microseconds * 1000
