"""Metadata records of a run: map defaults, then the file's own records, then its name."""

from __future__ import annotations

import re
from pathlib import Path
from typing import Any

from ingest import units
from ingest.channel_map import ChannelMap
from ingest.errors import IngestError
from ingest.structured import sidecar_path, sidecar_records

#: unit of a metadata value, by the key's suffix (spec key names)
_KEY_UNITS = {"_mps": "m/s", "_deg": "deg", "_rad": "rad", "_m": "m", "_N": "N", "_s": "s"}


#: where the files of each format (``RawRun.form``) keep a metadata record, ``{record}`` to
#: fill in (None: the sidecar only); every form also takes the sidecar ``<run>.run.json``
FORMS: dict[str, str | None] = {
    "mcap": "the MCAP's swt.{record} metadata record",
    "csv_run": 'run.json ("{record}": {{...}})',
    "hdf5": "root attributes {record}.<key> or swt.{record}.<key> (or attributes of the group "
            "/swt/{record})",
    "mat5": "a struct {record} or swt.{record} (one field per key)",
    "mat73": "a struct {record} or swt.{record} (one field per key)",
    "tdms": "file properties {record}.<key> or swt.{record}.<key>",
    "delimited": "the channel map's [metadata.{record}] (or its file-name regex)",
}


def metadata_form(path: Path, form: str) -> str:
    """Where a run's file of format ``form`` keeps a metadata record (``{record}`` to fill
    in): its format's place, and the sidecar (``ingest.structured.sidecar_path``)."""
    side = sidecar_path(path).name.replace("{", "{{").replace("}", "}}")
    own = FORMS.get(form)
    return f"{own}, or the sidecar {side}" if own else f"the sidecar {side}"


def merged_records(path: Path, file_records: dict[str, dict], cmap: ChannelMap) -> dict[str, dict]:
    """Map defaults < file records < the sidecar ``<run>.run.json`` (any format) < values
    parsed from the file name."""
    out: dict[str, dict[str, Any]] = {k: dict(v) for k, v in cmap.metadata_defaults.items()}
    for name, values in file_records.items():
        out.setdefault(name, {}).update(values)
    for name, values in sidecar_records(path).items():
        out.setdefault(name, {}).update(values)
    for key, value in filename_values(path, cmap).items():
        record, _, item = key.partition(".")
        out.setdefault(record, {})[item] = value
    out.setdefault("run", {}).setdefault("run_id", _default_run_id(path, cmap.run_id_parts))
    return out


def _default_run_id(path: Path, parts: int) -> str:
    """File stem (folder name for a run folder), with ``parts - 1`` parent folders before it."""
    path = Path(path).resolve()
    names = [p.name for p in reversed(path.parents)][-(parts - 1):] if parts > 1 else []
    return "/".join(names + [path.stem if path.is_file() else path.name])


def filename_values(path: Path, cmap: ChannelMap) -> dict[str, Any]:
    """Metadata from the map's file-name regex, converted to the unit each key names."""
    if cmap.filename_regex is None:
        return {}
    match = re.search(cmap.filename_regex, Path(path).name)
    if match is None:
        raise IngestError(path, None, f"file name does not match the channel map's regex "
                          f"{cmap.filename_regex!r} ({cmap.path.name}); rename it or fix the map")
    out: dict[str, Any] = {}
    for spec in cmap.filename_fields:
        text = match.group(spec.group)
        if text is None:
            continue
        value: Any = text
        if spec.unit is not None:
            value = float(units.to_si(float(text), units.lookup(spec.unit)))
            target = next((u for s, u in _KEY_UNITS.items() if spec.key.endswith(s)), None)
            if target is not None:
                value = float(f"{value / units.lookup(target).factor:.12g}")  # no 29.999999...
        if spec.omit_if is not None and float(text) == spec.omit_if:
            continue
        out[spec.key] = value
        out.update(spec.also)
    return out
