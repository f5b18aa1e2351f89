"""A second-rig truth from a terramechanics model: ``condition -> steady values``.

The second rig knows no wheel-soil physics (validation/second_rig); this callable gives it a
model's curves (``WheelModel.curves``: the Wong-Reece equilibrium, Wong & Reece 1967, J.
Terramechanics 4(1), with the model's effects). Towed: the slip where the torque is 0; free
sled: where the drawbar pull is 0; speed control: the set point.
"""

from __future__ import annotations

import numpy as np

import terramechanics as tm
from validation.second_rig import RunCondition

#: slips searched for the towed and free-sled roots
SLIP_GRID = np.linspace(-0.6, 0.9, 301)


class ModelTruth:
    """``condition -> steady truth`` from a terramechanics model's curves."""

    def __init__(self, model: tm.WheelModel):
        self.model = model

    def _at(self, condition: RunCondition, slip: float) -> dict[str, float]:
        c = self.model.curves(condition.load_n, slip, condition.multipass,
                              condition.gravity_mps2)
        return {"slip": float(slip), "travel_velocity_mps": condition.velocity_mps,
                "wheel_load_n": float(np.asarray(c["fz_n"])), "dp_n": float(c["dp_n"]),
                "torque_nm": float(c["torque_nm"]), "sinkage_m": float(c["sinkage_m"])}

    def _root(self, condition: RunCondition, key: str) -> float:
        """The slip where ``key`` crosses 0 (grid, then linear interpolation)."""
        c = self.model.curves(condition.load_n, SLIP_GRID, condition.multipass,
                              condition.gravity_mps2)[key]
        i = int(np.flatnonzero(np.diff(np.sign(c)) > 0)[0])
        return float(SLIP_GRID[i] - c[i] * (SLIP_GRID[i + 1] - SLIP_GRID[i]) / (c[i + 1] - c[i]))

    def __call__(self, condition: RunCondition) -> dict[str, float]:
        if condition.mode == "towed":
            return self._at(condition, self._root(condition, "torque_nm"))
        if condition.mode == "free_sled":
            return self._at(condition, self._root(condition, "dp_n"))
        return self._at(condition, condition.slip_setpoint)
