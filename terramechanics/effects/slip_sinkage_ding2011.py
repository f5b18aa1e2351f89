"""Slip-sinkage after Ding et al.: the sinkage exponent grows with slip, ``n = n0 + n1 |s|``.

Ding, Gao, Deng, Nagatani & Yoshida (2011) "Experimental study and analysis on driving wheels'
performance for planetary exploration rovers moving in deformable soil",
J. Terramechanics 48(1):27-45; Ding et al. (2015) "Interaction mechanics model for
rigid driving wheels of planetary rovers moving on sandy terrain with consideration
of multiple physical effects", J. Field Robotics 32(6): ``N = n0 + n1 s`` in Reece's
form ``p = k b^n0 (z/b)^N``, as here (z < b, so a larger exponent means a softer
response and more sinkage). Fitted by them per wheel on a lunar soil simulant at
slips 0-0.6; the skid branch uses |s| (sinkage also grows with skid), an extension
outside their data. The default n1 = 0.5 makes a BB2-like wheel sink about four times
deeper at 90 % slip than at zero slip; on the smooth wheel of Ding et al. 2011 at 80 N
bench/bench_ding2011.py fits n1 = 0.9 (soil stiffness set by the zero-slip sinkage).
"""

from __future__ import annotations

from dataclasses import dataclass, replace

from terramechanics.effects.base import Effect, FitParam


@dataclass(frozen=True)
class SlipSinkageDing2011(Effect):
    """``n1``: increase of the sinkage exponent per unit slip."""

    n1: float = 0.5
    name = "slip_sinkage"
    law = "ding2011"
    fit = (FitParam("n1", 0.3, 0.0, 1.5),)

    def soil(self, soil, cond, wheel):
        return replace(soil, n_slope=soil.n_slope + self.n1)
