"""MCAP form reader (spec: "MCAP form"): JSON blocks of samples, metadata records, camera frames.

A topic whose blocks are objects of short numbers is parsed straight into arrays
(``_number_blocks``, ``ingest.json_blocks``); else one ``orjson.loads`` per block, each field
made an array at once (``_plain_blocks``); only a block that may hold more than numbers goes
through the sample-by-sample checks (``_checked_blocks``), which name the first problem.
"""

from __future__ import annotations

import array
import json
from io import BytesIO
from collections import defaultdict
from itertools import chain
from pathlib import Path

import numpy as np
import orjson
from mcap.reader import NonSeekingReader, make_reader
import lz4.frame
import zstandard
from mcap.data_stream import ReadDataStream
from mcap.opcode import Opcode
from mcap.records import Channel, Chunk, Message, Metadata, Schema
from mcap.stream_reader import StreamReader, breakup_chunk

from ingest.errors import IngestError
from ingest.json_blocks import FIELD_COLUMNS, parse_blocks
from ingest.raw import FrameIndex, RawRun, RawTopic

IMAGE_SCHEMA = "foxglove.CompressedImage"
IMAGE_TOPICS = ("/camera/side", "/camera/track")
_HINT = "the file is damaged or was cut short; re-export it (or try `mcap recover`)"


def read_mcap(path: Path, topics: set[str]) -> RawRun:
    """Raw topics (only those in ``topics``), ``swt.*`` records and image topics of one MCAP run;
    an MCAP cut short (no summary, no footer) gives what its whole records hold
    (:func:`_recover`)."""
    path = Path(path)
    cut = None
    try:
        with open(path, "rb") as stream:
            reader = make_reader(stream, validate_crcs=True)
            records = _swt_records(reader.iter_metadata())
            if not records:  # no metadata index in the summary: scan the file for the records
                stream.seek(0)
                scan = NonSeekingReader(stream, validate_crcs=True)
                records = _swt_records(scan.iter_metadata())
                stream.seek(0)
            blocks, images = _collect(path, topics, reader.iter_messages(log_time_order=False))
    except IngestError:
        raise
    except OSError as exc:
        raise IngestError(path, None, f"cannot read file: {exc.strerror or exc}") from None
    except Exception as exc:  # mcap raises many types for damaged files
        records, blocks, images = _recover(path, topics, exc)
        cut = CUT_MCAP
    raw_topics = {topic: _decode_blocks(path, topic, data) for topic, data in blocks.items()}
    frames = {topic: _frame_index(path, topic, data) for topic, data in images.items()}
    return RawRun(path=path, records=records, topics=raw_topics, frames=frames, cut_short=cut)


#: why an MCAP that ends before its summary looks cut short (``ingest.cut_short``)
CUT_MCAP = ("truncated MCAP: no summary and no footer (the logger stopped mid-write); the "
            "messages of its whole records are read")


def _collect(path: Path, topics: set[str], messages) -> tuple[dict, dict]:
    """Message data by topic (``topics`` only) and image messages by topic, from
    ``(schema, channel, message)`` triples."""
    blocks: dict[str, list[bytes]] = defaultdict(list)
    images: dict[str, list[bytes]] = defaultdict(list)
    for schema, channel, message in messages:
        if channel.topic in IMAGE_TOPICS or (schema is not None
                                             and schema.name == IMAGE_SCHEMA):
            images[channel.topic].append(message.data)
        elif channel.topic in topics:
            if channel.message_encoding != "json":
                raise IngestError(path, channel.topic, f"message encoding "
                                  f"{channel.message_encoding!r}; the spec form uses json")
            blocks[channel.topic].append(message.data)
    return blocks, images


def _recover(path: Path, topics: set[str], error: Exception) -> tuple[dict, dict, dict]:
    """Records, message data and images of an MCAP that ends before its summary and footer
    (a logger stopped mid-write): the file's records in order up to its end, and the whole
    records at the start of a chunk cut by the end (:func:`_cut_chunk`). A file whose
    reading fails before its end is damaged, not cut short: an IngestError naming ``error``."""
    size = path.stat().st_size
    found: list = []
    with open(path, "rb") as stream:
        done = stream.tell()
        try:
            for record in StreamReader(stream, emit_chunks=True, validate_crcs=True).records:
                found += breakup_chunk(record, True) if isinstance(record, Chunk) else [record]
                done = stream.tell()
            at_end = False  # a footer: the file is whole, the first reading failed elsewhere
        except Exception:
            at_end = stream.tell() >= size
            stream.seek(done)
            found += _cut_chunk(stream.read()) if at_end else []
    schemas = {r.id: r for r in found if isinstance(r, Schema)}
    channels = {r.id: r for r in found if isinstance(r, Channel)}
    if not at_end or not channels:
        raise IngestError(path, None, f"corrupt or truncated MCAP ({type(error).__name__}: "
                          f"{error}); {_HINT}")
    triples = [(schemas.get(channels[r.channel_id].schema_id), channels[r.channel_id], r)
               for r in found if isinstance(r, Message) and r.channel_id in channels]
    return (_swt_records(r for r in found if isinstance(r, Metadata)),
            *_collect(path, topics, triples))


def _cut_chunk(tail: bytes) -> list:
    """The whole schema, channel and message records at the start of a chunk record cut by
    the end of the file (``tail``: the bytes from the record's opcode); [] for other records.
    Layout: MCAP specification, "Chunk" (opcode 0x06)."""
    if tail[:1] != bytes([Opcode.CHUNK]):
        return []
    head = ReadDataStream(BytesIO(tail[9:]))
    try:
        head.read(28)  # message start and end time, uncompressed size and CRC
        compression = head.read(head.read4()).decode()
        head.read8()
        data = tail[9 + head.count:]
        if compression == "zstd":
            data = zstandard.ZstdDecompressor().decompressobj().decompress(data)
        elif compression == "lz4":
            data = lz4.frame.LZ4FrameDecompressor().decompress(data)
        elif compression:
            return []
    except Exception:
        return []
    out, at = [], 0
    readers = {Opcode.SCHEMA: Schema.read, Opcode.CHANNEL: Channel.read}
    while at + 9 <= len(data):
        opcode, length = data[at], int.from_bytes(data[at + 1:at + 9], "little")
        body = data[at + 9:at + 9 + length]
        if len(body) < length:
            break
        stream = ReadDataStream(BytesIO(body))
        if opcode == Opcode.MESSAGE:
            out.append(Message.read(stream, length))
        elif opcode in readers:
            out.append(readers[opcode](stream))
        at += 9 + length
    return out


def _swt_records(metadata) -> dict[str, dict[str, str]]:
    """``swt.*`` metadata records by name without the prefix (other records are not ours)."""
    return {m.name[4:]: dict(m.metadata) for m in metadata if m.name.startswith("swt.")}


def _loads(message: bytes):
    """orjson (several times faster on long numeric arrays); the standard library for what
    orjson refuses, such as the ``NaN``/``Infinity`` tokens the checks then report by channel."""
    try:
        return orjson.loads(message)
    except orjson.JSONDecodeError:
        try:
            return json.loads(message)
        except RecursionError:
            raise ValueError("nested too deeply") from None


def _decode_blocks(path: Path, topic: str, data: list[bytes]) -> RawTopic:
    """Concatenate a topic's blocks (ordered by their first time stamp) into field arrays:
    :func:`_number_blocks` or :func:`_plain_blocks` when they can, else every sample checked
    (:func:`_checked_blocks`)."""
    for decode in (_number_blocks, _plain_blocks):
        topic_arrays = decode(data)
        if topic_arrays is not None:
            return topic_arrays
    return _checked_blocks(path, topic, data)


def _number_blocks(data: list[bytes]) -> RawTopic | None:
    """:func:`_plain_blocks` without Python numbers: every block parsed by
    :func:`ingest.json_blocks.parse_blocks`; None where it declines or where
    :func:`_plain_blocks` would (a block without ``t_ns``, a key twice, other keys than the
    first block's, fields of different lengths, stamps not whole or out of range)."""
    if not data:
        return None
    sizes = np.fromiter(map(len, data), np.int64, len(data))
    stops = np.cumsum(sizes)
    starts = stops - sizes
    buf = b"".join(data)
    codes = np.frombuffer(buf, np.uint8)
    values, ints = np.empty(len(buf) // 2 + 1), np.empty(len(buf) // 2 + 1, np.int64)
    fields = np.empty((len(buf) // 5 + len(data), FIELD_COLUMNS), np.int64)
    rows = parse_blocks(codes, starts, stops, values, ints, fields)
    if rows < 0:
        return None
    names: list[str] | None = None
    spans: list[dict[str, tuple[int, int]]] = []
    for block, key, key_stop, first, stop, whole in fields[:rows].tolist():
        if block == len(spans):
            spans.append({})
        name = buf[key:key_stop].decode("ascii")
        if name in spans[-1] or (name == "t_ns" and not whole):
            return None
        spans[-1][name] = (first, stop)
    for block in spans:
        if names is None:
            names = list(block)
        sizes = {stop - first for first, stop in block.values()}
        if "t_ns" not in block or block.keys() != set(names) or len(sizes) != 1:
            return None
    firsts = [ints[b["t_ns"][0]] if b["t_ns"][1] > b["t_ns"][0] else np.iinfo(np.int64).max
              for b in spans]  # an empty block sorts last
    order = np.argsort(firsts, kind="stable")
    t_ns = np.concatenate([ints[slice(*spans[i]["t_ns"])] for i in order])
    if t_ns.size and not (0 <= t_ns.min() and t_ns.max() <= MAX_T_NS):
        return None
    return RawTopic(t_s=t_ns * 1e-9, fields={
        name: np.concatenate([values[slice(*spans[i][name])] for i in order])
        for name in names if name != "t_ns"})


def _plain_blocks(data: list[bytes]) -> RawTopic | None:
    """The blocks decoded one at a time (each made arrays while its JSON is in the cache, as
    the decode limit of ``bench/bench_ingest.py`` does); None at anything that is not a
    well-formed block of numbers (and null as NaN) with whole-ns time stamps in range, which
    :func:`_checked_blocks` then names. Same arrays as that path."""
    columns: dict[str, list[np.ndarray]] = {}
    for message in data:
        try:
            block = orjson.loads(message)
        except orjson.JSONDecodeError:
            return None
        if type(block) is not dict or "t_ns" not in block or not (
                _numbers_only(message, len(block)) and _whole_stamps(message)):
            return None
        if not columns:
            columns = {name: [] for name in block}
        elif block.keys() != columns.keys():
            return None
        try:
            arrays = {name: np.array(v, np.int64) if name == "t_ns" else _floats(v)
                      for name, v in block.items()}
        except (ValueError, TypeError, OverflowError):  # a list or null among the samples,
            return None                                 # a number beyond int64/float64
        size = arrays["t_ns"].shape
        if len(size) != 1 or any(a.shape != size for a in arrays.values()):
            return None
        for name, values in arrays.items():
            columns[name].append(values)
    if not columns:
        return None
    stamps = columns.pop("t_ns")
    big = np.iinfo(np.int64).max  # an empty block sorts last
    order = np.argsort([s[0] if len(s) else big for s in stamps], kind="stable")
    t_ns = np.concatenate([stamps[i] for i in order])
    if t_ns.size and not (0 <= t_ns.min() and t_ns.max() <= MAX_T_NS):
        return None
    return RawTopic(t_s=t_ns * 1e-9, fields={name: np.concatenate([parts[i] for i in order])
                                               for name, parts in columns.items()})


def _floats(values) -> np.ndarray:
    """A JSON list of numbers as float64 (null as NaN): through ``array.array`` (about twice
    as fast as ``np.array`` on a list of Python floats, the same doubles) unless it is no list
    or holds something else, which ``np.array`` then converts or refuses."""
    if type(values) is list:
        try:
            return np.frombuffer(array.array("d", values), np.float64)
        except (TypeError, OverflowError):
            pass
    return np.array(values, np.float64)


def _checked_blocks(path: Path, topic: str, data: list[bytes]) -> RawTopic:
    """:func:`_decode_blocks` with every block's structure and every sample's JSON type
    checked, naming the first problem."""
    blocks = []
    for i, message in enumerate(data):
        try:
            blocks.append(_loads(message))
        except (ValueError, UnicodeDecodeError) as exc:
            raise IngestError(path, topic, f"message {i} is not valid JSON ({exc}); "
                              f"{_HINT}") from None
    names: list[str] | None = None
    lengths = np.empty(len(blocks), dtype=np.int64)
    for i, block in enumerate(blocks):
        if not isinstance(block, dict) or "t_ns" not in block:
            raise IngestError(path, topic, f"message {i} is not a block with t_ns")
        if names is None:
            names = list(block)
        elif block.keys() != set(names):
            raise IngestError(path, topic, f"message {i} has fields {sorted(block)}, "
                              f"the first one {sorted(names)}")
        sizes = {k: len(v) if isinstance(v, list) else -1 for k, v in block.items()}
        if len(set(sizes.values())) != 1 or -1 in sizes.values():
            raise IngestError(path, topic, f"message {i}: field arrays of different lengths "
                              f"({', '.join(f'{k} {n}' for k, n in sizes.items())}); "
                              "every field of a block must have one value per t_ns")
        lengths[i] = sizes["t_ns"]
    total = int(lengths.sum())
    t_ns = _flatten(path, topic, "t_ns", blocks, total, np.int64)
    starts = np.concatenate([[0], np.cumsum(lengths)])
    firsts = np.full(len(blocks), np.iinfo(np.int64).max)  # an empty block sorts last
    firsts[lengths > 0] = t_ns[starts[:-1][lengths > 0]]
    order = np.argsort(firsts, kind="stable")  # blocks by their first time stamp
    if (order != np.arange(len(blocks))).any():
        blocks = [blocks[i] for i in order]
        t_ns = np.concatenate([t_ns[starts[i]:starts[i + 1]] for i in order])
    fields = {k: _flatten(path, topic, k, blocks, total, np.float64)
              for k in names if k != "t_ns"}
    return RawTopic(t_s=t_ns * 1e-9, fields=fields)


#: the bytes of JSON numbers and arrays of them (``e`` of ``true``/``false`` included)
_NUMBER_BYTES = b"0123456789+-.eE,[] \t\r\n"


def _numbers_only(message: bytes, keys: int) -> bool:
    """Whether a block's JSON of ``keys`` fields can hold nothing but numbers and null: what
    is left of it without the bytes of numbers (keys, punctuation, literals) has no string
    other than its keys (two quotes per key) and no ``true``/``false`` (a key with ``tru``,
    ``fals`` or an escaped quote merely sends the block through the checks sample by sample)."""
    rest = message.translate(None, _NUMBER_BYTES)
    return rest.count(b'"') == 2 * keys and b"tru" not in rest and b"fals" not in rest


#: the bytes of the whole numbers a t_ns list holds, and of the JSON around them
_WHOLE_BYTES = b"0123456789-:,[ \t\r\n"


def _whole_stamps(message: bytes) -> bool:
    """Whether a plain block's t_ns list (up to its first ``]``) has no decimal point,
    exponent or null: whole numbers, which int64 takes as they are (a list nested in it
    fails the conversion or the shape check)."""
    start = message.find(b'"t_ns"')  # not found: a key spelt with escapes
    stop = message.find(b"]", start)
    return 0 <= start < stop and not message[start + 6:stop].translate(None, _WHOLE_BYTES)


#: JSON types a sample may have: numbers, and null (how many writers spell NaN)
_SAMPLE_TYPES = {int, float, type(None)}
#: time stamps: whole nanoseconds from the run start, at most this many (a century)
MAX_T_NS = 100 * 365 * 86400 * 10**9


def _flatten(path: Path, topic: str, name: str, blocks: list[dict], total: int,
             dtype: type) -> np.ndarray:
    """One field of every block as one array, each sample checked (:func:`_checked`)."""
    return _checked(path, topic, name, list(chain.from_iterable(b[name] for b in blocks)),
                    total, dtype)


def _checked(path: Path, topic: str, name: str, values: list, total: int,
             dtype: type) -> np.ndarray:
    """:func:`_flatten` sample by sample: each sample's JSON type checked."""
    where = f"{topic}.{name}"
    kinds = set(map(type, values))
    if not kinds <= _SAMPLE_TYPES:
        bad = sorted(k.__name__ for k in kinds - _SAMPLE_TYPES)
        raise IngestError(path, where, f"samples of JSON type {', '.join(bad)}; every sample "
                          "must be a number (or null)")
    if dtype is np.int64:
        if kinds - {int}:
            raise IngestError(path, where, "time stamps must be whole numbers of ns (no "
                              "decimals, no null)")
        if values and not (0 <= min(values) and max(values) <= MAX_T_NS):
            raise IngestError(path, where, f"time stamps outside 0..{MAX_T_NS} ns (t_ns counts "
                              "ns from the run start)")
        return np.array(values, dtype=np.int64)
    if type(None) in kinds:
        values = [np.nan if v is None else v for v in values]
    try:
        return np.fromiter(values, dtype=np.float64, count=total)
    except OverflowError:
        raise IngestError(path, where, "a sample is beyond the float64 range") from None


def _frame_index(path: Path, topic: str, data: list[bytes]) -> FrameIndex:
    """Frame times from ``foxglove.CompressedImage`` messages (the images are not decoded)."""
    t_s = np.full(len(data), np.nan)
    for i, message in enumerate(data):
        try:
            stamp = json.loads(message)["timestamp"]
            t_s[i] = float(stamp["sec"]) + float(stamp["nsec"]) * 1e-9
        except (ValueError, KeyError, TypeError):
            raise IngestError(path, topic, f"frame {i} has no timestamp {{sec, nsec}}") from None
    return FrameIndex(topic=topic, t_s=t_s, source=path)
