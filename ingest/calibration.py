"""Calibration apart from reading (spec: ``swt.calibration``, ``swt.zero``; channel-map units)."""

from __future__ import annotations

import numpy as np

from ingest import units
from ingest.channel_map import ChannelSpec


def to_canonical(raw: np.ndarray, spec: ChannelSpec,
                 calibration: tuple[float, float] | None) -> np.ndarray:
    """Raw field -> SI values of its canonical column.

    With a ``swt.calibration`` entry, ``gain*raw + offset`` is already SI (spec);
    otherwise the map's scale/offset/zeroing apply in the channel's unit, then the unit.
    """
    if calibration is not None:
        gain, offset = calibration
        return gain * np.asarray(raw, dtype=np.float64) + offset
    values = np.asarray(raw, dtype=np.float64)
    if spec.scale != 1.0 or spec.offset != 0.0:
        values = spec.scale * values + spec.offset
    if spec.zero == "first":
        finite = np.flatnonzero(np.isfinite(values))
        if len(finite):
            values = values - values[finite[0]] + spec.zero_value
    return units.to_si(values, spec.si_unit)


def subtract_zero(values: np.ndarray, offset: float | None) -> np.ndarray:
    """Wrench channel minus its ``swt.zero`` offset (N or N·m; spec)."""
    return values if offset is None else values - offset
