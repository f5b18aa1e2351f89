"""Wheel performance law: steady-state forces and sinkage at a test condition.

The virtual testbed takes its ground truth from a :class:`PerformanceLaw`. The
placeholder here stands in until the terramechanics model lands; any object with
the same ``evaluate`` method (and ``radius_m``/``parameters``) replaces it.

Sign conventions follow the raw-run spec: ``dp_n`` > 0 pulls forward,
``torque_nm`` > 0 drives the wheel, thrust is ``torque/r`` and motion
resistance is ``thrust - dp``.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass
from typing import Protocol

import numpy as np
from scipy.optimize import brentq

STANDARD_GRAVITY_MPS2 = 9.80665


class PerformanceLaw(Protocol):
    """Steady-state wheel performance, vectorised over load and slip."""

    radius_m: float

    def evaluate(self, load_n, slip, multipass: int, gravity_mps2: float) -> dict[str, np.ndarray]:
        """Return arrays ``dp_n``, ``torque_nm``, ``thrust_n``, ``resistance_n``, ``sinkage_m``."""
        ...

    def parameters(self) -> dict[str, float | str]:
        """The law's name and parameters, written into the truth."""
        ...


@dataclass(frozen=True)
class PlaceholderLaw:
    """Plausible BB2-like wheel on loose sand, not a physical model.

    Thrust follows a Janosi-Hanamoto-like saturation in slip (Wong, *Theory of
    Ground Vehicles*, 4th ed., sec. 2.4), offset so that an unpowered wheel
    skids slightly (``towed_skid``). Sinkage grows with load as
    ``(W/W_ref)^sinkage_load_exponent`` (Bekker pressure-sinkage with n ~ 1,
    exponent 2/(2n+1)) and linearly with |slip| (slip-sinkage, Lyasko 2010).
    Motion resistance is proportional to sinkage (compaction/bulldozing).
    Magnitudes at 180 N on undisturbed sand: resistance ~18 N near zero slip,
    DP/W ~0.45 at 90 % slip, sinkage 10-25 mm. Multipass 1 (the wheel's own
    compacted rut) sinks and resists less and grips slightly more.
    Gravity is recorded but ignored by the placeholder.
    """

    radius_m: float = 0.125
    reference_load_n: float = 180.0
    thrust_coefficient_max: float = 0.85
    thrust_slip_scale: float = 0.50
    towed_skid: float = -0.02
    sinkage_ref_m: float = 0.010
    sinkage_load_exponent: float = 0.6
    slip_sinkage_gain: float = 1.5
    resistance_coefficient_ref: float = 0.10
    resistance_load_exponent: float = 0.3
    multipass_sinkage_factor: float = 0.6
    multipass_resistance_factor: float = 0.7
    multipass_thrust_factor: float = 1.05

    def evaluate(self, load_n, slip, multipass: int, gravity_mps2: float = STANDARD_GRAVITY_MPS2):
        load_n, slip = np.broadcast_arrays(np.asarray(load_n, float), np.asarray(slip, float))
        compacted = multipass >= 1
        mu_max = self.thrust_coefficient_max * (self.multipass_thrust_factor if compacted else 1.0)
        offset = slip - self.towed_skid
        thrust_n = load_n * mu_max * np.sign(offset) * (
            1.0 - np.exp(-np.abs(offset) / self.thrust_slip_scale))
        load_ratio = load_n / self.reference_load_n
        slip_factor = 1.0 + self.slip_sinkage_gain * np.abs(slip)
        sinkage_m = (self.sinkage_ref_m * load_ratio ** self.sinkage_load_exponent * slip_factor
                     * (self.multipass_sinkage_factor if compacted else 1.0))
        resistance_n = (load_n * self.resistance_coefficient_ref
                        * load_ratio ** self.resistance_load_exponent * slip_factor
                        * (self.multipass_resistance_factor if compacted else 1.0))
        return {
            "dp_n": thrust_n - resistance_n,
            "torque_nm": thrust_n * self.radius_m,
            "thrust_n": thrust_n,
            "resistance_n": resistance_n,
            "sinkage_m": sinkage_m,
        }

    def parameters(self) -> dict[str, float | str]:
        return {"name": type(self).__name__, **asdict(self)}


def _root(law: PerformanceLaw, key: str, load_n: float, multipass: int,
          gravity_mps2: float) -> float:
    def f(s: float) -> float:
        return float(law.evaluate(load_n, s, multipass, gravity_mps2)[key])

    return float(brentq(f, -0.99, 0.99, xtol=1e-10))


def self_propelled_slip(law: PerformanceLaw, load_n: float, multipass: int,
                        gravity_mps2: float = STANDARD_GRAVITY_MPS2) -> float:
    """Slip where the law's drawbar pull is zero (a free sled settles there)."""
    return _root(law, "dp_n", load_n, multipass, gravity_mps2)


def towed_slip(law: PerformanceLaw, load_n: float, multipass: int,
               gravity_mps2: float = STANDARD_GRAVITY_MPS2) -> float:
    """Slip where the law's torque is zero (an unpowered, towed wheel skids there)."""
    return _root(law, "torque_nm", load_n, multipass, gravity_mps2)
