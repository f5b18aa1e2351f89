"""Channel maps: TOML files that tell ingest a lab's names, columns and units (docs/channel-map.md).

The spec form itself is the shipped map ``spec``; ``cmu_3d_terramechanics`` reads
the CMU motion logs.
"""

from __future__ import annotations

import re
import tomllib
from dataclasses import dataclass, field
from functools import lru_cache
from importlib import resources
from pathlib import Path
from typing import Any

from ingest import units
from ingest.canonical import CANONICAL
from ingest.errors import IngestError

FORMATS = ("spec", "delimited")
_TOP_KEYS = {"map", "files", "time", "channels", "metadata"}
_CHANNEL_KEYS = {"column", "topic", "field", "unit", "required", "csv_file", "csv_column",
                 "scale", "offset", "zero", "zero_value"}
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


def _unit(path: Path, where: str, unit: Any, quantity: str | None) -> str:
    if not isinstance(unit, str) or units.lookup(unit) is None:
        raise _fail(path, where, f"unknown unit {unit!r}; known: {' '.join(units.UNITS)}")
    found = units.lookup(unit).quantity
    if quantity is not None and found != quantity:
        raise _fail(path, where, f"unit {unit!r} is a {found} but the column holds a {quantity}")
    return unit.strip()


def _channel(path: Path, raw: dict, fmt: str, stream: str) -> ChannelSpec:
    column = raw.get("column")
    where = str(column)
    _check_keys(path, where, raw, _CHANNEL_KEYS)
    if not isinstance(column, str) or not re.fullmatch(r"[a-z][a-z0-9_]*", column):
        raise _fail(path, where, "every [[channels]] entry needs column = '<snake_case_name>'")
    quantity = units.column_quantity(column)
    if column not in CANONICAL and quantity == "dimensionless":
        raise _fail(path, where, "not a canonical column; an extra column must end in its SI "
                    "unit (" + " ".join(units.SUFFIX_QUANTITY) + ")")
    if "field" not in raw:
        raise _fail(path, where, "missing field = '<source field or column name>'")
    topic = raw.get("topic", stream if fmt == "delimited" else None)
    if not topic:
        raise _fail(path, where, "missing topic = '<source topic>'")
    zero = raw.get("zero")
    if zero not in (None, "first"):
        raise _fail(path, where, f"zero = {zero!r}; the only zeroing is 'first'")
    try:
        return ChannelSpec(column=column, topic=str(topic), field=str(raw["field"]),
                           unit=_unit(path, where, raw.get("unit"), quantity),
                           required=bool(raw.get("required", False)),
                           csv_file=raw.get("csv_file"), csv_column=raw.get("csv_column"),
                           scale=float(raw.get("scale", 1.0)), offset=float(raw.get("offset", 0.0)),
                           zero=zero, zero_value=float(raw.get("zero_value", 0.0)))
    except (TypeError, ValueError) as exc:
        raise _fail(path, where, f"bad number: {exc}") from None


def _filename_fields(path: Path, table: dict) -> tuple[str | None, tuple[FilenameField, ...]]:
    if "regex" not in table:
        return None, ()
    _check_keys(path, "metadata.filename", table, {"regex", "fields", "run_id_parts"})
    regex = table.get("regex")
    try:
        groups = set(re.compile(regex).groupindex)
    except (re.error, TypeError) as exc:
        raise _fail(path, "metadata.filename.regex", f"bad regular expression: {exc}") from None
    out = []
    for key, spec in table.get("fields", {}).items():
        where = f"metadata.filename.fields.{key}"
        if "." not in key:
            raise _fail(path, where, "key must be '<record>.<key>', e.g. 'run.velocity_mps'")
        _check_keys(path, where, spec, {"group", "unit", "omit_if", "also"})
        if spec.get("group") not in groups:
            raise _fail(path, where, f"group {spec.get('group')!r} is not a named group of regex")
        unit = spec.get("unit")
        if unit is not None:
            _unit(path, where, unit, None)
        out.append(FilenameField(key=key, group=spec["group"], unit=unit,
                                 omit_if=spec.get("omit_if"), also=dict(spec.get("also", {}))))
    return regex, tuple(out)


def _parse(path: Path, text: str) -> ChannelMap:
    try:
        doc = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise _fail(path, None, f"not valid TOML: {exc}") from None
    _check_keys(path, "(top level)", doc, _TOP_KEYS)
    head = doc.get("map", {})
    fmt = head.get("format", "spec")
    if fmt not in FORMATS:
        raise _fail(path, "map.format", f"{fmt!r}; use one of {', '.join(FORMATS)}")
    files = doc.get("files", {})
    _check_keys(path, "files", files, _FILES_KEYS)
    stream = str(files.get("stream", "delimited"))
    channels = tuple(_channel(path, c, fmt, stream) for c in doc.get("channels", []))
    if not channels:
        raise _fail(path, "channels", "no [[channels]] entries")
    seen: set[str] = set()
    for c in channels:
        if c.column in seen:
            raise _fail(path, c.column, "fed twice; map each canonical column once")
        seen.add(c.column)
    time = doc.get("time", {})
    _check_keys(path, "time", time, {"column", "unit"})
    time_unit = _unit(path, "time.unit", time.get("unit", "s"), "time")
    columns = tuple(str(c) for c in files.get("columns", ()))
    if fmt == "delimited":
        if not columns:
            raise _fail(path, "files.columns", "a delimited map needs the column order")
        for name in [time.get("column", "t_s")] + [c.field for c in channels]:
            if name not in columns:
                raise _fail(path, name, f"not one of files.columns ({', '.join(columns)})")
    metadata = dict(doc.get("metadata", {}))
    filename = metadata.pop("filename", {})
    regex, fname_fields = _filename_fields(path, filename)
    return ChannelMap(
        name=str(head.get("name", path.stem)), path=path, format=fmt, channels=channels,
        time_column=str(time.get("column", "t_s")), time_unit=time_unit,
        file_pattern=files.get("pattern"), delimiter=str(files.get("delimiter", ",")),
        header_rows=int(files.get("header_rows", 0)), columns=columns,
        comment=files.get("comment"), stream=stream,
        metadata_defaults={k: dict(v) for k, v in metadata.items()},
        filename_regex=regex, filename_fields=fname_fields,
        run_id_parts=int(filename.get("run_id_parts", 1)),
        description=str(head.get("description", "")))
