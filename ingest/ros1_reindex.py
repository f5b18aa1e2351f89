"""A ROS 1 bag cut short (``rosbag record`` killed, a copy interrupted) has no index: its
header's ``index_pos`` is 0 or lies beyond the file's end. ``reindexed`` writes the messages
of its chunks, up to the last whole record of the chunk the end cut, into an indexed copy
that ``rosbags`` reads (what ``rosbag reindex`` does). Layout: ROS bag format 2.0
(wiki.ros.org/Bags/Format/2.0)."""

from __future__ import annotations

import bz2
from io import BytesIO
from pathlib import Path

import lz4.frame

from ingest.errors import IngestError

#: why a ROS 1 bag without its index looks cut short (``ingest.cut_short``)
CUT_BAG = ("ROS 1 bag without its index (the recorder stopped mid-write); the messages of its "
           "whole chunks and records are read")
_HEADER_BYTES = 4096  # the bag header record, padded (ROS bag format 2.0)


def needs_reindex(path: Path) -> bool:
    """True when the bag header's ``index_pos`` is 0 (never closed) or beyond the file's end."""
    from rosbags.rosbag1.reader import Header, RecordType

    with open(path, "rb") as src:
        src.readline()
        try:
            index_pos = Header.read(src, RecordType.BAGHEADER).get_uint64("index_pos")
        except Exception:
            return False
    return index_pos == 0 or index_pos >= path.stat().st_size


def reindexed(path: Path, copy: Path) -> Path:
    """An indexed copy of the whole records of the bag ``path`` at ``copy``."""
    from rosbags.rosbag1 import Writer

    connections, messages = _scan(path)
    if not connections:
        raise IngestError(path, None, f"ROS 1 bag without its index and without a whole "
                          f"connection record: {CUT_BAG.split(';')[0]}, nothing to read")
    with Writer(copy) as writer:
        made = {cid: writer.add_connection(*args, **kwargs)
                for cid, (args, kwargs) in connections.items()}
        for cid, time_ns, data in messages:
            if cid in made:
                writer.write(made[cid], time_ns, data)
    return copy


_DECOMPRESSORS = {"none": lambda: None, "bz2": bz2.BZ2Decompressor,
                  "lz4": lz4.frame.LZ4FrameDecompressor}


def _scan(path: Path) -> tuple[dict, list]:
    """Connections (id -> Writer.add_connection arguments) and ``(id, time ns, data)`` of the
    messages in the bag's records, in file order, up to where the file ends."""
    from rosbags.rosbag1.reader import RecordType

    connections: dict = {}
    messages: list = []
    with open(path, "rb") as src:
        src.seek(_HEADER_BYTES + len(src.readline()))
        while True:
            header, data, whole = _record(src)
            if header is None:
                break
            op = header.get_uint8("op")
            if op == RecordType.CHUNK:
                make = _DECOMPRESSORS.get(header.get_string("compression"))
                if make is None:
                    break
                decompressor = make()
                try:
                    inner = data if decompressor is None else decompressor.decompress(data)
                except Exception:
                    break
                _inner(BytesIO(inner), connections, messages)
            elif op == RecordType.CONNECTION and whole:
                _connection(header, data, connections)
            if not whole:
                break
    return connections, messages


def _record(src):
    """(header, data, whole) of the record at ``src``; header None at the end of the file;
    ``whole`` False when the end cuts the record's data."""
    from rosbags.rosbag1.reader import Header, read_uint32

    try:
        header = Header.read(src)
        size = read_uint32(src)
    except Exception:
        return None, b"", False
    data = src.read(size)
    return header, data, len(data) == size


def _inner(bio: BytesIO, connections: dict, messages: list) -> None:
    """The connection and message records of a chunk's data (up to its last whole one)."""
    from rosbags.rosbag1.reader import RecordType

    while True:
        header, data, whole = _record(bio)
        if header is None or not whole:
            return
        op = header.get_uint8("op")
        if op == RecordType.CONNECTION:
            _connection(header, data, connections)
        elif op == RecordType.MSGDATA:
            messages.append((header.get_uint32("conn"), header.get_time("time"), data))


def _connection(header, data: bytes, connections: dict) -> None:
    """A connection record (its data: the connection header's fields) as the arguments of
    ``Writer.add_connection``."""
    from rosbags.rosbag1.reader import Header
    from rosbags.typesys.msg import normalize_msgtype

    cid = header.get_uint32("conn")
    if cid in connections:
        return
    fields = Header.read(BytesIO(len(data).to_bytes(4, "little") + data))
    kwargs = {"msgdef": fields.get_string("message_definition"),
              "md5sum": fields.get_string("md5sum")}
    for key in ("callerid", "latching"):
        if key in fields:
            value = fields.get_string(key)
            kwargs[key] = int(value) if key == "latching" and value else value
    connections[cid] = ((header.get_string("topic"), normalize_msgtype(fields.get_string("type"))),
                        kwargs)
