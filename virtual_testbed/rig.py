"""The simulated rig: wheel geometry, parallel suspension and run timeline."""

from __future__ import annotations

from dataclasses import dataclass, replace

from swtlab_base.domain import Wheel

__all__ = ["BB2_WHEEL", "Suspension", "Timeline", "Wheel"]

#: ExoMars BB2-like flexible wheel (radius 125 mm without grousers, 12 grousers of 9.2 mm);
#: its radial stiffness is the one of terramechanics/models/bb2_sand.toml (30 kN/m).
BB2_WHEEL = Wheel(name="BB2-like", radius_m=0.125, width_m=0.112, grouser_count=12,
                  grouser_height_m=0.0092, stiffness_n_per_mm=30.0)


@dataclass(frozen=True)
class Suspension:
    """Parallel-suspension arm: ``h = arm_length_m*(sin(angle) - sin(angle_zero_rad))``."""

    arm_length_m: float = 0.60
    angle_zero_rad: float = 0.05


@dataclass(frozen=True)
class Timeline:
    """Phases of a run in seconds: rest, acceleration, transient, stable, stop.

    The transient lasts ``settle_time_s`` after the end of the acceleration
    (about 25 s at 40 m/h on ES-3); the stable phase runs from there until the
    deceleration at the end of the bin.
    """

    rest_s: float = 2.0
    accel_s: float = 2.0
    settle_time_s: float = 25.0
    stable_s: float = 28.0
    decel_s: float = 2.0
    rest_end_s: float = 1.0

    @property
    def motion_start_s(self) -> float:
        return self.rest_s

    @property
    def window_start_s(self) -> float:
        return self.rest_s + self.accel_s + self.settle_time_s

    @property
    def decel_start_s(self) -> float:
        return self.window_start_s + self.stable_s

    @property
    def duration_s(self) -> float:
        return self.decel_start_s + self.decel_s + self.rest_end_s

    def with_duration(self, duration_s: float) -> "Timeline":
        """Same phases, stable phase stretched or shrunk to the given total duration."""
        stable_s = duration_s - (self.duration_s - self.stable_s)
        if stable_s <= 0:
            raise ValueError(f"duration {duration_s} s leaves no stable phase")
        return replace(self, stable_s=stable_s)
