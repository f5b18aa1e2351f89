"""The model as the virtual testbed's ground truth (its ``PerformanceLaw`` protocol).

The testbed's convention: thrust is ``torque / r`` and motion resistance is
``thrust - dp`` with the nominal radius, the same ``resistance_n`` the model gives.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from terramechanics.model import WheelModel
from terramechanics.state import EARTH_GRAVITY_MPS2


@dataclass(frozen=True)
class ModelLaw:
    """``evaluate(load_n, slip, multipass, gravity_mps2)`` and ``parameters()`` of a model."""

    model: WheelModel

    @property
    def radius_m(self) -> float:
        return self.model.wheel.radius_m

    def evaluate(self, load_n, slip, multipass: int = 0,
                 gravity_mps2: float = EARTH_GRAVITY_MPS2) -> dict[str, np.ndarray]:
        c = self.model.curves(load_n, slip, multipass=multipass, gravity_mps2=gravity_mps2)
        return {"dp_n": c["dp_n"], "torque_nm": c["torque_nm"],
                "thrust_n": c["torque_nm"] / self.radius_m, "resistance_n": c["resistance_n"],
                "sinkage_m": c["sinkage_m"]}

    def parameters(self) -> dict[str, float | str]:
        return {"name": "terramechanics.WheelModel", "soil": self.model.soil.name,
                "effects": ",".join(self.model.effects),
                "laws": ",".join(f"{n}={e.law}" for n, e in self.model.effects.items()),
                **self.model.parameters()}
