"""Sample checks that make a run unusable (IngestError): bad time stamps, NaN/inf samples."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd

from ingest.errors import IngestError
from ingest.raw import RawTopic


def check_topic(path: Path, topic: str, raw: RawTopic) -> None:
    """Time stamps finite and strictly increasing; every sample of every field finite."""
    t = raw.t_s
    if len(t) == 0:
        raise IngestError(path, topic, "no samples")
    bad_t = ~np.isfinite(t)
    if bad_t.any():
        raise IngestError(path, f"{topic}.t", f"{int(bad_t.sum())} time stamps are NaN/inf")
    step = np.diff(t)
    back = np.flatnonzero(step < 0)
    if len(back):
        i = back[0]
        raise IngestError(path, topic, f"time stamps go backwards {len(back)} times, first at "
                          f"t={t[i]:.6f} s -> {t[i + 1]:.6f} s; samples must be in time order")
    same = np.flatnonzero(step == 0)
    if len(same):
        raise IngestError(path, topic, f"{len(same)} duplicate time stamps, first at "
                          f"t={t[same[0]]:.6f} s; each sample needs its own time")
    for name, values in raw.fields.items():
        if len(values) != len(t):
            raise IngestError(path, f"{topic}.{name}",
                              f"{len(values)} values for {len(t)} time stamps")
        bad = ~np.isfinite(values)
        if bad.any():
            first = int(np.argmax(bad))
            raise IngestError(path, f"{topic}.{name}", f"{int(bad.sum())} NaN/inf samples, first "
                              f"at t={t[first]:.6f} s; fix or drop them at the source")


def numeric_column(path: Path, frame: pd.DataFrame, column: str, first_row: int) -> np.ndarray:
    """A text-table column as float64; a non-numeric cell is an IngestError naming the first
    one (``first_row``: the file's line number of the frame's first data row)."""
    values = pd.to_numeric(frame[column], errors="coerce").to_numpy(np.float64)
    bad = np.isnan(values) & frame[column].notna().to_numpy()
    if bad.any():
        row = int(np.argmax(bad))
        raise IngestError(path, column, f"{int(bad.sum())} non-numeric values, first in line "
                          f"{row + first_row}: {frame[column].iloc[row]!r}")
    return values
