"""Registry of transient detectors: adding a detector is adding one file that registers itself.

A detector implements ``locate(t_s, signals, period_s, params, gate_start) -> Cut``: given
the time base and signals (name -> array, NaN allowed) from the ramp start (where the
speeds began to move to their set points) to the gate's end, and the index where the gate
opens, it returns the start and stop (exclusive) indices of the stable part, within
``[gate_start, len)``.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Callable, Protocol

import numpy as np


@dataclass(frozen=True)
class Cut:
    """Stable part ``[start, stop)`` of a gated segment (indices into it) and diagnostics."""

    start: int
    stop: int
    diagnostics: dict


class Detector(Protocol):
    name: str
    description: str

    def locate(self, t_s: np.ndarray, signals: dict[str, np.ndarray], period_s: float | None,
               params, gate_start: int) -> Cut: ...


DETECTORS: dict[str, Detector] = {}


def register(detector_cls: Callable[[], Detector]):
    """Class decorator: instantiate and register under its ``name``."""
    instance = detector_cls()
    DETECTORS[instance.name] = instance
    return detector_cls


def get_detector(name: str) -> Detector:
    if name not in DETECTORS:
        raise KeyError(f"unknown stable-phase detector {name!r}; known: {sorted(DETECTORS)}")
    return DETECTORS[name]
