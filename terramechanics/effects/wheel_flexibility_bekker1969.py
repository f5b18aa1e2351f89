"""Flexible wheel after Bekker: a flat contact at the wheel's ground pressure.

Bekker (1969) "Introduction to terrain-vehicle systems"; Wong, Theory of Ground
Vehicles (4th ed. 2008), ch. 2 (motion resistance of a tyre): a wheel whose ground
pressure ``p_g`` (inflation plus carcass stiffness, p_i + p_c) is below the pressure
the rigid wheel would put on the soil, ``p_gcr = k z0^n`` with Bekker's rigid-wheel sinkage
``z0 = (3 W / ((3 - n) b k sqrt(D)))^(2/(2n + 1))``, ``k = kc/b + kphi``, flattens:
the flat part carries the load at ``p_g``, so it is ``l = W/(b p_g)`` long, and the
wheel deflects by the chord height ``delta = r - sqrt(r^2 - l^2/4)``. Above p_gcr the
wheel stays rigid. The deflected wheel enters the stress integrals as the equivalent
rigid wheel of the same contact length (``Geometry.contact_radius_m``). Bekker's
criterion for pneumatic tyres on soft soil (p_c from tyre tests); it holds while the
flat part is shorter than the wheel diameter (delta capped at r/2 here) and for wheels
whose carcass supports the load as a membrane (not for stiff-spoked metal wheels).
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from terramechanics.effects.base import Effect, FitParam
from terramechanics.state import ExtraForces


def bekker_rigid_sinkage_m(load_n, diameter_m, width_m, k, n):
    """Bekker's rigid-wheel sinkage ``(3W/((3 - n) b k sqrt(D)))^(2/(2n + 1))``."""
    return (3 * load_n / ((3 - n) * width_m * k * np.sqrt(diameter_m))) ** (2 / (2 * n + 1))


@dataclass(frozen=True)
class WheelFlexibilityBekker1969(Effect):
    """``ground_pressure_pa`` p_g = p_i + p_c of the wheel (Pa)."""

    ground_pressure_pa: float = 20e3
    name = "wheel_flexibility"
    law = "bekker1969"
    terms = ("deflection_m",)
    fit = (FitParam("ground_pressure_pa", 2e4, 2e3, 5e5, log=True),)

    def geometry(self, geo, soil, cond, wheel):
        load = np.asarray(cond.load_n, float)
        r, b = wheel.radius_m, wheel.width_m
        k, n = soil.kc / b + soil.kphi, soil.n0
        critical = k * bekker_rigid_sinkage_m(load, 2 * r, b, k, n) ** n
        half = np.minimum(load / (b * self.ground_pressure_pa) / 2, r * np.sqrt(0.75))
        delta = r - np.sqrt(r**2 - half**2)
        return replace(geo, deflection_m=np.where(self.ground_pressure_pa < critical,
                                                  delta, 0.0))

    def forces(self, contact, soil, geo, cond, wheel):
        return ExtraForces(terms={"deflection_m": np.broadcast_to(
            geo.deflection_m, np.shape(contact.sinkage_m))})
