"""Wheel performance law: steady-state forces and sinkage at a test condition.

The virtual testbed takes its ground truth from a :class:`PerformanceLaw`: by
default swtlab's terramechanics model (:func:`bb2_sand_law`); any object with the
same ``evaluate`` method (and ``radius_m``/``parameters``) replaces it.

Sign conventions follow the raw-run spec: ``dp_n`` > 0 pulls forward,
``torque_nm`` > 0 drives the wheel, thrust is ``torque/r`` and motion
resistance is ``thrust - dp``.
"""

from __future__ import annotations

from typing import Protocol

import numpy as np
from scipy.optimize import brentq

from swtlab_base.domain.gravity import G0_MPS2
from terramechanics import ModelLaw, shipped_model



class PerformanceLaw(Protocol):
    """Steady-state wheel performance, vectorised over load and slip."""

    radius_m: float

    def evaluate(self, load_n, slip, multipass: int, gravity_mps2: float) -> dict[str, np.ndarray]:
        """Return arrays ``dp_n``, ``torque_nm``, ``thrust_n``, ``resistance_n``, ``sinkage_m``."""
        ...

    def parameters(self) -> dict[str, float | str]:
        """The law's name and parameters, written into the truth."""
        ...


def bb2_sand_law() -> PerformanceLaw:
    """The testbed's truth: swtlab's terramechanics model of a BB2-like wheel on sand.

    ``terramechanics/models/bb2_sand.toml`` (Wong-Reece rigid-wheel model with
    grousers, slip-sinkage, wheel flexibility and multipass compaction; see
    docs/model-file.md).
    """
    return ModelLaw(shipped_model("bb2_sand"))


def _root(law: PerformanceLaw, key: str, load_n: float, multipass: int,
          gravity_mps2: float) -> float:
    def f(s: float) -> float:
        return float(law.evaluate(load_n, s, multipass, gravity_mps2)[key])

    return float(brentq(f, -0.99, 0.99, xtol=1e-10))


def self_propelled_slip(law: PerformanceLaw, load_n: float, multipass: int,
                        gravity_mps2: float = G0_MPS2) -> float:
    """Slip where the law's drawbar pull is zero (a free sled settles there)."""
    return _root(law, "dp_n", load_n, multipass, gravity_mps2)


def towed_slip(law: PerformanceLaw, load_n: float, multipass: int,
               gravity_mps2: float = G0_MPS2) -> float:
    """Slip where the law's torque is zero (an unpowered, towed wheel skids there)."""
    return _root(law, "torque_nm", load_n, multipass, gravity_mps2)
