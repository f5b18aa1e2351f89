"""Seeded hostile inputs for the reliability bench: real runs mutated one thing at a time.

The corpus: runs written by the virtual testbed (the committed sample campaign: MCAP files
and CSV run folders; in-family, same writer as the spec) and real CMU motion logs read
through their channel map (independent). Each case changes one of: MCAP bytes, one JSON
block, one whole channel (scaled, negated, offset, flat, clipped, spiked, frozen), one
metadata value, one CSV cell or line, one ``run.json`` value, one channel-map key,
one channel or the bytes of the run written as HDF5, MATLAB, TDMS or a ROS bag,
or cuts a CMU file short, to a value from a list of known-hostile ones (huge, tiny,
non-finite, wrong-typed, nested, math text, paths outside the run) or a random one.
``case(seed, i)`` is the same input on every machine.
"""

from __future__ import annotations

import json
import re
import shutil
from dataclasses import dataclass
from functools import lru_cache
from pathlib import Path
from typing import Callable

import numpy as np

from bench.mcap_content import McapContent, read_content, write_content

ROOT = Path(__file__).resolve().parents[1]
SAMPLE = ROOT / "sample_data" / "campaign"
MCAP_RUNS = ("L070_MP0_SC_s+010", "L180_MP0_SC_s+020", "L300_MP1_SC_s+060",
             "L180_MP0_SC_s+090", "L180_MP0_ST_s+020_b10")
CSV_RUNS = ("L070_MP0_FS", "L180_MP0_TW")
CMU_MAP = "cmu_3d_terramechanics"
CMU_LINES = 2500  # CMU logs cut to their first 30 s or so: fast, still a stable phase
MAPS = ROOT / "ingest" / "channel_maps"

#: JSON texts of hostile samples
HOSTILE_JSON = ("1" + "0" * 400, "-1" + "0" * 400, "1e308", "-1e308", "1e-300", "Infinity",
                "-Infinity", "NaN", str(2**63), str(-2**63 - 1), "0", "-0.0", "true", "false",
                "null", '"1.5"', '"x"', "[]", "{}", "[[1]]", "1.5", "-1", "3e5", "-9e5")
#: metadata texts (MCAP records are text; run.json takes the JSON forms above)
HOSTILE_TEXT = ("1e18", "1" + "0" * 400, "-1e308", "1e-300", "nan", "inf", "-inf", "", " ",
                "x", "-5", "0", "1e999", r"run $\frac{$ x", "A" * 5000, "0x10", "1_000",
                "1800", "3.0", "0.005", "500", "0.2", "-0.1", "2", "speed_control", "towed",
                "2026-13-45T99:00", "../../etc/passwd")
#: TOML values for channel-map keys
HOSTILE_TOML = ('"x"', "5", "-1", "1000000000", "1e308", "-1e308", "inf", "nan", "true",
                "[]", "[1, 2]", "{a = 1}", '"/etc/passwd"', '"../../../../etc/passwd"', "0",
                '"$\\\\frac{$"', "1e-300", '""')
CSV_CELLS = ("", "x", "nan", "inf", "-inf", "1e400", "1" + "0" * 400, "True", "1,5", '"',
             "0x1F", "1e-300", "-1e308", "   ", "1.5.5")


@dataclass(frozen=True)
class Case:
    """One input: ``kind`` (what was mutated), ``how`` (which of the kind's mutations),
    ``what`` (the mutation in full), and ``write(folder)``, which writes it under ``folder``
    and returns (run path, channel map or None)."""

    kind: str
    how: str
    what: str
    write: Callable[[Path], tuple[Path, str | None]]


@lru_cache(maxsize=None)
def _mcap(run_id: str) -> bytes:
    return (SAMPLE / f"{run_id}.mcap").read_bytes()


@lru_cache(maxsize=None)
def _content(run_id: str) -> McapContent:
    return read_content(SAMPLE / f"{run_id}.mcap")


def _fresh(run_id: str) -> McapContent:
    base = _content(run_id)
    return McapContent(messages=[type(m)(**vars(m)) for m in base.messages],
                       metadata={k: dict(v) for k, v in base.metadata.items()})


@lru_cache(maxsize=None)
def cmu_files() -> tuple[Path, ...]:
    root = Path("/work/shared/data/cmu-3d-terramechanics/raw")
    if not root.is_dir():
        root = ROOT.parent / "shared" / "data" / "cmu-3d-terramechanics" / "raw"
    return tuple(sorted(root.rglob("10_*_*_*.txt"))) if root.is_dir() else ()


def _pick(rng: np.random.Generator, items):
    return items[int(rng.integers(len(items)))]


def _mcap_bytes(rng, run_id: str) -> Case:
    data = bytearray(_mcap(run_id))
    how = _pick(rng, ("flip", "cut", "insert", "zero"))
    at = int(rng.integers(len(data)))
    if how == "flip":
        for i in rng.integers(len(data), size=int(rng.integers(1, 9))):
            data[int(i)] ^= int(rng.integers(1, 256))
    elif how == "cut":
        del data[at:]
    elif how == "insert":
        data[at:at] = rng.bytes(int(rng.integers(1, 64)))
    else:
        data[at:at + int(rng.integers(1, 256))] = bytes(min(255, len(data) - at))

    def write(folder: Path):
        path = folder / f"{run_id}.mcap"
        path.write_bytes(bytes(data))
        return path, None
    return Case("mcap_bytes", how, f"{run_id}: {how} at {at}", write)


def _sensor_messages(content: McapContent) -> list[int]:
    return [i for i, m in enumerate(content.messages) if m.message_encoding == "json"
            and not m.topic.startswith("/camera")]


def _json_block(rng, run_id: str) -> Case:
    content = _fresh(run_id)
    index = _pick(rng, _sensor_messages(content))
    message = content.messages[index]
    block = json.loads(message.data)
    how = _pick(rng, ("sample", "sample", "t_ns", "drop_key", "add_key", "short", "payload",
                      "scale", "swap_t"))
    value = _pick(rng, HOSTILE_JSON)
    names = [k for k in block if k != "t_ns"] or ["t_ns"]
    name = _pick(rng, names)
    if how in ("sample", "t_ns"):
        key = "t_ns" if how == "t_ns" else name
        if block[key]:
            block[key][int(rng.integers(len(block[key])))] = "@HOSTILE@"
        text = json.dumps(block).replace('"@HOSTILE@"', value)
    elif how == "drop_key":
        block.pop(_pick(rng, list(block)))
        text = json.dumps(block)
    elif how == "add_key":
        block["extra"] = [0.0] * len(block["t_ns"])
        text = json.dumps(block)
    elif how == "short":
        block[name] = block[name][:-1]
        text = json.dumps(block)
    elif how == "payload":
        value = _pick(rng, ("[" * 100_000, "{}", "null", "1e999", "[]", '{"t_ns": []}',
                            rng.bytes(32).hex(), '{"t_ns": 5}', "{" * 50_000))
        text = value
    elif how == "scale":
        block[name] = (np.asarray(block[name], float)
                       * float(_pick(rng, (1e300, -1e300, 1e-300, 0.0)))).tolist()
        text = json.dumps(block)
    else:
        block["t_ns"] = block["t_ns"][::-1]
        text = json.dumps(block)
    message.data = text.encode()

    def write(folder: Path):
        return write_content(folder / f"{run_id}.mcap", content), None
    return Case("json_block", how, f"{run_id} {message.topic}: {how} {name} = {value[:24]}",
                write)


def _channel(rng, run_id: str) -> Case:
    """A whole channel made wrong but finite: scaled, negated, offset, flat, clipped,
    spiked or frozen part way (a unit slip, a sign error, a dead or saturating sensor)."""
    content = _fresh(run_id)
    topic = _pick(rng, sorted({content.messages[i].topic for i in _sensor_messages(content)}))
    blocks = content.blocks(topic)
    name = _pick(rng, [k for k in blocks[0] if k != "t_ns"])
    y = np.concatenate([np.asarray(b[name], float) for b in blocks])
    how = _pick(rng, ("scale", "negate", "offset", "flat", "clip", "spikes", "freeze"))
    if how == "scale":
        y = y * float(_pick(rng, (10.0, 0.1, 1000.0, 1e-3, 4.448, 0.0254)))
    elif how == "negate":
        y = -y
    elif how == "offset":
        y = y + float(_pick(rng, (-1.0, 1.0, -100.0, 100.0, -1e4)))
    elif how == "flat":
        y = np.full_like(y, float(_pick(rng, (0.0, float(np.median(y)), -1.0))))
    elif how == "clip":
        y = np.clip(y, None, np.percentile(y, float(rng.uniform(5, 95))))
    elif how == "spikes":
        at = rng.integers(len(y), size=int(rng.integers(1, 20)))
        y[at] = y[at] + float(_pick(rng, (1e3, -1e3, 1e5)))
    else:
        y[int(rng.integers(len(y))):] = y[0]
    start = 0
    for b in blocks:
        b[name] = y[start:start + len(b[name])].tolist()
        start += len(b[name])
    content.set_blocks(topic, blocks)

    def write(folder: Path):
        return write_content(folder / f"{run_id}.mcap", content), None
    return Case("channel", how, f"{run_id} {topic}.{name}: {how}", write)


def _metadata(rng, run_id: str) -> Case:
    content = _fresh(run_id)
    record = _pick(rng, sorted(content.metadata))
    values = content.metadata[record]
    how = _pick(rng, ("set", "set", "set", "drop", "new", "drop_record"))
    key = _pick(rng, sorted(values)) if values else "x"
    value = _pick(rng, HOSTILE_TEXT)
    if how == "set":
        values[key] = value
    elif how == "drop":
        values.pop(key, None)
    elif how == "new":
        record = _pick(rng, ("swt.zero", "swt.calibration", "swt.camera", "swt.wheel"))
        key = _pick(rng, ("ty", "fz", "/hub/wrench.fz.gain", "/tether/force.dp.offset",
                          "px_per_m", "mass_kg", "stiffness_N_per_mm"))
        content.metadata.setdefault(record, {})[key] = value
    else:
        del content.metadata[record]

    def write(folder: Path):
        return write_content(folder / f"{run_id}.mcap", content), None
    return Case("metadata", how, f"{run_id} {record}.{key}: {how} {value[:24]!r}", write)


def _copy_csv_run(run_id: str, folder: Path) -> Path:
    return Path(shutil.copytree(SAMPLE / run_id, folder / run_id))


def _csv_cell(rng, run_id: str) -> Case:
    files = sorted(p.name for p in (SAMPLE / run_id).glob("*.csv"))
    name = _pick(rng, files)
    lines = (SAMPLE / run_id / name).read_text().splitlines()
    how = _pick(rng, ("cell", "cell", "drop_line", "cut", "header", "junk_line"))
    row = int(rng.integers(len(lines)))
    if how == "cell":
        cells = lines[row].split(",")
        cells[int(rng.integers(len(cells)))] = _pick(rng, CSV_CELLS)
        lines[row] = ",".join(cells)
    elif how == "drop_line":
        del lines[row]
    elif how == "cut":
        lines = lines[:row]
    elif how == "header":
        lines[0] = lines[0].replace(_pick(rng, lines[0].split(",")), _pick(rng, CSV_CELLS), 1)
    else:
        lines.insert(row, rng.bytes(24).hex())

    def write(folder: Path):
        path = _copy_csv_run(run_id, folder)
        (path / name).write_text("\n".join(lines) + "\n")
        return path, None
    return Case("csv_cell", how, f"{run_id}/{name}: {how} line {row}", write)


def _run_json(rng, run_id: str) -> Case:
    meta = json.loads((SAMPLE / run_id / "run.json").read_text())
    record = _pick(rng, sorted(meta))
    key = _pick(rng, sorted(meta[record]))
    how = _pick(rng, ("set", "set", "drop", "text"))
    value = _pick(rng, HOSTILE_JSON)
    if how == "set":
        meta[record][key] = "@HOSTILE@"
        text = json.dumps(meta).replace('"@HOSTILE@"', value)
    elif how == "drop":
        del meta[record][key]
        text = json.dumps(meta)
    else:
        text = _pick(rng, ("[" * 100_000, "", "{", "null", '{"run": 5}', "[]",
                           json.dumps(meta)[:int(rng.integers(1, 200))]))

    def write(folder: Path):
        path = _copy_csv_run(run_id, folder)
        (path / "run.json").write_text(text)
        return path, None
    return Case("run_json", how, f"{run_id} {record}.{key}: {how} {value[:24]}", write)


def _channel_map(rng) -> Case:
    """A key of the CMU map (on a CMU log) or of the spec map (on a CSV run folder)."""
    on_cmu = bool(cmu_files()) and rng.random() < 0.5
    text = (MAPS / (f"{CMU_MAP}.toml" if on_cmu else "spec.toml")).read_text()
    keys = [m.start() for m in re.finditer(r"(?m)^[a-z_\"\.]+ = ", text)]
    at = _pick(rng, keys)
    end = text.index("\n", at)
    key = text[at:text.index(" = ", at)]
    how = _pick(rng, ("set", "set", "set", "drop", "csv_file"))
    value = _pick(rng, HOSTILE_TOML)
    if how == "set":
        text = text[:at] + f"{key} = {value}" + text[end:]
    elif how == "drop":
        text = text[:at] + text[end:]
    else:
        first = text.index("[[channels]]")
        text = text[:first] + text[first:].replace(
            "[[channels]]\n", f"[[channels]]\ncsv_file = {_pick(rng, HOSTILE_TOML)}\n", 1)
    source = _pick(rng, cmu_files()) if on_cmu else None
    run_id = _pick(rng, CSV_RUNS)

    def write(folder: Path):
        cmap = folder / "map.toml"
        cmap.write_text(text)
        if source is not None:
            path = folder / source.name
            path.write_text("".join(source.read_text().splitlines(True)[:CMU_LINES]))
            return path, str(cmap)
        return _copy_csv_run(run_id, folder), str(cmap)
    return Case("channel_map", how, f"{'cmu' if on_cmu else 'spec'} map: {how} {key} = {value}",
                write)


def _format_file(rng, run_id: str) -> Case:
    """The run written as HDF5, MAT v5/v7.3, TDMS or a ROS bag (bench.format_files), then one
    channel made hostile (non-finite, huge, one sample short) or the file's bytes damaged."""
    from bench import format_files

    fmt = _pick(rng, sorted(format_files.WRITERS))
    writer, cmap = format_files.WRITERS[fmt]
    run = format_files.read_spec_mcap(SAMPLE / f"{run_id}.mcap")
    how = _pick(rng, ("channel", "bytes", "cut"))
    topic = _pick(rng, sorted(run.topics))
    field = _pick(rng, sorted(set(run.topics[topic]) - {"t_ns"}))
    what = f"{run_id} as {fmt}: {how}"
    if how == "channel":
        values = run.topics[topic][field]
        hostile = _pick(rng, ("nan", "inf", "huge", "short", "spike"))
        if hostile == "short":
            run.topics[topic][field] = values[:-1]
        else:
            value = {"nan": np.nan, "inf": np.inf, "huge": 1e308, "spike": 1e6}[hostile]
            at = rng.integers(len(values), size=max(1, len(values) // int(rng.integers(1, 50))))
            values[at] = value
        what += f" {topic}.{field} {hostile}"
    cut = float(rng.uniform(0.05, 0.95))
    at = int(rng.integers(1 << 30))

    def write(folder: Path):
        path = writer(run, folder)
        target = path if path.is_file() else max(
            (p for p in path.iterdir() if p.suffix != ".yaml"), key=lambda p: p.stat().st_size)
        data = bytearray(target.read_bytes())
        if how == "cut":
            del data[int(cut * len(data)):]
        elif how == "bytes":
            i = at % max(1, len(data) - 8)
            data[i:i + 8] = bytes(b ^ 0xFF for b in data[i:i + 8])
        target.write_bytes(bytes(data))
        return path, cmap
    return Case("format_file", how, what, write)


def _cmu_file(rng) -> Case:
    source = _pick(rng, cmu_files())
    lines = source.read_text().splitlines(True)[:CMU_LINES]
    how = _pick(rng, ("cut", "cell", "junk", "cell"))
    if how == "cut":
        lines = lines[:int(rng.integers(0, 6))]
    elif how == "cell":
        row = int(rng.integers(len(lines)))
        cells = lines[row].rstrip("\n").split(",")
        cells[int(rng.integers(len(cells)))] = _pick(rng, CSV_CELLS)
        lines[row] = ",".join(cells) + "\n"
    else:
        lines.insert(int(rng.integers(len(lines))), rng.bytes(20).hex() + "\n")

    def write(folder: Path):
        path = folder / source.name
        path.write_text("".join(lines))
        return path, CMU_MAP
    return Case("cmu_file", how, f"{source.parent.name}/{source.name}: {how}", write)


#: case kinds and their weights
KINDS = (("mcap_bytes", 2), ("json_block", 4), ("channel", 2), ("metadata", 4),
         ("csv_cell", 2), ("run_json", 2), ("channel_map", 2), ("cmu_file", 1),
         ("format_file", 2))


def case(seed: int, index: int) -> Case:
    """The ``index``-th input of the seeded sequence ``seed``."""
    rng = np.random.default_rng([seed, index])
    kinds = [k for k, _ in KINDS if k != "cmu_file" or cmu_files()]
    weights = np.array([w for k, w in KINDS if k in kinds], float)
    kind = kinds[int(rng.choice(len(kinds), p=weights / weights.sum()))]
    if kind == "mcap_bytes":
        return _mcap_bytes(rng, _pick(rng, MCAP_RUNS))
    if kind == "json_block":
        return _json_block(rng, _pick(rng, MCAP_RUNS))
    if kind == "channel":
        return _channel(rng, _pick(rng, MCAP_RUNS))
    if kind == "metadata":
        return _metadata(rng, _pick(rng, MCAP_RUNS))
    if kind == "csv_cell":
        return _csv_cell(rng, _pick(rng, CSV_RUNS))
    if kind == "run_json":
        return _run_json(rng, _pick(rng, CSV_RUNS))
    if kind == "channel_map":
        return _channel_map(rng)
    if kind == "format_file":
        return _format_file(rng, _pick(rng, MCAP_RUNS))
    return _cmu_file(rng)
