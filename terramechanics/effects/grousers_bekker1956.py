"""Grousers after Bekker: shear through the grouser tips plus the side shear of the soil blocks.

Bekker (1956) "Theory of land locomotion", ch. 8; Wong, Theory of Ground Vehicles (4th
ed. 2008), ch. 2 (tractive effort of a track with grousers): the soil between the
grousers moves with the running gear, so it shears on the surface through the grouser
tips and, at both edges, on the two vertical sides of the soil blocks (height h); the
sides carry the full cohesion but only part of the normal stress::

    F = b l c (1 + 2h/b) + W tan(phi) (1 + 0.64 (h/b) arccot(h/b))

Here the shear acts on the radius ``r_s = r + lambda h`` (lambda = 1: the tip surface
of Bekker's picture; Ding et al. 2011, J. Terramech. 48(1):27-45, fit
0 <= lambda <= 1 per wheel), and the two factors multiply ``c`` and ``tan phi`` of the
contact's shear strength (the bulldozing laws then see the same strengthened soil).
The grouser faces add nothing else: their push on the trapped soil is what this shear
carries (a passive earth pressure per grouser on top would count the grousers twice).
Derived for track grousers in cohesive-frictional soils; it holds for dense grousers
(several in contact, spacing short against the contact), not for one or two.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from terramechanics.effects.base import Effect, FitParam


def side_shear_factors(height_m: float, width_m: float) -> tuple[float, float]:
    """Bekker's factors on cohesion ``1 + 2h/b`` and on friction ``1 + 0.64 (h/b)
    arccot(h/b)`` (both 1 for h = 0)."""
    ratio = height_m / width_m
    if ratio <= 0:
        return 1.0, 1.0
    return 1.0 + 2.0 * ratio, 1.0 + 0.64 * ratio * np.arctan2(1.0, ratio)


@dataclass(frozen=True)
class GrousersBekker1956(Effect):
    """``shear_radius_factor`` lambda of r_s = r + lambda h (1 = grouser tips)."""

    shear_radius_factor: float = 1.0
    name = "grousers"
    law = "bekker1956"
    fit = (FitParam("shear_radius_factor", 0.5, 0.0, 1.5),)

    def soil(self, soil, cond, wheel):
        on_c, on_tan_phi = side_shear_factors(wheel.grouser_height_m, wheel.width_m)
        return replace(soil, cohesion_pa=soil.cohesion_pa * on_c,
                       phi_rad=np.arctan(on_tan_phi * np.tan(soil.phi_rad)))

    def geometry(self, geo, soil, cond, wheel):
        offset = self.shear_radius_factor * wheel.grouser_height_m
        return replace(geo, shear_offset_m=np.full(np.shape(cond.slip), offset))
