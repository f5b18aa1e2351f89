"""Grousers after Bekker: shear at the grouser tips plus the side shear of the soil blocks.

Bekker (1956) "Theory of land locomotion", ch. 8; Wong, Theory of Ground Vehicles (4th
ed. 2008), sec. 2.4: the soil between the grousers moves with the wheel, so it shears on
the surface through the grouser tips and, at both wheel edges, on the two sides of the
soil blocks; the thrust of a grousered running gear is::

    F = (A c + W tan phi)(1 + 0.64 (h/b) arccot(h/b))

Here the shear acts on the radius ``r_s = r + lambda h`` (lambda = 1: the tip surface
of Bekker's picture; Ding, Gao, Deng & Tao 2011, J. Terramech. 48(1):27-45, fit
0 <= lambda <= 1 per wheel), and the side-shear factor multiplies the shear strength
``c + sigma tan phi`` of the contact (``c`` and ``tan phi`` scaled). The grouser faces
add nothing else: their push on the trapped soil is what this shear carries (adding a
passive earth pressure per grouser on top would count the grousers twice). Derived for
track grousers in cohesive-frictional soils with the grouser spacing shorter than the
contact; it holds for dense lugs (several in contact), not for one or two.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from terramechanics.effects.base import Effect, FitParam


def side_shear_factor(height_m: float, width_m: float) -> float:
    """Bekker's ``1 + 0.64 (h/b) arccot(h/b)`` (1 for h = 0)."""
    ratio = height_m / width_m
    return 1.0 + 0.64 * ratio * np.arctan2(1.0, ratio) if ratio > 0 else 1.0


@dataclass(frozen=True)
class GrousersBekker1956(Effect):
    """``shear_radius_factor`` lambda of r_s = r + lambda h (1 = grouser tips)."""

    shear_radius_factor: float = 1.0
    name = "grousers"
    law = "bekker1956"
    fit = (FitParam("shear_radius_factor", 0.5, 0.0, 1.5),)

    def soil(self, soil, cond, wheel):
        factor = side_shear_factor(wheel.grouser_height_m, wheel.width_m)
        return replace(soil, cohesion_pa=soil.cohesion_pa * factor,
                       phi_rad=np.arctan(factor * np.tan(soil.phi_rad)))

    def geometry(self, geo, soil, cond, wheel):
        offset = self.shear_radius_factor * wheel.grouser_height_m
        return replace(geo, shear_offset_m=np.full(np.shape(cond.slip), offset))
