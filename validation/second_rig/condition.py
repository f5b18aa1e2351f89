"""What the second rig is told: the wheel, the run conditions and the caller's truth.

The rig knows no wheel-soil physics. For each condition a caller's truth (a callable or a
table keyed by run id) gives the true steady values in :data:`TRUTH_KEYS`; the rig only turns
them into signals and sensor readings.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from dataclasses import asdict, dataclass, field

from swtlab_base.errors import InputError

STANDARD_GRAVITY_MPS2 = 9.80665
MODES = ("speed_control", "towed", "free_sled")
#: keys a truth must give for every condition (SI units; slip per the raw-run spec)
TRUTH_KEYS = ("slip", "travel_velocity_mps", "wheel_load_n", "dp_n", "torque_nm", "sinkage_m")


class SecondRigError(InputError, ValueError):
    """Bad input to the second rig (one line)."""


@dataclass(frozen=True)
class WheelGeometry:
    """The test wheel: radius without grousers, width, grousers; ``stiffness_n_per_mm`` only
    for a flexible wheel (its hub drops by ``fz / (1000 k)``, raw-run spec)."""

    name: str = "second_rig_wheel"
    radius_m: float = 0.1
    width_m: float = 0.09
    grouser_count: int = 15
    grouser_height_m: float = 0.008
    stiffness_n_per_mm: float | None = None

    def __post_init__(self):
        if not (self.radius_m > 0 and self.width_m > 0 and self.grouser_height_m >= 0):
            raise SecondRigError(f"wheel {self.name!r}: radius and width must be > 0, "
                                 "grouser height >= 0")
        if self.grouser_count < 0 or (self.stiffness_n_per_mm is not None
                                      and not self.stiffness_n_per_mm > 0):
            raise SecondRigError(f"wheel {self.name!r}: grouser_count >= 0 and stiffness > 0")


@dataclass(frozen=True)
class RunCondition:
    """One run's test condition. ``slip_setpoint`` only (and always) for ``speed_control``."""

    run_id: str
    mode: str
    load_n: float
    slip_setpoint: float | None = None
    multipass: int = 0
    gravity_mps2: float = STANDARD_GRAVITY_MPS2
    velocity_mps: float = 0.01
    soil: str = "second_rig_sand"
    campaign: str = "second_rig"
    wheel: WheelGeometry = field(default_factory=WheelGeometry)

    def __post_init__(self):
        if self.mode not in MODES:
            raise SecondRigError(f"run {self.run_id!r}: mode {self.mode!r} not one of {MODES}")
        if (self.mode == "speed_control") != (self.slip_setpoint is not None):
            raise SecondRigError(f"run {self.run_id!r}: slip_setpoint is set for speed_control "
                                 "and only for it")
        if self.slip_setpoint is not None and not -1 < self.slip_setpoint < 1:
            raise SecondRigError(f"run {self.run_id!r}: slip_setpoint must lie in (-1, 1)")
        if not (self.load_n > 0 and self.velocity_mps > 0 and self.gravity_mps2 > 0):
            raise SecondRigError(f"run {self.run_id!r}: load, velocity and gravity must be > 0")
        if self.multipass < 0 or not self.run_id or any(c in self.run_id for c in "/\\ "):
            raise SecondRigError(f"run {self.run_id!r}: multipass >= 0 and a run id without "
                                 "slashes or spaces")

    def to_dict(self) -> dict:
        return asdict(self)


Truth = Callable[[RunCondition], Mapping[str, float]] | Mapping[str, Mapping[str, float]]


def wheel_omega_radps(slip: float, velocity_mps: float, radius_m: float) -> float:
    """Wheel speed from the spec's slip: ``r w = v/(1-s)`` driving, ``r w = v (1+s)`` skid."""
    surface_mps = velocity_mps / (1.0 - slip) if slip >= 0 else velocity_mps * (1.0 + slip)
    return surface_mps / radius_m


def steady_truth(truth: Truth, condition: RunCondition) -> dict[str, float]:
    """The caller's steady values for one condition, checked, with the derived quantities
    (omega, thrust ``T/r``, resistance ``T/r - DP``) in the names of ``swtlab results``."""
    raw = truth.get(condition.run_id) if isinstance(truth, Mapping) else truth(condition)
    if raw is None:
        raise SecondRigError(f"run {condition.run_id!r}: the truth table has no row for it")
    missing = [k for k in TRUTH_KEYS if k not in raw]
    if missing:
        raise SecondRigError(f"run {condition.run_id!r}: truth lacks {missing}")
    values = {k: float(raw[k]) for k in TRUTH_KEYS}
    if not all(math.isfinite(v) for v in values.values()):
        raise SecondRigError(f"run {condition.run_id!r}: truth not finite: {values}")
    if not (-1 < values["slip"] < 1 and values["travel_velocity_mps"] > 0
            and values["wheel_load_n"] > 0 and values["sinkage_m"] >= 0):
        raise SecondRigError(f"run {condition.run_id!r}: truth needs slip in (-1, 1), "
                             f"velocity > 0, load > 0, sinkage >= 0: {values}")
    if condition.mode == "free_sled":
        values["dp_n"] = 0.0  # no tether: the DP cell carries no force
    r = condition.wheel.radius_m
    values["wheel_omega_radps"] = wheel_omega_radps(values["slip"],
                                                    values["travel_velocity_mps"], r)
    values["thrust_n"] = values["torque_nm"] / r
    values["resistance_n"] = values["thrust_n"] - values["dp_n"]
    return values
