"""CSV form reader (spec: "CSV form"): ``run.json`` + one ``<topic>.csv`` per topic + frames."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pandas as pd

from ingest.channel_map import ChannelMap
from ingest.checks import numeric_column
from ingest.cut_short import CUT_LINE, last_line_cut
from ingest.errors import IngestError
from ingest.raw import FrameIndex, RawRun, RawTopic

IMAGE_SUFFIXES = (".png", ".jpg", ".jpeg")
VIDEO_SUFFIXES = (".mp4", ".avi", ".mkv")


def read_run_json(path: Path) -> dict[str, dict]:
    """The metadata records of a spec ``run.json`` (``{"run": {...}, "wheel": {...}}``)."""
    try:
        records = json.loads(path.read_text(encoding="utf-8"))
    except OSError as exc:
        raise IngestError(path, None, f"cannot read: {exc.strerror}") from None
    except (ValueError, RecursionError) as exc:
        why = "nested too deeply" if isinstance(exc, RecursionError) else exc
        raise IngestError(path, None, f"not valid JSON: {why}") from None
    if not isinstance(records, dict) or not all(isinstance(v, dict) for v in records.values()):
        raise IngestError(path, None, 'expected {"run": {...}, "wheel": {...}, ...}')
    return records


def read_csv_run(folder: Path, cmap: ChannelMap) -> RawRun:
    """Raw topics of a CSV run folder, the records of its ``run.json``, and its frames."""
    folder = Path(folder)
    records = read_run_json(folder / "run.json")
    topics, cut = {}, []
    for topic in cmap.topics:
        specs = cmap.channels_of(topic)
        csv_path = folder / specs[0].csv_name
        if not csv_path.resolve().is_relative_to(folder.resolve()):
            raise IngestError(folder, topic, f"channel map {cmap.name}: {specs[0].csv_name} "
                              "lies outside the run's folder; a map may only name files in it")
        if csv_path.is_file():
            topics[topic], cut_here = _read_topic(csv_path, cmap, {c.csv_column or c.field:
                                                                   c.field for c in specs})
            if cut_here:
                cut.append(csv_path.name)
    frames = {}
    side = _side_frames(folder)
    if side is not None:
        frames["/camera/side"] = side
    track = folder / "camera_track"
    if track.is_dir():
        files = tuple(sorted(p for p in track.iterdir() if p.suffix.lower() in IMAGE_SUFFIXES))
        frames["/camera/track"] = FrameIndex("/camera/track", np.full(len(files), np.nan),
                                             folder, files=files)
    return RawRun(path=folder, records=records, topics=topics, frames=frames,
                  cut_short=f"{', '.join(cut)}: {CUT_LINE}" if cut else None)


def _read_topic(path: Path, cmap: ChannelMap, fields: dict[str, str]) -> tuple[RawTopic, bool]:
    """One topic CSV: a header row, the time column first, then the fields (CSV column ->
    source field name); other columns are ignored, absent ones are left to the coverage check.
    True beside it when its last line was cut (and dropped)."""
    try:
        frame = pd.read_csv(path, engine="c")
    except (OSError, ValueError, pd.errors.ParserError) as exc:
        raise IngestError(path, None, f"cannot parse CSV: {exc}") from None
    cut = last_line_cut(path)
    if cut:
        frame = frame.iloc[:-1]  # a row the logger did not finish (ingest.cut_short)
    if len(frame.columns) == 0 or frame.columns[0] != cmap.time_column:
        raise IngestError(path, cmap.time_column, f"first column must be {cmap.time_column!r} "
                          f"(found {frame.columns[0] if len(frame.columns) else 'none'!r})")
    wanted = {cmap.time_column: "t", **fields}
    out = {}
    for column, name in wanted.items():
        if column not in frame.columns:
            continue
        out[name] = numeric_column(path, frame, column, first_row=2)  # after the header
    t = out.pop("t") * cmap.time_scale_s
    return RawTopic(t_s=t, fields=out), cut


def _side_frames(folder: Path) -> FrameIndex | None:
    """``camera_side/<t_ns>.png|jpg`` files, or ``camera_side.<video>`` with ``camera_side.csv``."""
    images = folder / "camera_side"
    if images.is_dir():
        files = sorted((p for p in images.iterdir() if p.suffix.lower() in IMAGE_SUFFIXES),
                       key=lambda p: int(p.stem) if p.stem.isdigit() else -1)
        bad = [p.name for p in files if not p.stem.isdigit()]
        if bad:
            raise IngestError(images / bad[0], "/camera/side", "frame names must be <t_ns>.png|jpg")
        t_s = np.array([int(p.stem) for p in files], dtype=np.int64) * 1e-9
        return FrameIndex("/camera/side", t_s, folder, files=tuple(files))
    videos = [folder / f"camera_side{s}" for s in VIDEO_SUFFIXES
              if (folder / f"camera_side{s}").is_file()]
    if not videos:
        return None
    index = folder / "camera_side.csv"
    try:
        table = pd.read_csv(index)
        t_s = table.sort_values("frame")["t_s"].to_numpy(np.float64)
    except (OSError, KeyError, ValueError) as exc:
        raise IngestError(index, "/camera/side",
                          f"video needs camera_side.csv (frame, t_s): {exc}") from None
    return FrameIndex("/camera/side", t_s, folder, video=videos[0])
