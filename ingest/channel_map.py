"""Channel maps: TOML files that tell ingest a lab's names, columns and units (docs/channel-map.md).

The spec form itself is the shipped map ``spec``; ``cmu_3d_terramechanics`` reads
the CMU motion logs and the rig's bags.
"""

from __future__ import annotations

import os
import re
import tomllib
from dataclasses import dataclass, field, replace
from functools import lru_cache
from importlib import resources
from pathlib import Path
from typing import Any

from ingest import units
from ingest.canonical import CANONICAL, DERIVED
from ingest.errors import IngestError

FORMATS = ("spec", "delimited")
_TOP_KEYS = {"map", "files", "time", "channels", "metadata"}
_CHANNEL_KEYS = {"column", "topic", "field", "unit", "required", "csv_file", "csv_column",
                 "scale", "offset", "zero", "zero_value", "stamp"}
_FILES_KEYS = {"pattern", "delimiter", "header_rows", "columns", "stream", "comment"}


@dataclass(frozen=True)
class ChannelSpec:
    """One source field feeding one canonical column: ``si = unit(scale*raw + offset)``.

    ``zero = "first"`` shifts the channel so its first finite sample reads
    ``zero_value`` (both in the channel's own unit) before conversion.
    """

    column: str
    topic: str
    field: str
    unit: str
    required: bool = False
    csv_file: str | None = None
    csv_column: str | None = None
    scale: float = 1.0
    offset: float = 0.0
    zero: str | None = None
    zero_value: float = 0.0
    stamp: str | None = None  # ROS: message path of the time stamp (default header.stamp)

    @property
    def csv_name(self) -> str:
        """CSV file of the topic (spec: slashes to underscores, leading one dropped)."""
        return self.csv_file or self.topic.strip("/").replace("/", "_") + ".csv"

    @property
    def si_unit(self) -> units.Unit:
        return units.lookup(self.unit)


@dataclass(frozen=True)
class FilenameField:
    """A metadata value taken from a regex group of the run's file name."""

    key: str  # "<record>.<key>", e.g. "run.velocity_mps"
    group: str
    unit: str | None = None
    omit_if: float | None = None
    also: dict[str, Any] = field(default_factory=dict)


@dataclass(frozen=True)
class ChannelMap:
    """A parsed, checked channel map."""

    name: str
    path: Path
    format: str
    channels: tuple[ChannelSpec, ...]
    time_column: str = "t_s"
    time_unit: str = "s"
    file_pattern: str | None = None
    delimiter: str = ","
    header_rows: int = 0
    columns: tuple[str, ...] = ()
    comment: str | None = None
    stream: str = "delimited"
    metadata_defaults: dict[str, dict[str, Any]] = field(default_factory=dict)
    filename_regex: str | None = None
    filename_fields: tuple[FilenameField, ...] = ()
    run_id_parts: int = 1
    description: str = ""

    @property
    def topics(self) -> list[str]:
        """Source topics in map order, each once."""
        return list(dict.fromkeys(c.topic for c in self.channels))

    def channels_of(self, topic: str) -> list[ChannelSpec]:
        return [c for c in self.channels if c.topic == topic]

    def stamp_of(self, topic: str) -> str | None:
        """Message path of the topic's time stamp (None: ``header.stamp``, else log time)."""
        return next((c.stamp for c in self.channels_of(topic)), None)

    def text_log_map(self) -> "ChannelMap":
        """A delimited map as it applies to the text log itself: the ``stream``'s channels
        only (channels on other topics read message paths of a bag)."""
        return replace(self, channels=tuple(c for c in self.channels if c.topic == self.stream))

    @property
    def time_scale_s(self) -> float:
        return units.lookup(self.time_unit).factor


def shipped_maps() -> list[str]:
    """Names of the channel maps shipped with ingest."""
    folder = resources.files("ingest") / "channel_maps"
    return sorted(p.name[:-5] for p in folder.iterdir() if p.name.endswith(".toml"))


def load_channel_map(spec: "str | Path | ChannelMap | None" = None) -> ChannelMap:
    """A channel map from a TOML path, a shipped map's name, or None for the spec map."""
    if isinstance(spec, ChannelMap):
        return spec
    if spec is None:
        spec = "spec"
    text_spec = str(spec)
    is_name = not text_spec.endswith(".toml") and "/" not in text_spec and "\\" not in text_spec
    if is_name and not Path(text_spec).is_file():
        return _shipped(text_spec)
    path = Path(spec)
    try:
        text = path.read_text(encoding="utf-8")
    except OSError as exc:
        raise IngestError(path, None, f"cannot read channel map: {exc.strerror}") from None
    return _parse(path, text)


@lru_cache(maxsize=None)
def _shipped(name: str) -> ChannelMap:
    """A shipped map, parsed once per process."""
    resource = resources.files("ingest") / "channel_maps" / f"{name}.toml"
    if not resource.is_file():
        raise IngestError(name, None, "no such shipped channel map; shipped: "
                          + ", ".join(shipped_maps()) + " (or give a .toml path)")
    return _parse(Path(str(resource)), resource.read_text(encoding="utf-8"))


def _fail(path: Path, where: str | None, problem: str) -> IngestError:
    return IngestError(path, where, f"channel map: {problem}")


def _check_keys(path: Path, where: str, table: dict, known: set[str]) -> None:
    unknown = sorted(set(table) - known)
    if unknown:
        raise _fail(path, where, f"unknown key {unknown[0]!r}; known: {', '.join(sorted(known))}")


#: bounds of a map's numeric keys (a value beyond them is a typo, and some would hang a read)
MAX_HEADER_ROWS = 10_000
MAX_RUN_ID_PARTS = 10
MAX_COLUMNS = 1000
MAX_SCALE = 1e12


def _table(path: Path, where: str, value: Any) -> dict:
    if not isinstance(value, dict):
        raise _fail(path, where, f"must be a table, not {type(value).__name__}")
    return value


def _text(path: Path, where: str, value: Any, default: str | None = None) -> str | None:
    if value is None:
        return default
    if not isinstance(value, str):
        raise _fail(path, where, f"must be text, not {type(value).__name__}")
    return value


def _integer(path: Path, where: str, value: Any, default: int, low: int, high: int) -> int:
    if value is None:
        return default
    if isinstance(value, bool) or not isinstance(value, int) or not low <= value <= high:
        raise _fail(path, where, f"must be a whole number from {low} to {high}")
    return value


def _number(path: Path, where: str, value: Any, default: float) -> float:
    if value is None:
        return default
    if isinstance(value, bool) or not isinstance(value, (int, float)) \
            or not abs(value) <= MAX_SCALE:
        raise _fail(path, where, f"must be a number of magnitude at most {MAX_SCALE:g}")
    return float(value)


def _file_name(path: Path, where: str, value: Any) -> str | None:
    """A file name relative to the run's folder, never outside it."""
    name = _text(path, where, value)
    if name is not None and (not name or Path(name).is_absolute() or ".." in Path(name).parts
                             or "\\" in name):
        raise _fail(path, where, "must name a file inside the run's folder (no absolute path, "
                    "no '..')")
    return name


def _unit(path: Path, where: str, unit: Any, quantity: str | None) -> str:
    if not isinstance(unit, str) or units.lookup(unit) is None:
        raise _fail(path, where, f"unknown unit {unit!r}; known: {' '.join(units.UNITS)}")
    found = units.lookup(unit).quantity
    if quantity is not None and found != quantity:
        raise _fail(path, where, f"unit {unit!r} is a {found} but the column holds a {quantity}")
    return unit.strip()


def _channel(path: Path, raw: Any, fmt: str, stream: str) -> ChannelSpec:
    raw = _table(path, "channels", raw)
    column = raw.get("column")
    where = str(column)[:60]
    _check_keys(path, where, raw, _CHANNEL_KEYS)
    if not isinstance(column, str) or not re.fullmatch(r"[a-z][a-z0-9_]*", column):
        raise _fail(path, where, "every [[channels]] entry needs column = '<snake_case_name>'")
    near = None if column in CANONICAL else near_canonical(column)
    if near is not None:
        raise _fail(path, where, f"`{column}` is not a canonical column; did you mean "
                    f"`{near}`? (the source's unit goes in `unit`; an extra column needs a "
                    f"name more than {NEAR_EDITS} edits from every canonical one)")
    quantity = units.column_quantity(column)
    if column not in CANONICAL and quantity == "dimensionless":
        raise _fail(path, where, "not a canonical column; an extra column must end in its SI "
                    "unit (" + " ".join(units.SUFFIX_QUANTITY) + ")")
    if not _text(path, f"{where}.field", raw.get("field")):
        raise _fail(path, where, "missing field = '<source field or column name>'")
    topic = _text(path, f"{where}.topic", raw.get("topic"),
                  stream if fmt == "delimited" else None)
    if not topic:
        raise _fail(path, where, "missing topic = '<source topic>'")
    zero = raw.get("zero")
    if zero not in (None, "first"):
        raise _fail(path, where, f"zero = {str(zero)[:40]!r}; the only zeroing is 'first'")
    required = raw.get("required", False)
    if not isinstance(required, bool):
        raise _fail(path, f"{where}.required", "must be true or false")
    scale = _number(path, f"{where}.scale", raw.get("scale"), 1.0)
    if scale == 0:
        raise _fail(path, f"{where}.scale", "a scale of 0 would erase the channel")
    return ChannelSpec(column=column, topic=topic, field=raw["field"],
                       unit=_unit(path, where, raw.get("unit"), quantity), required=required,
                       csv_file=_file_name(path, f"{where}.csv_file", raw.get("csv_file")),
                       csv_column=_text(path, f"{where}.csv_column", raw.get("csv_column")),
                       scale=scale, offset=_number(path, f"{where}.offset", raw.get("offset"), 0.0),
                       zero=zero,
                       zero_value=_number(path, f"{where}.zero_value", raw.get("zero_value"), 0.0),
                       stamp=_text(path, f"{where}.stamp", raw.get("stamp")))


#: an extra column this close to a canonical name (Levenshtein edits) is taken for a typo
NEAR_EDITS = 2


def edits(a: str, b: str) -> int:
    """Levenshtein distance: insertions, deletions and substitutions turning ``a`` into ``b``."""
    row = list(range(len(b) + 1))
    for i, x in enumerate(a, 1):
        row, previous = [i], row
        for j, y in enumerate(b, 1):
            row.append(min(previous[j] + 1, row[j - 1] + 1, previous[j - 1] + (x != y)))
    return row[-1]


def near_canonical(column: str) -> str | None:
    """The canonical or derived column ``column`` looks like a misspelling of: one within
    :data:`NEAR_EDITS` edits (``sled_postion_m``, ``fz_nn``), or one with another unit
    after its name (``sled_position_mm``, ``dp_kn``); None for a name like none of them."""
    names = [c for c in dict.fromkeys(CANONICAL + DERIVED) if c != column]
    prefix = {c: len(os.path.commonprefix([column, c])) for c in names}  # ties: the likelier
    distance, _, best = min((edits(column, c), -prefix[c], c) for c in names)
    if distance <= NEAR_EDITS:
        return best
    stem, _, unit = column.rpartition("_")
    return next((c for c in names if stem and "_" not in unit and units.column_quantity(c)
                 != "dimensionless" and c.rpartition("_")[0] == stem), None)


def _filename_fields(path: Path, table: dict) -> tuple[str | None, tuple[FilenameField, ...]]:
    if "regex" not in table:
        return None, ()
    _check_keys(path, "metadata.filename", table, {"regex", "fields", "run_id_parts"})
    regex = _text(path, "metadata.filename.regex", table.get("regex"))
    try:
        groups = set(re.compile(regex).groupindex)
    except re.error as exc:
        raise _fail(path, "metadata.filename.regex", f"bad regular expression: {exc}") from None
    out = []
    for key, spec in _table(path, "metadata.filename.fields", table.get("fields", {})).items():
        where = f"metadata.filename.fields.{key}"
        if "." not in key:
            raise _fail(path, where, "key must be '<record>.<key>', e.g. 'run.velocity_mps'")
        spec = _table(path, where, spec)
        _check_keys(path, where, spec, {"group", "unit", "omit_if", "also"})
        if spec.get("group") not in groups:
            raise _fail(path, where, "group is not a named group of regex")
        unit = spec.get("unit")
        if unit is not None:
            _unit(path, where, unit, None)
        omit_if = spec.get("omit_if")
        out.append(FilenameField(key=key, group=spec["group"], unit=unit,
                                 omit_if=None if omit_if is None else _number(
                                     path, f"{where}.omit_if", omit_if, 0.0),
                                 also=dict(_table(path, f"{where}.also", spec.get("also", {})))))
    return regex, tuple(out)


def _parse(path: Path, text: str) -> ChannelMap:
    try:
        doc = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise _fail(path, None, f"not valid TOML: {exc}") from None
    _check_keys(path, "(top level)", doc, _TOP_KEYS)
    head = _table(path, "map", doc.get("map", {}))
    fmt = head.get("format", "spec")
    if fmt not in FORMATS:
        raise _fail(path, "map.format", f"{str(fmt)[:40]!r}; use one of {', '.join(FORMATS)}")
    files = _table(path, "files", doc.get("files", {}))
    _check_keys(path, "files", files, _FILES_KEYS)
    stream = _text(path, "files.stream", files.get("stream"), "delimited")
    listed = doc.get("channels", [])
    if not isinstance(listed, list):
        raise _fail(path, "channels", "must be an array of [[channels]] tables")
    channels = tuple(_channel(path, c, fmt, stream) for c in listed)
    if not channels:
        raise _fail(path, "channels", "no [[channels]] entries")
    seen: set[str] = set()
    stamps: dict[str, str | None] = {}
    for c in channels:
        if c.column in seen:
            raise _fail(path, c.column, "fed twice; map each canonical column once")
        seen.add(c.column)
        if stamps.setdefault(c.topic, c.stamp) != c.stamp:
            raise _fail(path, c.column, f"stamp differs from another channel of {c.topic}; "
                        "a topic has one time stamp")
    time = _table(path, "time", doc.get("time", {}))
    _check_keys(path, "time", time, {"column", "unit"})
    time_unit = _unit(path, "time.unit", time.get("unit", "s"), "time")
    time_column = _text(path, "time.column", time.get("column"), "t_s")
    columns = files.get("columns", [])
    if not isinstance(columns, list) or len(columns) > MAX_COLUMNS \
            or not all(isinstance(c, str) for c in columns):
        raise _fail(path, "files.columns", f"must be a list of at most {MAX_COLUMNS} names")
    columns = tuple(columns)
    pattern = _text(path, "files.pattern", files.get("pattern"))
    if pattern is not None and ("/" in pattern or "\\" in pattern or ".." in pattern):
        raise _fail(path, "files.pattern", "must match file names, not paths (no '/', no '..')")
    delimiter = _text(path, "files.delimiter", files.get("delimiter"), ",")
    comment = _text(path, "files.comment", files.get("comment"))
    if not 1 <= len(delimiter) <= 4 or (comment is not None and len(comment) != 1):
        raise _fail(path, "files", "delimiter must be 1 to 4 characters, comment 1 character")
    if fmt == "delimited":
        if not columns:
            raise _fail(path, "files.columns", "a delimited map needs the column order")
        # channels on another topic than the stream read message paths of a bag
        for name in [time_column] + [c.field for c in channels if c.topic == stream]:
            if name not in columns:
                raise _fail(path, name[:60], f"not one of files.columns ({', '.join(columns)})")
    metadata = dict(_table(path, "metadata", doc.get("metadata", {})))
    filename = _table(path, "metadata.filename", metadata.pop("filename", {}))
    regex, fname_fields = _filename_fields(path, filename)
    defaults = {k: dict(_table(path, f"metadata.{k}", v)) for k, v in metadata.items()}
    return ChannelMap(
        name=_text(path, "map.name", head.get("name"), path.stem), path=path, format=fmt,
        channels=channels, time_column=time_column, time_unit=time_unit,
        file_pattern=pattern, delimiter=delimiter,
        header_rows=_integer(path, "files.header_rows", files.get("header_rows"), 0, 0,
                             MAX_HEADER_ROWS),
        columns=columns, comment=comment, stream=stream, metadata_defaults=defaults,
        filename_regex=regex, filename_fields=fname_fields,
        run_id_parts=_integer(path, "metadata.filename.run_id_parts",
                              filename.get("run_id_parts"), 1, 1, MAX_RUN_ID_PARTS),
        description=_text(path, "map.description", head.get("description"), ""))
