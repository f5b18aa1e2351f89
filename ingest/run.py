"""``read_run``: a run's files -> ``Run`` (typed metadata, SI streams, one channel table)."""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pandas as pd

from ingest import cut_short, derive
from ingest.calibration import subtract_zero, to_canonical
from ingest.canonical import CANONICAL, DERIVED, MEASURED, SUBSTITUTES, WRENCH_COLUMNS
from ingest.channel_map import ChannelMap, ChannelSpec, load_channel_map
from ingest.checks import check_calibrated, check_topic
from ingest.delimited_reader import read_delimited
from ingest.errors import IngestError, Problem
from ingest.formats import is_ros_bag, sniff
from ingest.metadata import RunMetadata, parse_metadata
from ingest.raw import FrameIndex, RawRun
from ingest.records import merged_records, metadata_form
from ingest.ros_reader import read_ros_rows
from ingest.timebase import (DROP_FACTOR, GAP_FACTOR, JITTER_LIMIT, StreamTiming, common_grid,
                             grid_mask, grid_size, stream_timing, to_grid)

_ZERO_OF = {column: fld for fld, column in WRENCH_COLUMNS.items()}
#: longest plausible run; longer spans mean a stream is on another clock
MAX_RUN_S = 6 * 3600.0
#: a time base longer than this many times the longest stream is a stray time stamp
MAX_GRID_PER_SAMPLE = 20


@dataclass(frozen=True)
class Run:
    """One run as ingest sees it.

    ``streams``: per source topic, native ``t_s`` + canonical SI columns.
    ``channels``: one table on the uniform ``t_s`` grid with every canonical and
    derived column (NaN where a channel is missing or inside a gap).
    """

    source: Path
    metadata: RunMetadata
    streams: dict[str, pd.DataFrame]
    channels: pd.DataFrame
    problems: list[Problem]
    derivation: dict
    frames: dict[str, FrameIndex] = field(default_factory=dict)
    timing: dict[str, StreamTiming] = field(default_factory=dict)
    units: dict[str, str] = field(default_factory=dict)
    channel_map: str = "spec"
    #: ``"<file>: file ends at t = ... s (cut short?): <why>"`` when the file looks cut short
    cut_short: str | None = None

    @property
    def run_id(self) -> str:
        return self.metadata.run.run_id


def read_run(path: str | Path, channel_map: "str | Path | ChannelMap | None" = None) -> Run:
    """Read one run: a file or folder of any format ``ingest.formats`` recognises by content
    (MCAP, HDF5, MATLAB, TDMS, ROS bags, CSV run folder), or a text log its channel map
    describes. A file cut short is read as far as it goes; the run says so in
    ``cut_short`` (and a run it leaves unusable, in its IngestError)."""
    path = Path(path)
    cmap = load_channel_map(channel_map)
    if cmap.format == "delimited" and not is_ros_bag(path):
        cmap = cmap.text_log_map()  # a text log has only the stream's channels
    raw = _read_raw(path, cmap)
    if raw.cut_short is None:
        return _run(path, cmap, raw, None)
    end = max((float(t.t_s[-1]) for t in raw.topics.values() if len(t.t_s)), default=None)
    try:
        return _run(path, cmap, raw, cut_short.message(path, end, raw.cut_short))
    except IngestError as exc:
        raise IngestError(exc.path, exc.channel,
                          f"{exc.problem}; {cut_short.note(end, raw.cut_short)}") from None


def _run(path: Path, cmap: ChannelMap, raw: RawRun, cut: str | None) -> Run:
    for topic, data in raw.topics.items():
        check_topic(path, topic, data)
    problems = _coverage_problems(path, raw, cmap)
    if cut is not None:
        problems.append(Problem("error", None, cut))
    provided = {c.column for c in cmap.channels
                if c.topic in raw.topics and c.field in raw.topics[c.topic].fields}
    records = merged_records(path, raw.records, cmap)
    metadata, meta_problems = parse_metadata(path, records,
                                             needs_suspension="suspension_angle_rad" in provided,
                                             form=metadata_form(path, raw.form))
    problems += meta_problems
    arrays, units = _streams(raw, cmap, metadata, problems)
    timing = {topic: stream_timing(columns["t_s"]) for topic, columns in arrays.items()}
    _check_clocks(path, timing)
    problems += _timing_problems(timing)
    channels, derivation = _channel_table(arrays, timing, metadata, provided, problems)
    derivation.update(_dp_from_hub(cmap, provided))
    streams = {topic: pd.DataFrame(columns, copy=False)  # their own arrays: no copy
               for topic, columns in arrays.items()}
    problems += _frame_problems(raw.frames, metadata)
    return Run(source=path, metadata=metadata, streams=streams, channels=channels,
               problems=problems, derivation=derivation, frames=raw.frames, timing=timing,
               units=units, channel_map=cmap.name, cut_short=cut)


def _read_raw(path: Path, cmap: ChannelMap) -> RawRun:
    if not path.exists():
        raise IngestError(path, None, "no such file or folder")
    if cmap.format == "delimited":
        if is_ros_bag(path):
            raw = read_ros_rows(path, cmap)  # the text log's rows recorded in a bag
            raw.form = "rosbag"
            return raw
        if not path.is_file():
            raise IngestError(path, None, f"channel map {cmap.name} reads one text file per run")
        raw = read_delimited(path, cmap)
        raw.form = "delimited"
        return raw
    return read_raw_file(path, cmap)


def read_raw_file(path: Path, cmap: ChannelMap) -> RawRun:
    """Read ``path`` with the reader of its sniffed format (named in the raw run's ``form``)."""
    fmt = sniff(path)
    raw = _read(path, cmap, fmt)
    raw.form = fmt
    return raw


def _read(path: Path, cmap: ChannelMap, fmt: str) -> RawRun:
    if fmt == "mcap":
        from ingest.mcap_reader import read_mcap
        return read_mcap(path, set(cmap.topics))
    if fmt == "csv_run":
        from ingest.csv_reader import read_csv_run
        return read_csv_run(path, cmap)
    if fmt == "hdf5":
        from ingest.hdf5_reader import read_hdf5
        return read_hdf5(path, cmap)
    if fmt in ("mat5", "mat73"):
        from ingest.mat_reader import read_mat
        return read_mat(path, cmap, fmt)
    if fmt == "tdms":
        from ingest.tdms_reader import read_tdms
        return read_tdms(path, cmap)
    from ingest.ros_reader import read_ros
    return read_ros(path, cmap)


def _coverage_problems(path: Path, raw: RawRun, cmap: ChannelMap) -> list[Problem]:
    """Missing required channels raise; missing optional or unmapped canonical ones are problems."""
    problems = []
    mapped = {c.column for c in cmap.channels}
    for spec in cmap.channels:
        topic = raw.topics.get(spec.topic)
        if topic is not None and spec.field in topic.fields:
            continue
        where = f"{spec.topic}.{spec.field}"
        why = "topic absent" if topic is None else f"field {spec.field!r} absent from the topic"
        if spec.required:
            raise IngestError(path, where, f"required channel missing ({why}); it feeds "
                              f"{spec.column}")
        problems.append(Problem("warning", spec.column, f"optional channel {where} absent ({why})"))
    for column, required in MEASURED.items():
        if column in mapped or not required:
            continue
        if any(s in mapped for s in SUBSTITUTES.get(column, ())):
            continue
        problems.append(Problem("error", column, f"not in this source (channel map "
                                f"{cmap.name} has no channel for it); column is NaN"))
    return problems


def _streams(raw: RawRun, cmap: ChannelMap, metadata: RunMetadata,
             problems: list[Problem]) -> tuple[dict[str, dict[str, np.ndarray]], dict[str, str]]:
    """Per topic: native t_s + calibrated, zeroed canonical SI columns (arrays by name)."""
    streams, units = {}, {}
    used = set()
    # dp_n read as a wrench column is (same field, same conversion) has that column's zero
    zero_of = {_conversion(c): _ZERO_OF[c.column] for c in cmap.channels if c.column in _ZERO_OF}
    for topic in cmap.topics:
        data = raw.topics.get(topic)
        if data is None:
            continue
        columns = {"t_s": data.t_s}
        for spec in cmap.channels_of(topic):
            if spec.field not in data.fields:
                continue
            cal = metadata.calibration.get((topic, spec.field))
            used.add((topic, spec.field))
            with np.errstate(over="ignore", invalid="ignore"):
                values = to_canonical(data.fields[spec.field], spec, cal)
                if _conversion(spec) in zero_of:
                    values = subtract_zero(values, metadata.zero.get(zero_of[_conversion(spec)]))
            check_calibrated(raw.path, f"{topic}.{spec.field}", spec.column, values)
            columns[spec.column] = values
            units[spec.column] = spec.unit if cal is None else "SI (swt.calibration)"
        streams[topic] = columns
    for topic, fld in sorted(set(metadata.calibration) - used):
        problems.append(Problem("warning", f"{topic}.{fld}",
                                "swt.calibration names a channel this run does not have"))
    return streams, units


def _conversion(spec: ChannelSpec) -> tuple:
    """A channel's source field and how it becomes SI: two columns alike here hold the same
    values."""
    return spec.topic, spec.field, spec.unit, spec.scale, spec.offset, spec.zero, spec.zero_value


#: ``run.derivation["dp_n"]["method"]`` of drawbar pull read from the hub's force channel
DP_FROM_HUB = "the hub's horizontal force channel (no drawbar-pull cell)"


def _dp_from_hub(cmap: ChannelMap, provided: set[str]) -> dict:
    """``{"dp_n": ...}`` when the map feeds ``dp_n`` from the source field of a wrench column
    (a rig without a drawbar-pull cell: DP is the hub's horizontal force), else {}."""
    dp = next((c for c in cmap.channels if c.column == "dp_n"), None)
    if dp is None or "dp_n" not in provided:
        return {}
    hub = [c.column for c in cmap.channels if c.column in WRENCH_COLUMNS.values()
           and (c.topic, c.field) == (dp.topic, dp.field)]
    return {"dp_n": {"method": DP_FROM_HUB, "channel": f"{dp.topic}.{dp.field}",
                     "same_as": hub}} if hub else {}


def _check_clocks(path: Path, timing: dict[str, StreamTiming]) -> None:
    """All streams must count from the run start: a run longer than MAX_RUN_S is a clock error."""
    start = min(s.t0_s for s in timing.values())
    for topic, s in timing.items():
        if s.t1_s - start > MAX_RUN_S:
            raise IngestError(path, topic, f"time stamps reach {s.t1_s - start:.6g} s after the "
                              f"run start (over {MAX_RUN_S / 3600:g} h): t_ns must count from "
                              "the run start; is this stream on another clock?")
    grid, _ = grid_size(list(timing.values()))
    recorded = max(s.n for s in timing.values())
    if grid > MAX_GRID_PER_SAMPLE * max(recorded, 1):
        raise IngestError(path, None, f"the streams span {grid} samples of the time base but "
                          f"the longest holds {recorded}: a time stamp far from the others? "
                          "(t_ns must count from the run start)")


def _timing_problems(timing: dict[str, StreamTiming]) -> list[Problem]:
    problems = []
    for topic, s in timing.items():
        if s.n < 2:
            problems.append(Problem("warning", topic, "only one sample; no rate, no interpolation"))
            continue
        if s.gaps:
            total = sum(b - a for a, b in s.gaps)
            first = s.gaps[0]
            problems.append(Problem("warning", topic, f"{len(s.gaps)} gap(s) longer than "
                                    f"{GAP_FACTOR:g} sample intervals, {total:.3f} s in all, first "
                                    f"{first[0]:.3f}-{first[1]:.3f} s; NaN there on the time base"))
        if s.dropped:
            problems.append(Problem("warning", topic, f"about {s.dropped} dropped samples "
                                    f"(intervals {DROP_FACTOR:g}-{GAP_FACTOR:g}x the median)"))
        if s.jitter > JITTER_LIMIT:
            problems.append(Problem("warning", topic, f"irregular clock: interval std is "
                                    f"{100 * s.jitter:.0f}% of the median interval"))
    return problems


def _channel_table(streams, timing, metadata: RunMetadata, provided: set[str],
                   problems: list[Problem]) -> tuple[pd.DataFrame, dict]:
    """Every stream (arrays by column) onto one uniform grid, then the derived signals on it."""
    grid, rate = common_grid(list(timing.values()))
    table: dict[str, np.ndarray] = {"t_s": grid}
    for topic, columns in streams.items():
        t = columns["t_s"]
        mask = grid_mask(t, timing[topic], grid)
        for column, values in columns.items():
            if column != "t_s":
                table[column] = to_grid(t, values, grid, mask)
    derivation: dict = {"time_base": {
        "rate_hz": rate, "t0_s": float(grid[0]), "samples": len(grid),
        "method": "uniform grid at the fastest stream's median rate (capped at 1000 Hz); "
                  "linear interpolation; NaN outside a stream's span and inside its gaps",
        "gap_factor": GAP_FACTOR}}
    _derive_rates(table, streams, rate, metadata, provided, derivation)
    _derive_heights(table, metadata, provided, derivation, problems)
    for column in CANONICAL + DERIVED:
        if column not in table:
            table[column] = np.full(len(grid), np.nan)
    order = ["t_s", *CANONICAL, *(c for c in DERIVED if c not in CANONICAL)]
    order += sorted(set(table) - set(order))  # extra columns a channel map adds
    return pd.DataFrame({c: table[c] for c in order}, copy=False), derivation  # arrays made here


def _derive_rates(table, streams, rate, metadata, provided, derivation) -> None:
    radius = metadata.wheel.radius_m
    for position, rate_column in (("wheel_angle_rad", "wheel_omega_radps"),
                                  ("sled_position_m", "sled_velocity_mps")):
        if rate_column in provided:
            derivation[rate_column] = {"method": "direct from source (channel map)"}
            continue
        if position not in provided:
            continue
        columns = next(c for c in streams.values() if position in c)
        stats = derive.encoder_noise(columns["t_s"], columns[position])
        window_s = derive.choose_window_s(stats)
        table[rate_column], window = derive.savgol_derivative(table[position], rate, window_s)
        derivation[rate_column] = {
            "method": "savitzky_golay_derivative", "of": position, "polyorder": derive.POLYORDER,
            "window_s": window / rate, "window_samples": window,
            "target_relative_error": derive.TARGET_REL_ERROR, **stats}
    if "wheel_surface_speed_mps" in provided and "wheel_omega_radps" not in table:
        table["wheel_omega_radps"] = table["wheel_surface_speed_mps"] / radius
        derivation["wheel_omega_radps"] = {"method": "wheel_surface_speed_mps / radius_m"}
    elif "wheel_omega_radps" in table and "wheel_surface_speed_mps" not in provided:
        table["wheel_surface_speed_mps"] = radius * table["wheel_omega_radps"]
        derivation["wheel_surface_speed_mps"] = {"method": "radius_m * wheel_omega_radps",
                                                 "radius_m": radius}
    if "wheel_surface_speed_mps" in table and "sled_velocity_mps" in table:
        eps = derive.slip_eps(metadata.run.condition.velocity_set_mps,
                              table["wheel_surface_speed_mps"], table["sled_velocity_mps"])
        table["slip"] = derive.slip(table["wheel_surface_speed_mps"],
                                    table["sled_velocity_mps"], eps)
        derivation["slip"] = {"method": "spec: (r*omega - v)/(r*omega) driving, "
                                        "(r*omega - v)/v skid (r*omega < v)",
                              "nan_below_mps": eps,
                              "nan_rule": "max(r*omega, v) <= nan_below_mps"}


def _derive_heights(table, metadata, provided, derivation, problems) -> None:
    if "suspension_angle_rad" in provided:
        s = metadata.suspension
        table["hub_height_m"] = derive.hub_height_m(table["suspension_angle_rad"],
                                                    s.arm_length_m, s.angle_zero_rad)
        derivation["hub_height_m"] = {"method": "spec: arm_length_m*(sin(angle)"
                                                "-sin(angle_zero_rad))",
                                      "arm_length_m": s.arm_length_m,
                                      "angle_zero_rad": s.angle_zero_rad}
    elif "hub_height_m" in provided:
        derivation["hub_height_m"] = {"method": "direct from source (channel map)"}
    else:
        return
    stiffness = metadata.wheel.stiffness_n_per_mm
    fz = table.get("fz_n")
    if stiffness is not None and fz is None:
        problems.append(Problem("warning", "sinkage_m", "flexible wheel but no fz_n: sinkage "
                                "cannot remove the wheel's own deflection; column is NaN"))
    table["sinkage_m"] = derive.sinkage_m(table["hub_height_m"], fz, stiffness)
    derivation["sinkage_m"] = (
        {"method": "spec rigid: -hub_height_m"} if stiffness is None else
        {"method": "spec flexible: -hub_height_m - fz_n/(1000*stiffness_N_per_mm)",
         "stiffness_n_per_mm": stiffness})


def _frame_problems(frames: dict[str, FrameIndex], metadata: RunMetadata) -> list[Problem]:
    problems = []
    if "/camera/side" in frames and metadata.camera is None:
        problems.append(Problem("warning", "/camera/side", "frames without swt.camera metadata "
                                "(px_per_m): soil flow cannot be scaled"))
    if "/camera/track" in frames and metadata.camera_track is None:
        problems.append(Problem("warning", "/camera/track", "photos without swt.camera_track "
                                "metadata (px_per_m)"))
    return problems
