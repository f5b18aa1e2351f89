"""HDF5 reader (h5py): one group per topic (its path is the map's topic), one dataset per field.

Time: the map's ``[time] column`` dataset in each group, else ``t_ns`` (whole ns). Metadata:
attributes ``"<record>.<key>"`` or ``"swt.<record>.<key>"`` of the root group, attributes of
``/swt/<record>`` groups, then the sidecar ``<name>.run.json`` (``ingest.records``).
"""

from __future__ import annotations

from pathlib import Path

import h5py

from ingest.channel_map import ChannelMap
from ingest.errors import IngestError
from ingest.raw import RawRun
from ingest.structured import dotted_records, raw_topic, scalar, time_s

_HINT = "the file is damaged, cut short or not HDF5; re-export it"


def read_hdf5(path: Path, cmap: ChannelMap) -> RawRun:
    """The map's topics (groups) and fields (datasets) of one HDF5 run file."""
    path = Path(path)
    try:
        with h5py.File(path, "r") as root:
            records = _records(path, root)
            topics = {}
            for topic in cmap.topics:
                group = root.get(topic)
                if group is None:
                    continue
                if not isinstance(group, h5py.Group):
                    raise IngestError(path, topic, "is a dataset; a topic must be a group of "
                                      "datasets (one per field)")
                topics[topic] = _topic(path, topic, group, cmap)
    except IngestError:
        raise
    except OSError as exc:
        raise IngestError(path, None, f"cannot read HDF5 ({exc}); {_HINT}") from None
    return RawRun(path=path, records=records, topics=topics)


def _dataset(group: h5py.Group, name: str):
    node = group.get(name)
    return node[()] if isinstance(node, h5py.Dataset) else None


def _topic(path: Path, topic: str, group: h5py.Group, cmap: ChannelMap):
    def get(name):
        return _dataset(group, name)

    found = time_s(path, topic, cmap, get)
    if found is None:
        raise IngestError(path, topic, f"no time dataset ({cmap.time_column!r} or 't_ns') in "
                          "the group")
    return raw_topic(path, topic, cmap, found[0], get)


def _records(path: Path, root: h5py.File) -> dict[str, dict]:
    records = dotted_records(path, root.attrs.items())
    swt = root.get("swt")
    if isinstance(swt, h5py.Group):
        for name, group in swt.items():
            if isinstance(group, h5py.Group):
                records.setdefault(name, {}).update(
                    {k: scalar(path, f"swt/{name}.{k}", v) for k, v in group.attrs.items()})
    return records
