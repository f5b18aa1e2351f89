"""Slip-sinkage after Lyasko: the static sinkage times a slip-sinkage coefficient.

Lyasko (2010) "Slip sinkage effect in soil-vehicle mechanics", J. Terramechanics
47(1):21-31: the sinkage of a slipping running gear is its static (zero-slip) sinkage
times ``K_s = (1 + i)/(1 - 0.5 i)`` at slip i (1 at rest, 2.3 at i = 0.6, 4 at i = 1),
from the shear-induced loss of bearing of the soil under the running gear, for
off-road running gears on soft soils (Yang, Lin, Zhang & Wang 2016, J. Southeast Univ.
32(2):201-207, found it the best of three slip-sinkage laws on a real vehicle). No
soil constant: it holds where the soil's bearing loss with slip is of the average
kind, and overstates it on firm soils that sink little with slip.
Here the soil under the wheel is softened so that Bekker's rigid-wheel sinkage, which
goes as ``k^(-1/(n + 1/2))`` at a fixed load (Bekker 1956), grows by ``K_s^kappa``:
``kc, kphi -> kc, kphi K_s^(-kappa (n + 1/2))`` (kappa = 1 as published; in the
Wong-Reece integrals the sinkage follows within a few per cent). |i| on the skid branch.
The coefficient's form is quoted from the paper as cited; the swtlab tests check the
law against it, not against Lyasko's own data.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from terramechanics.effects.base import Effect, FitParam


def slip_sinkage_coefficient(slip) -> np.ndarray:
    """Lyasko's ``(1 + i)/(1 - 0.5 i)`` at i = |slip| (clipped at 1)."""
    i = np.minimum(np.abs(np.asarray(slip, dtype=float)), 1.0)
    return (1.0 + i) / (1.0 - 0.5 * i)


@dataclass(frozen=True)
class SlipSinkageLyasko2010(Effect):
    """``coefficient`` kappa: exponent on Lyasko's K_s (1 = as published)."""

    coefficient: float = 1.0
    name = "slip_sinkage"
    law = "lyasko2010"
    fit = (FitParam("coefficient", 0.7, 0.0, 3.0),)

    def soil(self, soil, cond, wheel):
        softening = slip_sinkage_coefficient(cond.slip) ** (-self.coefficient
                                                            * (soil.n0 + 0.5))
        return replace(soil, kc=soil.kc * softening, kphi=soil.kphi * softening)
