"""Lugs after Ding et al.: equivalent shear radius and lug-induced slip-sinkage.

Ding, Gao, Deng, Nagatani & Yoshida (2011) "Experimental study and analysis on driving wheels'
performance for planetary exploration rovers moving in deformable soil", J.
Terramechanics 48(1):27-45, and Ding et al. (2015), J. Field Robotics 32(6): the lugs
move the shear surface to the equivalent radius ``r_s = r + lambda h`` (0 <= lambda
<= 1), and lugged wheels sink more with slip than smooth ones, because the lugs dig
and carry the soil backwards: in their tests at 80 N the 10 mm lug wheel sank 6 times
deeper at s = 0.6 than at s = 0, the smooth wheel 3.5 times. Ding et al. fit the
sinkage exponent ``N = n0 + n1 s`` per wheel; here the lug part of ``n1`` grows with
the lug height, ``n1_lug = kappa h / r`` (a linearisation in h of their per-wheel
values), added to the soil's own slip-sinkage. The default kappa = 3 is fitted on the
Ding et al. 2011 10 mm lug wheel at 80 N (bench/bench_ding2011.py, ``static_k`` soil,
the smooth wheel's ``slip_sinkage`` n1 = 0.9); that wheel is then no hold-out for this
law. It holds for lugs short against the radius (h/r <= 0.1 in their tests); the same slope
on the braked branch (|s|) is an extension outside their data.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from terramechanics.effects.base import Effect, FitParam


@dataclass(frozen=True)
class GrousersDing2011(Effect):
    """``shear_radius_factor`` lambda of r + lambda h; ``lug_sinkage_gain`` kappa of
    n1_lug = kappa h / r."""

    shear_radius_factor: float = 0.5
    lug_sinkage_gain: float = 3.0
    name = "grousers"
    law = "ding2011"
    fit = (FitParam("shear_radius_factor", 0.5, 0.0, 1.5),
           FitParam("lug_sinkage_gain", 3.0, 0.0, 30.0))

    def soil(self, soil, cond, wheel):
        lug_n1 = self.lug_sinkage_gain * wheel.grouser_height_m / wheel.radius_m
        return replace(soil, n_slope=soil.n_slope + lug_n1,
                       n_skid_slope=soil.n_skid_slope + lug_n1)

    def geometry(self, geo, soil, cond, wheel):
        offset = self.shear_radius_factor * wheel.grouser_height_m
        return replace(geo, shear_offset_m=np.full(np.shape(cond.slip), offset))
