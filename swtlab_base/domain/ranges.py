"""Physical ranges of a run's metadata and channels: one definition for ingest, which refuses
a value outside the *possible* range (no single-wheel testbed holds it: a typo, a unit
slip, a corrupt file), and for the plausibility checks of the results, which flag a value
outside the *plausible* range (possible, but unlike any rover wheel or lab rig).

Plausible wheel sizes span the planetary wheels flown or built (Sojourner r = 0.065 m,
MER 0.13 m, Curiosity 0.25 m, VIPER 0.25 m) and laboratory wheels down to 0.02 m with
margin; stiffness spans stiff elastic wheels to soft tyres (about 1 to 10^4 N/mm).
"""

from __future__ import annotations

import math
from dataclasses import dataclass


@dataclass(frozen=True)
class Range:
    """``possible`` and ``plausible`` closed intervals ``(low, high)`` of one value, in
    ``unit``."""

    possible: tuple[float, float]
    plausible: tuple[float, float]
    unit: str

    def impossible(self, value: float) -> str | None:
        """Why ``value`` is impossible, or None."""
        low, high = self.possible
        if not (math.isfinite(value) and low <= value <= high):
            return f"{value:g} {self.unit} is outside the possible range {low:g} to {high:g}"
        return None

    def implausible(self, value: float) -> str | None:
        """Why ``value`` is implausible (possible, outside the plausible range), or None."""
        low, high = self.plausible
        if not low <= value <= high:
            return f"{value:g} {self.unit} outside the plausible {low:g}-{high:g} {self.unit}"
        return None


#: metadata ``record.key`` -> its range
METADATA: dict[str, Range] = {
    "wheel.radius_m": Range((1e-3, 10.0), (0.02, 1.0), "m"),
    "wheel.width_m": Range((1e-3, 10.0), (0.01, 1.0), "m"),
    "wheel.grouser_count": Range((0, 1000), (0, 100), ""),
    "wheel.grouser_height_m": Range((0.0, 1.0), (0.0, 0.05), "m"),
    "wheel.stiffness_N_per_mm": Range((1e-3, 1e7), (1.0, 1e4), "N/mm"),
    "wheel.mass_kg": Range((1e-4, 1e4), (0.01, 500.0), "kg"),
    "run.load_N": Range((1e-3, 1e6), (1.0, 1e4), "N"),
    "run.velocity_mps": Range((0.0, 100.0), (0.0, 2.0), "m/s"),
    "run.wheel_surface_speed_setpoint_mps": Range((0.0, 100.0), (0.0, 4.0), "m/s"),
    "run.gravity_mps2": Range((1e-3, 100.0), (1.0, 25.0), "m/s^2"),
    "run.steer_deg": Range((-90.0, 90.0), (-60.0, 60.0), "deg"),
    "run.multipass": Range((0, 10000), (0, 100), ""),
    "suspension.arm_length_m": Range((1e-3, 100.0), (0.05, 5.0), "m"),
    "suspension.angle_zero_rad": Range((-2 * math.pi, 2 * math.pi), (-math.pi / 2, math.pi / 2),
                                       "rad"),
    "camera.px_per_m": Range((1e-3, 1e9), (10.0, 1e7), "px/m"),
    "camera.wheel_radius_px": Range((1e-3, 1e6), (1.0, 1e5), "px"),
    "camera_track.px_per_m": Range((1e-3, 1e9), (10.0, 1e7), "px/m"),
    "zero": Range((-1e6, 1e6), (-1e4, 1e4), "N or N*m"),
}

#: the wheel geometry checked for plausibility (metadata key -> ``Wheel`` field)
WHEEL_KEYS = {"wheel.radius_m": "radius_m", "wheel.width_m": "width_m",
              "wheel.grouser_count": "grouser_count",
              "wheel.grouser_height_m": "grouser_height_m",
              "wheel.stiffness_N_per_mm": "stiffness_n_per_mm"}

#: largest magnitude a channel of each quantity can read on a single-wheel testbed, SI
#: (a channel beyond it after calibration and zeroing is a wrong gain, offset or unit)
CHANNEL_LIMITS: dict[str, float] = {
    "force": 1e6, "torque": 1e5, "angle": 1e8, "length": 1e4, "velocity": 1e3,
    "angular_velocity": 1e5, "time": 1e6, "dimensionless": 1e6,
}

#: channels bounded tighter than their quantity: an arm or slip angle turns less than a turn
COLUMN_LIMITS: dict[str, float] = {"suspension_angle_rad": 2 * math.pi,
                                   "slip_angle_rad": 2 * math.pi}

