"""Bulldozing as the Rankine passive earth pressure on the front of the rut.

Terzaghi (1943) "Theoretical soil mechanics", ch. 4 (Rankine's passive state, 1857):
a smooth vertical wall of height z pushed into a cohesive-frictional soil meets, per
width, ``P_p = gamma z^2 N_phi / 2 + 2 c z sqrt(N_phi)``, ``N_phi = tan^2(45 deg +
phi/2)``. Taking the wall as the rut front of depth z (the wheel sinkage) and the
wheel width b: ``R_b = b P_p``, subtracted from the drawbar pull (passive earth
pressure as in Wong, Theory of Ground Vehicles 2008, ch. 2). Rankine's wall has no
wall friction and a plane failure surface, and the rut front is taken vertical: for
shallow ruts this is far smaller than Bekker's curved-front formula
(``bulldozing_bekker1969``, which adds the wedge ahead of the front); it holds for
ruts shallow against the radius. ``coefficient`` scales it (1 = the formula).

Its fit range stays 0-5 though Bekker's formula gives 17-180 times Rankine's on
planetary-wheel ruts (3-40 mm, phi 28-38 deg, c up to 0.8 kPa): widened to 0-1000 to reach
Bekker's resistances (tried in 0.6.0), Rankine's law carried a Bekker bulldozing truth in
size but not in shape, and wheel flexibility patched the shape into confident wrong
"wheel_flexibility + bulldozing" calls on two independent campaigns (docs/gap-report.md,
"0.6.0"). Pinned at 5, such a fit ends on its bound.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from terramechanics.effects.base import Effect, FitParam
from terramechanics.state import ExtraForces


def rankine_passive_n_m(depth_m, cohesion_pa, phi_rad, gamma_n_m3):
    """Rankine passive force per width (N/m) on a vertical wall of height ``depth_m``."""
    n_phi = np.tan(np.pi / 4 + phi_rad / 2) ** 2
    return 0.5 * gamma_n_m3 * depth_m**2 * n_phi + 2 * cohesion_pa * depth_m * np.sqrt(n_phi)


@dataclass(frozen=True)
class BulldozingRankineTerzaghi1943(Effect):
    """``coefficient``: multiplier on the Rankine passive resistance (1 = as published)."""

    coefficient: float = 1.0
    name = "bulldozing"
    law = "rankine_terzaghi1943"
    terms = ("bulldozing_n",)
    fit = (FitParam("coefficient", 0.5, 0.0, 5.0),)

    def forces(self, contact, soil, geo, cond, wheel):
        r_b = self.coefficient * wheel.width_m * rankine_passive_n_m(
            contact.sinkage_m, soil.cohesion_pa, soil.phi_rad, soil.unit_weight_n_m3)
        return ExtraForces(dp_n=-r_b, terms={"bulldozing_n": r_b})
