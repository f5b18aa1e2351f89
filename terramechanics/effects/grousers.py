"""Grousers: a larger shear radius and the thrust of the grouser faces.

Shear radius ``r_s = r + lambda h`` (Ding, Gao, Deng, Tao 2011, J. Terramech.
48(1):27-45, "equivalent radius" with 0 <= lambda <= 1): the shear displacement,
the shear forces and their moment use ``r_s``. Thrust of the grousers in contact
(``N (theta_1 - theta_2)/(2 pi)`` of them): each face pushes the soil with the
Rankine/Bekker passive earth pressure per width ``gamma h^2 N_phi / 2 + 2 c h
sqrt(N_phi)``, ``N_phi = tan^2(45 deg + phi/2)`` (Bekker 1969, "Introduction to
terrain-vehicle systems", ch. 8; Wong 2008, ch. 2), mobilised
like the shear, by ``1 - exp(-j_exit/K)``; its moment arm is ``r - delta + h/2``.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from terramechanics.effects.base import Effect
from terramechanics.state import ExtraForces


@dataclass(frozen=True)
class Grousers(Effect):
    """``shear_radius_factor`` lambda of r_s = r + lambda h (Ding et al. 2011)."""

    shear_radius_factor: float = 0.5
    name = "grousers"
    terms = ("grouser_thrust_n",)

    def geometry(self, geo, cond, wheel):
        offset = self.shear_radius_factor * wheel.grouser_height_m
        return replace(geo, shear_offset_m=np.full(np.shape(cond.slip), offset))

    def forces(self, contact, soil, geo, cond, wheel):
        h = wheel.grouser_height_m
        n_phi = np.tan(np.pi / 4 + soil.phi_rad / 2) ** 2
        passive = (0.5 * soil.unit_weight_n_m3 * h**2 * n_phi
                   + 2 * soil.cohesion_pa * h * np.sqrt(n_phi))
        engaged = wheel.grouser_count * (contact.theta1_rad - contact.theta2_rad) / (2 * np.pi)
        j = contact.exit_shear_displacement_m
        mobilised = np.sign(j) * -np.expm1(-np.abs(j) / soil.shear_modulus_m)
        thrust = mobilised * engaged * wheel.width_m * passive
        return ExtraForces(dp_n=thrust, torque_nm=thrust * (geo.arm_radius_m + h / 2),
                           terms={"grouser_thrust_n": thrust})
