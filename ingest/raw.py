"""What a reader hands on: source fields per topic on native time stamps, plus metadata records."""

from __future__ import annotations

import base64
import json
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ingest.errors import IngestError


@dataclass
class RawTopic:
    """One source topic: ``t_s`` (seconds since run start) and raw field arrays of equal length."""

    t_s: np.ndarray
    fields: dict[str, np.ndarray]


@dataclass(frozen=True)
class FrameIndex:
    """Camera frames of one topic: times and count; images stay undecoded (softflow reads them).

    ``data(i)`` returns the i-th frame's encoded bytes (png/jpeg) lazily.
    """

    topic: str
    t_s: np.ndarray
    source: Path
    files: tuple[Path, ...] = ()
    video: Path | None = None

    @property
    def count(self) -> int:
        return int(len(self.t_s))

    def data(self, index: int) -> bytes:
        """Encoded bytes of frame ``index`` (image file, or the MCAP message's base64 data)."""
        if self.files:
            return self.files[index].read_bytes()
        if self.video is not None:
            raise IngestError(self.video, self.topic, "frames are in a video file; decode it "
                              "with a video reader (softflow) rather than frame by frame bytes")
        from mcap.reader import make_reader

        with open(self.source, "rb") as stream:
            for i, (_, _, message) in enumerate(
                    make_reader(stream).iter_messages(topics=[self.topic], log_time_order=False)):
                if i == index:
                    return base64.b64decode(json.loads(message.data)["data"])
        raise IndexError(f"{self.topic} has {self.count} frames, no frame {index}")

    def to_dict(self) -> dict:
        t = self.t_s[np.isfinite(self.t_s)]
        return {"topic": self.topic, "count": self.count,
                "first_s": float(t[0]) if len(t) else None,
                "last_s": float(t[-1]) if len(t) else None}


@dataclass
class RawRun:
    """A run as read from its files, before mapping, calibration and checks; ``cut_short``:
    why the file looks cut short (``ingest.cut_short``), None for a whole file; ``form``: the
    file's format (``ingest.formats.FORMATS``, or ``delimited``), which says where its
    metadata records live (``ingest.records.FORMS``)."""

    path: Path
    records: dict[str, dict]
    topics: dict[str, RawTopic]
    frames: dict[str, FrameIndex] = field(default_factory=dict)
    cut_short: str | None = None
    form: str = "mcap"
