"""Slip-sinkage: the sinkage exponent grows with slip, ``n = n0 + n1 |s|``.

Ding, Gao, Deng, Tao (2011) "Experimental study and analysis on driving wheels'
performance for planetary exploration rovers moving in deformable soil",
J. Terramechanics 48(1):27-45; Ding et al. (2015) "Interaction mechanics model for
rigid driving wheels of planetary rovers moving on sandy terrain with consideration
of multiple physical effects", J. Field Robotics 32(6), use ``N = n0 + n1 s`` in
Reece's form ``p = k b^n0 (z/b)^N``, as here. The skid branch uses |s| (sinkage
also grows with skid). The default n1 = 0.5 makes a BB2-like wheel sink about four
times deeper at 90 % slip than at zero slip; fit it per wheel and soil.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from terramechanics.effects.base import Effect


@dataclass(frozen=True)
class SlipSinkage(Effect):
    """``n1``: increase of the sinkage exponent per unit slip."""

    n1: float = 0.5
    name = "slip_sinkage"

    def soil(self, soil, cond, wheel):
        return replace(soil, n_slope=np.full(np.shape(cond.slip), self.n1))
