"""Shared by the readers of array formats (HDF5, MATLAB, TDMS, ROS): one topic's arrays checked
into a ``RawTopic``, and the sidecar ``<name>.run.json`` metadata records."""

from __future__ import annotations

import glob
from pathlib import Path
from typing import Any, Callable

import numpy as np

from ingest.channel_map import ChannelMap
from ingest.csv_reader import read_run_json
from ingest.errors import IngestError
from ingest.formats import BY_SUFFIX, ROS2_METADATA
from ingest.raw import RawTopic

#: the spec MCAP form's time field: whole ns since the run start (used when the map's
#: ``[time] column`` is not in the file)
SPEC_TIME_NS = "t_ns"
#: a run's sidecar of metadata records: ``<run>.run.json`` beside it
SIDECAR_SUFFIX = ".run.json"


def variable_name(topic: str) -> str:
    """``/hub/wrench`` -> ``hub_wrench``: a topic as an identifier (MATLAB variables)."""
    return topic.strip("/").replace("/", "_")


def vector(path: Path, where: str, value: Any) -> np.ndarray:
    """A 1-D numeric array (a MATLAB 1xN or Nx1 matrix flattened), else a one-line error."""
    try:
        array = np.asarray(value)
    except Exception as exc:  # any unreadable array is one error
        raise IngestError(path, where, f"cannot read as an array ({exc})") from None
    if array.ndim > 1 and sorted(array.shape)[:-1] != [1] * (array.ndim - 1):
        raise IngestError(path, where, f"shape {array.shape}; a channel must be one vector")
    array = array.reshape(-1)
    if array.dtype.kind not in "biuf":
        raise IngestError(path, where, f"{array.dtype} values; a channel must be numbers")
    return array


def time_s(path: Path, topic: str, cmap: ChannelMap,
           get: Callable[[str], Any]) -> tuple[np.ndarray, str] | None:
    """Seconds since the run start from the map's time column (its unit), else ``t_ns``;
    None when the topic has neither. Returns the array and the name used."""
    for name, scale in ((cmap.time_column, cmap.time_scale_s), (SPEC_TIME_NS, 1e-9)):
        value = get(name)
        if value is None:
            continue
        t = vector(path, f"{topic}.{name}", value)
        if name == SPEC_TIME_NS and t.dtype.kind not in "iu":
            raise IngestError(path, f"{topic}.{name}", "t_ns must be whole numbers of ns")
        return (t.astype(np.int64) if t.dtype.kind in "iu" else t.astype(np.float64)) * scale, \
            name
    return None


def raw_topic(path: Path, topic: str, cmap: ChannelMap, t_s: np.ndarray,
              get: Callable[[str], Any]) -> RawTopic:
    """The map's fields of one topic (``get(field)`` -> array or None when absent), each as
    long as the time base."""
    fields = {}
    for spec in cmap.channels_of(topic):
        value = get(spec.field)
        if value is None:
            continue  # left to the coverage check (required channel -> error)
        where = f"{topic}.{spec.field}"
        values = vector(path, where, value).astype(np.float64)
        if len(values) != len(t_s):
            raise IngestError(path, where, f"{len(values)} samples but the time base has "
                              f"{len(t_s)}; every channel needs one value per time stamp")
        fields[spec.field] = values
    return RawTopic(t_s=np.asarray(t_s, dtype=np.float64), fields=fields)


def sidecar_path(path: Path) -> Path:
    """The run's sidecar beside it: ``<file name>.run.json`` (``run7.h5`` ->
    ``run7.h5.run.json``) when there is one, else ``<stem>.run.json`` (``run7.run.json``; a
    ROS 2 bag folder ``bag7/`` -> ``bag7.run.json``). A stem sidecar that another run file
    of that stem would read too (``run7.h5`` and ``run7.bag``) is an IngestError."""
    path = Path(path)
    own = path.with_name(path.name + SIDECAR_SUFFIX)
    shared = path.with_name(path.name.split(".")[0] + SIDECAR_SUFFIX)
    if own != shared and own.is_file():
        return own
    if shared.is_file():
        rivals = [p.name for p in _same_stem_runs(path)
                  if not p.with_name(p.name + ".run.json").is_file()]
        if rivals:
            raise IngestError(path, "sidecar", f"{shared.name} is ambiguous: runs {path.name} "
                              f"and {rivals[0]} share its stem; name each run's sidecar after "
                              f"its whole file name ({path.name}.run.json)")
    return shared


def _same_stem_runs(path: Path) -> list[Path]:
    """Other run files or ROS 2 bag folders beside ``path`` with its stem (``run7.*``)."""
    stem = path.name.split(".")[0]
    near = [*path.parent.glob(glob.escape(stem) + ".*"), path.parent / stem]
    return sorted(p for p in near if p != path and (
        (p.is_file() and p.suffix.lower() in BY_SUFFIX)
        or (p.is_dir() and (p / ROS2_METADATA).is_file())))


def sidecar_records(path: Path) -> dict[str, dict]:
    """Metadata records of the sidecar ``<name>.run.json`` (spec ``run.json`` layout), if any."""
    side = sidecar_path(path)
    return read_run_json(side) if side.is_file() else {}


def dotted_records(path: Path, items) -> dict[str, dict]:
    """Records from flat ``"<record>.<key>" = value`` or ``"swt.<record>.<key>" = value``
    properties (TDMS properties, HDF5 attributes); other names are not ours and are
    skipped."""
    out: dict[str, dict] = {}
    for name, value in items:
        text = str(name)
        record, dot, key = text.removeprefix("swt.").partition(".")
        if not dot or not record or not key:
            continue
        out.setdefault(record, {})[key] = scalar(path, text, value)
    return out


def scalar(path: Path, where: str, value: Any):
    """A metadata value as text or a Python number (numpy scalars, bytes, 1-element arrays)."""
    if isinstance(value, bytes):
        return value.decode("utf-8", errors="replace")
    array = np.asarray(value)
    if array.size == 1 and array.dtype.kind in "biuf":
        return array.reshape(-1)[0].item()
    if array.dtype.kind == "M" and array.size == 1:  # TDMS time stamps
        return str(np.datetime_as_string(array.reshape(-1)[0], unit="us")) + "Z"
    if array.dtype.kind in "US" and array.size == 1:
        return str(array.reshape(-1)[0])
    if isinstance(value, str):
        return value
    raise IngestError(path, where, f"metadata value of shape {array.shape} ({array.dtype}); "
                      "expected one number or text")
