"""Slip-sinkage after Ding et al.: the sinkage exponent grows with slip, ``n = n0 + n1 s``.

Ding, Gao, Deng, Nagatani & Yoshida (2011) "Experimental study and analysis on driving wheels'
performance for planetary exploration rovers moving in deformable soil",
J. Terramechanics 48(1):27-45; Ding et al. (2015) "Interaction mechanics model for
rigid driving wheels of planetary rovers moving on sandy terrain with consideration
of multiple physical effects", J. Field Robotics 32(6): ``N = n0 + n1 s`` in Reece's
form ``p = k b^n0 (z/b)^N``, as here (z < b, so a larger exponent means a softer
response and more sinkage). Fitted by them per wheel on a lunar soil simulant at
slips 0-0.6. Braked (skid ratio s < 0): ``N = n0 + n2 |s|`` with its own slope, as in
the CMU model of Pavlov & Johnson (robomechanics/3d-terramechanics, ``sigma.m``; their
hand-tuned smooth wheel on dry sand: n1 = 0.01, n2 = 0.55, i.e. sinkage grows with
skid, hardly with slip; their ``k z^N`` is kept here in Reece's form, so their values
carry over approximately); ``n2`` unset takes n1 on both branches (an extension of
Ding's law outside their data). Only n1 is freed by a gap fit. The default n1 = 0.5
makes a BB2-like wheel sink about four times deeper at 90 % slip than at zero slip; on
the smooth wheel of Ding et al. 2011 at 80 N bench/bench_ding2011.py fits n1 = 0.9 (soil
stiffness set by the zero-slip sinkage).
"""

from __future__ import annotations

from dataclasses import dataclass, replace

from terramechanics.effects.base import Effect, FitParam


@dataclass(frozen=True)
class SlipSinkageDing2011(Effect):
    """``n1``: increase of the sinkage exponent per unit slip; ``n2`` per unit skid
    ratio (None: n1)."""

    n1: float = 0.5
    n2: float | None = None
    name = "slip_sinkage"
    law = "ding2011"
    fit = (FitParam("n1", 0.3, 0.0, 1.5),)

    def soil(self, soil, cond, wheel):
        n2 = self.n1 if self.n2 is None else self.n2
        return replace(soil, n_slope=soil.n_slope + self.n1,
                       n_skid_slope=soil.n_skid_slope + n2)
