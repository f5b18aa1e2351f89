"""Units a channel map may name, and their conversion to SI (docs/channel-map.md)."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from swtlab_base.domain.gravity import G0_MPS2


@dataclass(frozen=True)
class Unit:
    """``si = factor * value + offset`` for a named unit of one quantity."""

    quantity: str
    factor: float
    offset: float = 0.0


_DEG = math.pi / 180.0
_LBF = 4.4482216152605
_IN = 0.0254

UNITS: dict[str, Unit] = {
    # force
    "N": Unit("force", 1.0), "kN": Unit("force", 1e3), "mN": Unit("force", 1e-3),
    "lbf": Unit("force", _LBF), "kgf": Unit("force", G0_MPS2),
    # torque
    "N·m": Unit("torque", 1.0), "N*m": Unit("torque", 1.0), "Nm": Unit("torque", 1.0),
    "N.m": Unit("torque", 1.0), "N m": Unit("torque", 1.0), "kN*m": Unit("torque", 1e3),
    "N*mm": Unit("torque", 1e-3), "Nmm": Unit("torque", 1e-3), "N·mm": Unit("torque", 1e-3),
    "lbf*in": Unit("torque", _LBF * _IN), "lbf·in": Unit("torque", _LBF * _IN),
    "lbf*ft": Unit("torque", _LBF * 0.3048), "lbf·ft": Unit("torque", _LBF * 0.3048),
    # angle
    "rad": Unit("angle", 1.0), "mrad": Unit("angle", 1e-3), "deg": Unit("angle", _DEG),
    "°": Unit("angle", _DEG), "rev": Unit("angle", 2 * math.pi),
    # length
    "m": Unit("length", 1.0), "cm": Unit("length", 1e-2), "mm": Unit("length", 1e-3),
    "um": Unit("length", 1e-6), "µm": Unit("length", 1e-6), "km": Unit("length", 1e3),
    "in": Unit("length", _IN), "ft": Unit("length", 0.3048),
    # velocity
    "m/s": Unit("velocity", 1.0), "cm/s": Unit("velocity", 1e-2),
    "mm/s": Unit("velocity", 1e-3), "km/h": Unit("velocity", 1 / 3.6),
    "m/h": Unit("velocity", 1 / 3600.0), "m/min": Unit("velocity", 1 / 60.0),
    "in/s": Unit("velocity", _IN), "ft/s": Unit("velocity", 0.3048),
    # angular velocity
    "rad/s": Unit("angular_velocity", 1.0), "deg/s": Unit("angular_velocity", _DEG),
    "rpm": Unit("angular_velocity", 2 * math.pi / 60.0),
    "rev/s": Unit("angular_velocity", 2 * math.pi),
    # time
    "s": Unit("time", 1.0), "ms": Unit("time", 1e-3), "us": Unit("time", 1e-6),
    "µs": Unit("time", 1e-6), "ns": Unit("time", 1e-9), "min": Unit("time", 60.0),
    "h": Unit("time", 3600.0),
    # dimensionless
    "1": Unit("dimensionless", 1.0), "%": Unit("dimensionless", 0.01),
}

#: column-name suffix -> quantity (the SI unit is in the column name, docs/channels.md)
SUFFIX_QUANTITY: dict[str, str] = {
    "_n": "force", "_nm": "torque", "_rad": "angle", "_m": "length", "_mps": "velocity",
    "_radps": "angular_velocity", "_s": "time",
}


def lookup(unit: str) -> Unit | None:
    """The unit named ``unit`` (exact spelling, surrounding blanks ignored), or None."""
    return UNITS.get(unit.strip())


def column_quantity(column: str) -> str:
    """Quantity a canonical column name carries by its unit suffix (``dp_n`` -> force)."""
    for suffix in sorted(SUFFIX_QUANTITY, key=len, reverse=True):
        if column.endswith(suffix):
            return SUFFIX_QUANTITY[suffix]
    return "dimensionless"


def to_si(values: np.ndarray, unit: Unit) -> np.ndarray:
    """Values in ``unit`` converted to SI (float64; the values themselves when already SI)."""
    out = np.asarray(values, dtype=np.float64)
    if unit.factor != 1.0:
        out = out * unit.factor
    return out + unit.offset if unit.offset else out
