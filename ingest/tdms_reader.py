"""NI TDMS reader (npTDMS): one group per topic, one channel per field.

A group is the map's topic as written (``/hub/wrench``) or as an identifier
(``hub_wrench``). Time: the map's ``[time] column`` channel, else ``t_ns``, else the
channels' waveform timing (``wf_start_time`` + ``wf_start_offset`` + i * ``wf_increment``,
counted from the earliest ``wf_start_time`` in the file). Metadata: file and group
properties named ``"<record>.<key>"`` or ``"swt.<record>.<key>"``, then the sidecar
``<name>.run.json`` (``ingest.records``).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ingest.channel_map import ChannelMap
from ingest.errors import IngestError
from ingest.raw import RawRun
from ingest.structured import dotted_records, raw_topic, time_s, variable_name

_HINT = "the file is damaged or cut short; export it again"


def read_tdms(path: Path, cmap: ChannelMap) -> RawRun:
    """The map's topics (groups) and fields (channels) of one TDMS run file."""
    from nptdms import TdmsFile

    path = Path(path)
    try:
        tdms = TdmsFile.read(path)
        groups = {g.name: g for g in tdms.groups()}
        records = dotted_records(path, tdms.properties.items())
        for group in groups.values():
            for name, values in dotted_records(path, group.properties.items()).items():
                records.setdefault(name, {}).update(values)
        start = _earliest_start(groups.values())
        topics = {}
        for topic in cmap.topics:
            group = groups.get(topic, groups.get(variable_name(topic)))
            if group is None:
                continue
            channels = {c.name: c for c in group.channels()}

            def get(name, channels=channels):
                channel = channels.get(name)
                return None if channel is None else channel[:]

            found = time_s(path, topic, cmap, get)
            t_s = found[0] if found else _waveform_s(path, topic, cmap, channels, start)
            topics[topic] = raw_topic(path, topic, cmap, t_s, get)
    except IngestError:
        raise
    except OSError as exc:
        raise IngestError(path, None, f"cannot read file: {exc.strerror or exc}") from None
    except Exception as exc:  # npTDMS raises many types for damaged files
        raise IngestError(path, None, f"corrupt TDMS ({type(exc).__name__}: {exc}); "
                          f"{_HINT}") from None
    return RawRun(path=path, records=records, topics=topics)


def _earliest_start(groups) -> np.datetime64 | None:
    starts = [c.properties["wf_start_time"] for g in groups for c in g.channels()
              if "wf_start_time" in c.properties]
    return min(np.datetime64(s, "ns") for s in starts) if starts else None


def _waveform_s(path: Path, topic: str, cmap: ChannelMap, channels: dict,
                start: np.datetime64 | None) -> np.ndarray:
    """Sample times of a group's waveform channels (all must share one timing)."""
    timings = set()
    for spec in cmap.channels_of(topic):
        channel = channels.get(spec.field)
        if channel is None:
            continue
        props = channel.properties
        if "wf_increment" not in props:
            raise IngestError(path, f"{topic}.{spec.field}", f"no time channel "
                              f"({cmap.time_column!r} or 't_ns') in the group and no waveform "
                              "timing (wf_increment)")
        t0_s = float(props.get("wf_start_offset", 0.0))
        if "wf_start_time" in props and start is not None:
            t0_s += (np.datetime64(props["wf_start_time"], "ns") - start) / np.timedelta64(1, "s")
        timings.add((t0_s, float(props["wf_increment"]), len(channel)))
    if not timings:
        return np.array([])
    if len(timings) > 1:
        raise IngestError(path, topic, "waveform channels of the group differ in start, "
                          "increment or length; give the group a time channel")
    t0_s, step_s, n = timings.pop()
    if not (np.isfinite(step_s) and step_s > 0):
        raise IngestError(path, topic, f"wf_increment {step_s!r}; must be a positive number "
                          "of seconds")
    return t0_s + step_s * np.arange(n)
