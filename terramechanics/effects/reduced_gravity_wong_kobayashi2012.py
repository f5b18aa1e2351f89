"""Reduced gravity as gravity similitude: every soil strength term scales with rho g.

Wong & Kobayashi (2012) "Further study of the method of approach to testing the
performance of extraterrestrial rovers/rover wheels and related issues", J.
Terramech. 49(6):329-346, found in the parabolic-flight data of Kobayashi et al.
(2010, J. Terramech. 47(4):261-274) little change in the slip-sinkage of a wheel of
the same mass at low gravity. In Reece's (1965) equation ``p = (c k'c + gamma b
k'phi)(z/b)^n`` with Mohr-Coulomb shear that holds exactly when the cohesion of the dry
granular soil scales with the unit weight like the frictional term (an apparent,
stress-induced cohesion): then all stresses go as g, and a wheel load proportional to
g gives the same sinkage and DP/W. This law makes that hypothesis:
``kc, kphi, c -> (g/g_ref)^alpha kc, kphi, c`` and ``gamma -> rho g``. At the same
load the lunar soil is then weaker than the Earth one in every term: the wheel sinks
about three times deeper and pulls less (Niksirat, Daca & Skonieczny 2020, IJRR
39(7):797-811: about -20 % average traction at lunar g at the same load, more sinkage;
Kobayashi et al. 2010: more slip at low g), see tests/test_terramechanics_laws.py.
Holds for dry granular soils (no true cohesion); alpha = 1 is the similitude.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from terramechanics.effects.base import Effect, FitParam
from terramechanics.state import EARTH_GRAVITY_MPS2


@dataclass(frozen=True)
class ReducedGravityWongKobayashi2012(Effect):
    """``bearing_exponent`` alpha of the strength terms ~ g^alpha;
    ``reference_gravity_mps2``: where the soil parameters were measured."""

    bearing_exponent: float = 1.0
    reference_gravity_mps2: float = EARTH_GRAVITY_MPS2
    name = "reduced_gravity"
    law = "wong_kobayashi2012"
    fit = (FitParam("bearing_exponent", 1.0, 0.0, 2.5),)

    def soil(self, soil, cond, wheel):
        ratio = np.asarray(cond.gravity_mps2, dtype=float) / self.reference_gravity_mps2
        scale = ratio ** self.bearing_exponent
        return replace(soil, kc=soil.kc * scale, kphi=soil.kphi * scale,
                       cohesion_pa=soil.cohesion_pa * scale,
                       unit_weight_n_m3=soil.unit_weight_n_m3 * ratio)
