"""Write a raw run in the spec's MCAP form: JSON blocks of samples, string metadata, zstd chunks."""

from __future__ import annotations

import base64
import json
from datetime import datetime
from pathlib import Path

import numpy as np
from mcap.writer import CompressionType, Writer

from swtlab_base.atomic import atomic_file
from virtual_testbed.measure import RawRun
from virtual_testbed.topics import TOPIC_FIELDS

LIBRARY = "swtlab virtual_testbed"
#: One chunk holds a whole sample run, so zstd sees all of it.
CHUNK_SIZE_BYTES = 4 * 1024 * 1024


def block_schema(topic: str) -> bytes:
    """JSON Schema of a block message: ``t_ns`` and every field as same-length arrays."""
    fields = TOPIC_FIELDS[topic]
    properties = {"t_ns": {"type": "array", "items": {"type": "integer"},
                           "description": "int64 ns since run start"}}
    properties.update({f: {"type": "array", "items": {"type": "number"}} for f in fields})
    schema = {"type": "object", "properties": properties, "required": ["t_ns", *fields]}
    return json.dumps(schema, separators=(",", ":")).encode()


def metadata_strings(record: dict) -> dict[str, str]:
    """MCAP metadata is string -> string: numbers in their shortest round-trip text."""
    return {k: v if isinstance(v, str) else repr(v) for k, v in record.items()}


def _blocks(raw: RawRun, topic: str):
    channel = raw.channels[topic]
    bounds = np.concatenate([[0], np.cumsum(raw.blocks[topic])])
    columns = {k: v.tolist() for k, v in channel.items()}
    for seq, (a, b) in enumerate(zip(bounds[:-1], bounds[1:])):  # one message per block
        message = {k: columns[k][a:b] for k in ("t_ns", *TOPIC_FIELDS[topic])}
        yield seq, int(channel["t_ns"][b - 1]), json.dumps(message, separators=(",", ":")).encode()


#: JSON Schema of foxglove.CompressedImage as the spec uses it (timestamp since run start)
IMAGE_SCHEMA = json.dumps({
    "type": "object", "title": "foxglove.CompressedImage",
    "properties": {"timestamp": {"type": "object", "properties": {
        "sec": {"type": "integer"}, "nsec": {"type": "integer"}}},
        "frame_id": {"type": "string"}, "format": {"type": "string"},
        "data": {"type": "string", "contentEncoding": "base64"}},
    "required": ["timestamp", "frame_id", "format", "data"]}, separators=(",", ":")).encode()


def _image_messages(topic: str, photos: list) -> list[tuple[int, bytes]]:
    frame_id = topic.strip("/").replace("/", "_")
    return [(p.t_ns, json.dumps({
        "timestamp": {"sec": p.t_ns // 1_000_000_000, "nsec": p.t_ns % 1_000_000_000},
        "frame_id": frame_id, "format": p.format,
        "data": base64.b64encode(p.data).decode()}, separators=(",", ":")).encode())
        for p in photos]


def write_mcap(raw: RawRun, path: Path) -> Path:
    """Write ``raw`` to ``path`` (``.mcap``); same input, same bytes."""
    started = datetime.fromisoformat(raw.metadata["run"]["started_at"].replace("Z", "+00:00"))
    epoch_ns = int(started.timestamp()) * 1_000_000_000
    messages = []
    with atomic_file(path, "wb") as stream:
        writer = Writer(stream, chunk_size=CHUNK_SIZE_BYTES, compression=CompressionType.ZSTD)
        writer.start(profile="", library=LIBRARY)
        for topic in raw.channels:
            schema_id = writer.register_schema(name=f"swt{topic.replace('/', '.')}.block",
                                               encoding="jsonschema", data=block_schema(topic))
            channel_id = writer.register_channel(topic=topic, message_encoding="json",
                                                 schema_id=schema_id)
            messages += [(t_ns, channel_id, seq, data) for seq, t_ns, data in _blocks(raw, topic)]
        for topic, photos in raw.images.items():
            schema_id = writer.register_schema(name="foxglove.CompressedImage",
                                               encoding="jsonschema", data=IMAGE_SCHEMA)
            channel_id = writer.register_channel(topic=topic, message_encoding="json",
                                                 schema_id=schema_id)
            messages += [(t_ns, channel_id, seq, data)
                         for seq, (t_ns, data) in enumerate(_image_messages(topic, photos))]
        for t_ns, channel_id, seq, data in sorted(messages, key=lambda m: m[:3]):
            writer.add_message(channel_id=channel_id, log_time=epoch_ns + t_ns, data=data,
                               publish_time=epoch_ns + t_ns, sequence=seq)
        for name, record in raw.metadata.items():
            writer.add_metadata(name=f"swt.{name}", data=metadata_strings(record))
        writer.finish()
    return path
