"""Sample checks that make a run unusable (IngestError): bad time stamps, NaN/inf samples."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pandas as pd

from ingest.errors import IngestError
from ingest.raw import RawTopic
from ingest.units import column_quantity
from swtlab_base.domain.ranges import CHANNEL_LIMITS, COLUMN_LIMITS


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


#: longest text of a bad cell an error line quotes
MAX_CELL_CHARS = 40


def _float_or_nan(text: str) -> float:
    try:
        return float(text)
    except ValueError:
        return float("nan")


def numeric_column(path: Path, frame: pd.DataFrame, column: str, first_row: int) -> np.ndarray:
    """A text-table column as float64; a non-numeric cell is an IngestError naming the first
    one (``first_row``: the file's line number of the frame's first data row)."""
    try:
        values = pd.to_numeric(frame[column], errors="coerce").to_numpy(np.float64)
    except OverflowError:  # an integer cell beyond float64: inf, which check_topic reports
        values = pd.to_numeric(frame[column].astype(str).map(_float_or_nan),
                               errors="coerce").to_numpy(np.float64)
    bad = np.isnan(values) & frame[column].notna().to_numpy()
    if bad.any():
        row = int(np.argmax(bad))
        cell = repr(frame[column].iloc[row])
        cell = cell if len(cell) <= MAX_CELL_CHARS else cell[:MAX_CELL_CHARS - 3] + "..."
        raise IngestError(path, column, f"{int(bad.sum())} non-numeric values, first in line "
                          f"{row + first_row}: {cell}")
    return values


def check_calibrated(path: Path, where: str, column: str, values: np.ndarray) -> None:
    """A channel after calibration and zeroing: every sample finite and within the
    magnitude its quantity (or column) can have on a testbed (``swtlab_base.domain.ranges``);
    beyond it the gain, offset, zero or unit is wrong."""
    peak = float(np.max(np.abs(values))) if values.size else 0.0  # NaN or inf: some are
    if not math.isfinite(peak):
        raise IngestError(path, where, f"{int((~np.isfinite(values)).sum())} samples of {column} "
                          "are NaN/inf after calibration and zeroing (gain, offset or zero "
                          "overflows)")
    quantity = column_quantity(column)
    limit = COLUMN_LIMITS.get(column, CHANNEL_LIMITS[quantity])
    if peak > limit:
        raise IngestError(path, where, f"{column} reaches {peak:.3g} (SI) after calibration "
                          f"and zeroing, beyond any {quantity} a testbed measures ({limit:g}); "
                          "check gain, offset, zero and unit")
