"""MATLAB ``.mat`` reader: v5 files through scipy.io, v7.3 (HDF5 inside) through h5py.

One struct variable per topic, named as the topic with slashes to underscores
(``/hub/wrench`` -> ``hub_wrench``), one numeric field per source field; time as in the
map's ``[time] column`` or ``t_ns``. Metadata: a struct ``swt`` of record structs
(``swt.run.run_id = 'r001'``) or record structs of their own (``run.run_id = 'r001'``), then
the sidecar ``<name>.run.json`` (``ingest.records``).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ingest.channel_map import ChannelMap
from ingest.errors import IngestError
from ingest.metadata import RECORDS
from ingest.raw import RawRun
from ingest.structured import raw_topic, scalar, time_s, variable_name

_HINT = "the file is damaged or cut short; save it again from MATLAB"


def read_mat(path: Path, cmap: ChannelMap, version: str) -> RawRun:
    """One run in a ``.mat`` file; ``version`` is ``"mat5"`` or ``"mat73"`` (see formats.sniff)."""
    path = Path(path)
    variables = _load_v73(path) if version == "mat73" else _load_v5(path)
    swt = variables.get("swt", {})
    if not isinstance(swt, dict):
        raise IngestError(path, "swt", "must be a struct of record structs (swt.run.run_id)")
    records: dict[str, dict] = {}
    structs = [(f"swt.{n}", n, r) for n, r in swt.items()]
    # record structs of their own (run.run_id); a variable of another kind is not ours
    structs += [(n, n, variables[n]) for n in RECORDS if isinstance(variables.get(n), dict)]
    for where, name, record in structs:
        if not isinstance(record, dict):
            raise IngestError(path, where, "must be a struct of metadata values")
        records.setdefault(name, {}).update(
            {k: scalar(path, f"{where}.{k}", v) for k, v in record.items()})
    topics = {}
    for topic in cmap.topics:
        name = variable_name(topic)
        struct = variables.get(name)
        if struct is None:
            continue
        if not isinstance(struct, dict):
            raise IngestError(path, topic, f"variable {name} must be a struct with one field "
                              "per channel")
        found = time_s(path, topic, cmap, struct.get)
        if found is None:
            raise IngestError(path, topic, f"struct {name} has no time field "
                              f"({cmap.time_column!r} or 't_ns')")
        topics[topic] = raw_topic(path, topic, cmap, found[0], struct.get)
    return RawRun(path=path, records=records, topics=topics)


def _load_v5(path: Path) -> dict:
    from scipy.io import loadmat

    try:
        return loadmat(path, simplify_cells=True)
    except OSError as exc:
        raise IngestError(path, None, f"cannot read file: {exc.strerror or exc}") from None
    except Exception as exc:  # scipy raises many types for damaged files
        raise IngestError(path, None, f"corrupt MATLAB v5 file ({type(exc).__name__}: "
                          f"{exc}); {_HINT}") from None


def _load_v73(path: Path) -> dict:
    """Variables of a v7.3 file: structs (HDF5 groups) as dicts, matrices as arrays, char
    matrices as text."""
    import h5py

    def convert(node):
        if isinstance(node, h5py.Group):
            return {k: convert(v) for k, v in node.items() if not k.startswith("#")}
        value = node[()]
        cls = node.attrs.get("MATLAB_class", b"")
        if (cls.decode() if isinstance(cls, bytes) else cls) == "char":
            return "".join(map(chr, np.asarray(value).reshape(-1)))
        return value

    try:
        with h5py.File(path, "r") as root:
            return {k: convert(v) for k, v in root.items() if not k.startswith("#")}
    except OSError as exc:
        raise IngestError(path, None, f"cannot read MATLAB v7.3 (HDF5) file ({exc}); "
                          f"{_HINT}") from None
