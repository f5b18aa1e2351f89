"""Reduced gravity after Reece: the frictional bearing term scales with gamma = rho g.

Reece (1965) "Principles of soil-vehicle mechanics", Proc. IMechE 180(2A):
``p = (c k'c + gamma b k'phi)(z/b)^n`` - the frictional modulus is proportional to
the unit weight, so at gravity g ``kphi(g) = kphi (g/g_ref)^alpha`` (alpha = 1 for
Reece's law); c and kc stay. Wong (2012) "Predicting the performances of rigid rover
wheels on extraterrestrial surfaces based on test results obtained on earth", J.
Terramech. 49(1):49-61, uses this to show that testing with the reduced load alone
overestimates performance. Fitted by Reece to plate and wheel tests on Earth at
different sizes (gravity enters through gamma only); with c > 0 it predicts a better
lunar DP/W at equal mass (the cohesion does not scale), which the flights do not show
(see reduced_gravity_wong_kobayashi2012). The unit weight in the bulldozing terms also
becomes rho g. Without a reduced-gravity law gravity enters only through the load.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from terramechanics.effects.base import Effect, FitParam
from terramechanics.state import EARTH_GRAVITY_MPS2


@dataclass(frozen=True)
class ReducedGravityReece1965(Effect):
    """``bearing_exponent`` alpha of kphi ~ g^alpha; ``reference_gravity_mps2``: where the
    soil parameters were measured."""

    bearing_exponent: float = 1.0
    reference_gravity_mps2: float = EARTH_GRAVITY_MPS2
    name = "reduced_gravity"
    law = "reece1965"
    fit = (FitParam("bearing_exponent", 1.0, 0.0, 2.5),)

    def soil(self, soil, cond, wheel):
        ratio = np.asarray(cond.gravity_mps2, dtype=float) / self.reference_gravity_mps2
        return replace(soil, kphi=soil.kphi * ratio ** self.bearing_exponent,
                       unit_weight_n_m3=soil.unit_weight_n_m3 * ratio)
