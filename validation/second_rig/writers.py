"""Raw runs to disk in the raw-run spec's two forms, atomically.

MCAP: one file, JSON messages with a ``jsonschema`` schema per topic, each message a block of
samples (random lengths, some of one sample), ``swt.*`` metadata records of strings (written
with the ``mcap`` library). CSV: a folder with ``run.json`` and one ``<topic>.csv`` per topic
(``t_s`` first). Both are built in ``<staging>/`` and moved into place with one rename.
"""

from __future__ import annotations

import json
import os
import shutil
import tempfile
from pathlib import Path

import numpy as np
from mcap.writer import CompressionType, Writer

FILE_MODE = 0o644  # temporary files are created 0600; the runs are meant to be shared


def _blocks(n: int, rng: np.random.Generator, mean_samples: int) -> list[tuple[int, int]]:
    """Consecutive ``(start, stop)`` blocks of 1 to 2x ``mean_samples``, 5 % single samples."""
    out, start = [], 0
    while start < n:
        size = 1 if rng.random() < 0.05 else int(rng.integers(mean_samples, 2 * mean_samples))
        out.append((start, min(n, start + size)))
        start += size
    return out


def _text(value) -> str:
    return repr(float(value)) if isinstance(value, float | np.floating) else str(value)


def write_mcap(path: Path, topics: dict, records: dict, rng: np.random.Generator,
               staging: Path, block_s: float = 0.8) -> Path:
    """One MCAP run at ``path``; ``topics``: topic -> ``{"t_ns": int64, field: array}``."""
    messages = []
    with tempfile.NamedTemporaryFile(dir=staging, suffix=".mcap", delete=False) as stream:
        writer = Writer(stream, compression=CompressionType.ZSTD)
        writer.start(profile="", library="swtlab-second-rig")
        for topic, fields in topics.items():
            schema = {"type": "object", "properties": {
                k: {"type": "array", "items": {"type": "integer" if k == "t_ns" else "number"}}
                for k in fields}}
            schema_id = writer.register_schema(name="swt" + topic.replace("/", "."),
                                               encoding="jsonschema",
                                               data=json.dumps(schema).encode())
            channel_id = writer.register_channel(topic=topic, message_encoding="json",
                                                 schema_id=schema_id)
            t_ns = fields["t_ns"]
            rate_hz = len(t_ns) / max((t_ns[-1] - t_ns[0]) * 1e-9, 1e-9)
            for start, stop in _blocks(len(t_ns), rng, max(1, int(block_s * rate_hz))):
                block = {k: v[start:stop].tolist() for k, v in fields.items()}
                messages.append((int(t_ns[start]), channel_id, json.dumps(block).encode()))
        for log_time, channel_id, data in sorted(messages, key=lambda m: (m[0], m[1])):
            writer.add_message(channel_id=channel_id, log_time=log_time, data=data,
                               publish_time=log_time)
        for name, values in records.items():
            writer.add_metadata(name=f"swt.{name}", data={k: _text(v) for k, v in values.items()})
        writer.finish()
    os.chmod(stream.name, FILE_MODE)
    os.replace(stream.name, path)
    return path


def write_csv_folder(folder: Path, topics: dict, records: dict, staging: Path) -> Path:
    """One CSV-form run folder at ``folder`` (replaced whole if it exists)."""
    tmp = Path(tempfile.mkdtemp(dir=staging))
    tmp.chmod(0o755)
    (tmp / "run.json").write_text(json.dumps(records, indent=1))
    for topic, fields in topics.items():
        names = [k for k in fields if k != "t_ns"]
        table = np.column_stack([fields["t_ns"] * 1e-9] + [fields[k] for k in names])
        row = ",".join(["%.9f"] + ["%.10g"] * len(names)) + "\n"
        # what numpy.savetxt writes with these formats, a row per %-formatting of Python
        # floats (savetxt formats numpy scalars row by row: a third of a campaign's time)
        (tmp / (topic.strip("/").replace("/", "_") + ".csv")).write_text(
            ",".join(["t_s", *names]) + "\n" + "".join(row % tuple(r) for r in table.tolist()),
            encoding="latin-1")
    if folder.exists():
        shutil.rmtree(folder)
    os.replace(tmp, folder)
    return folder


def write_json(path: Path, document: dict, staging: Path) -> Path:
    """A JSON file written whole or not at all."""
    with tempfile.NamedTemporaryFile("w", dir=staging, suffix=".json", delete=False) as f:
        json.dump(document, f, indent=1)
    os.chmod(f.name, FILE_MODE)
    os.replace(f.name, path)
    return path
