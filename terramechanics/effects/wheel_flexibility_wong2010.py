"""Flexible wheel after Wong: an equivalent rigid wheel of the same contact length.

The deflected wheel is replaced by the equivalent rigid wheel with the same contact
length (Wong, Terramechanics and Off-Road Vehicle Engineering 2010, ch. 4, flexible
tyre as a rigid wheel of larger diameter; see ``Geometry.contact_radius_m``), with a
linear radial stiffness, deflection ``delta = min(W / k_r, delta_max)``: a longer
contact, less sinkage. The internal (hysteresis) loss is a rolling resistance
``F_h = mu_h W`` that the drive torque pays, ``T += F_h r``. Default ``mu_h =
4.6/180``: the ExoMars BB2 flexible wheel loses about 4.6 N at 180 N, a quarter of
its resistance near zero slip (ExoMars BB2 single-wheel studies, the numbers quoted
in the swtlab issue; for flexible planetary wheels in general see Favaedi, Pechev,
Scharringhausen & Richter 2011, "Prediction of tractive response for flexible wheels
with application to planetary rovers", J. Terramech. 48(3)). Wong fitted the
equivalent diameter to pneumatic tyres on soft soils; it holds while the deflection
is small against the radius.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from terramechanics.effects.base import Effect, FitParam
from terramechanics.state import ExtraForces


@dataclass(frozen=True)
class WheelFlexibilityWong2010(Effect):
    """Radial stiffness (N/m), deflection cap (m), hysteresis coefficient mu_h (-)."""

    radial_stiffness_n_m: float = 30e3
    max_deflection_m: float = 0.02
    hysteresis_coefficient: float = 4.6 / 180.0
    name = "wheel_flexibility"
    law = "wong2010"
    terms = ("hysteresis_n", "deflection_m")
    fit = (FitParam("radial_stiffness_n_m", 3e4, 5e3, 5e5, log=True),
           FitParam("hysteresis_coefficient", 0.02, 0.0, 0.1))

    def geometry(self, geo, soil, cond, wheel):
        delta = np.minimum(np.asarray(cond.load_n, float) / self.radial_stiffness_n_m,
                           self.max_deflection_m)
        return replace(geo, deflection_m=delta)

    def forces(self, contact, soil, geo, cond, wheel):
        hysteresis = self.hysteresis_coefficient * np.asarray(cond.load_n, float)
        return ExtraForces(torque_nm=hysteresis * wheel.radius_m,
                           terms={"hysteresis_n": hysteresis,
                                  "deflection_m": np.broadcast_to(geo.deflection_m,
                                                                  hysteresis.shape)})
