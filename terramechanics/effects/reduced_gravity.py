"""Reduced gravity: the soil's frictional bearing term scales with gamma = rho g.

Reece (1965) "Principles of soil-vehicle mechanics", Proc. IMechE 180(2A):
``p = (c k'c + gamma b k'phi)(z/b)^n`` - the frictional modulus is proportional to
the unit weight, so at gravity g ``kphi(g) = kphi (g/g_ref)^alpha`` (alpha = 1 for
Reece's law). Wong (2012) "Predicting the performances of rigid rover wheels on
extraterrestrial surfaces based on test results obtained on earth", J. Terramech.
49(1):49-61, shows that testing with the reduced load alone overestimates
performance. Niksirat, Daca & Skonieczny (2020) "The effects of reduced-gravity on
planetary rover mobility", Int. J. Robotics Research 39(7):797-811, measured in
parabolic flights at the same wheel load about 20 % less traction at lunar gravity,
5-10 % at Martian gravity, with more sinkage. With Reece's law (alpha = 1) the
Wong-Reece model of a BB2-like wheel (terramechanics/models/bb2_sand.toml) loses 21 % of
its peak drawbar pull at lunar and 10 % at Martian gravity, with 2-3 times the
sinkage; ``alpha`` is the handle to fit flight data. The unit weight in the grouser
and bulldozing terms also becomes rho g. Without this effect gravity enters only through the load.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from terramechanics.effects.base import Effect
from terramechanics.state import EARTH_GRAVITY_MPS2


@dataclass(frozen=True)
class ReducedGravity(Effect):
    """``bearing_exponent`` alpha of kphi ~ g^alpha; ``reference_gravity_mps2``: where the
    soil parameters were measured."""

    bearing_exponent: float = 1.0
    reference_gravity_mps2: float = EARTH_GRAVITY_MPS2
    name = "reduced_gravity"

    def soil(self, soil, cond, wheel):
        ratio = np.asarray(cond.gravity_mps2, dtype=float) / self.reference_gravity_mps2
        return replace(soil, kphi=soil.kphi * ratio ** self.bearing_exponent,
                       unit_weight_n_m3=soil.unit_weight_n_m3 * ratio)
