"""A spec-form MCAP file as plain data (messages and metadata records) and back, so a bench or
a test can change one thing in a real run and write it again. Independent of ``ingest``."""

from __future__ import annotations

import json
from dataclasses import dataclass, field
from pathlib import Path

from mcap.reader import make_reader
from mcap.writer import Writer


@dataclass
class Message:
    """One message: its channel (topic, encodings, schema) and its bytes."""

    topic: str
    message_encoding: str
    schema_name: str
    schema_encoding: str
    schema_data: bytes
    log_time: int
    data: bytes


@dataclass
class McapContent:
    """Every message in file order and every metadata record (name -> {key: text})."""

    messages: list[Message] = field(default_factory=list)
    metadata: dict[str, dict[str, str]] = field(default_factory=dict)

    def blocks(self, topic: str) -> list[dict]:
        """The decoded JSON blocks of ``topic``, in file order."""
        return [json.loads(m.data) for m in self.messages if m.topic == topic]

    def set_blocks(self, topic: str, blocks: list[dict]) -> None:
        """Replace the blocks of ``topic`` (same number, in file order) by ``blocks``."""
        mine = [m for m in self.messages if m.topic == topic]
        if len(mine) != len(blocks):
            raise ValueError(f"{topic}: {len(mine)} messages, {len(blocks)} blocks given")
        for message, block in zip(mine, blocks):
            message.data = json.dumps(block).encode()


def read_content(path: str | Path) -> McapContent:
    """Messages and metadata of an MCAP file."""
    out = McapContent()
    with open(path, "rb") as stream:
        reader = make_reader(stream)
        for schema, channel, message in reader.iter_messages(log_time_order=False):
            out.messages.append(Message(
                topic=channel.topic, message_encoding=channel.message_encoding,
                schema_name=schema.name if schema else "", schema_encoding=(
                    schema.encoding if schema else ""), schema_data=schema.data if schema else b"",
                log_time=message.log_time, data=bytes(message.data)))
        for record in reader.iter_metadata():
            out.metadata[record.name] = dict(record.metadata)
    return out


def write_content(path: str | Path, content: McapContent) -> Path:
    """Write ``content`` as an MCAP file (one channel per topic, chunked)."""
    path = Path(path)
    with open(path, "wb") as stream:
        writer = Writer(stream, chunk_size=64 * 1024)
        writer.start(profile="", library="swtlab-bench")
        channels: dict[str, int] = {}
        for m in content.messages:
            if m.topic not in channels:
                schema = writer.register_schema(name=m.schema_name, encoding=m.schema_encoding,
                                                data=m.schema_data)
                channels[m.topic] = writer.register_channel(
                    topic=m.topic, message_encoding=m.message_encoding, schema_id=schema)
            writer.add_message(channel_id=channels[m.topic], log_time=m.log_time, data=m.data,
                               publish_time=m.log_time)
        for name, values in content.metadata.items():
            writer.add_metadata(name=name, data={k: str(v) for k, v in values.items()})
        writer.finish()
    return path
