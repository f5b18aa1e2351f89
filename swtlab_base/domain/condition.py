"""The soil and the set point of a run (test condition), validated on construction."""

from __future__ import annotations

import math
from dataclasses import dataclass

from swtlab_base.domain.gravity import G0_MPS2

MODES = ("speed_control", "free_sled", "towed", "steered")


@dataclass(frozen=True)
class Soil:
    """A soil as the lab names it (metadata ``swt.run.soil``); ``description`` optional."""

    name: str
    description: str = ""

    def __post_init__(self) -> None:
        if not isinstance(self.name, str) or not self.name.strip():
            raise ValueError(f"soil name {self.name!r} must be a non-empty text")


@dataclass(frozen=True)
class TestCondition:
    """The set point of one run: ``mode`` (one of :data:`MODES`), set wheel load
    ``load_set_n`` (> 0; the measured load is a result, ``wheel_load_n``), soil passes
    ``multipass`` (>= 0), set slip (speed control), set travel velocity, gravity (default
    g0) and steering angle."""

    __test__ = False  # not a pytest class

    mode: str
    load_set_n: float
    multipass: int
    velocity_set_mps: float
    slip_setpoint: float | None = None
    gravity_mps2: float = G0_MPS2
    steer_deg: float | None = None

    def __post_init__(self) -> None:
        if self.mode not in MODES:
            raise ValueError(f"mode {self.mode!r} not in {MODES}")
        if not (math.isfinite(self.load_set_n) and self.load_set_n > 0):
            raise ValueError(f"load_set_n {self.load_set_n!r} must be > 0 N")
        if int(self.multipass) != self.multipass or self.multipass < 0:
            raise ValueError(f"multipass {self.multipass!r} must be an integer >= 0")
        if not (math.isfinite(self.gravity_mps2) and self.gravity_mps2 > 0):
            raise ValueError(f"gravity_mps2 {self.gravity_mps2!r} must be > 0")
        if not math.isfinite(self.velocity_set_mps):
            raise ValueError(f"velocity_set_mps {self.velocity_set_mps!r} must be finite")
        if self.slip_setpoint is not None and not -1.0 <= self.slip_setpoint <= 1.0:
            raise ValueError(f"slip_setpoint {self.slip_setpoint!r} outside [-1, 1]")
        object.__setattr__(self, "multipass", int(self.multipass))
