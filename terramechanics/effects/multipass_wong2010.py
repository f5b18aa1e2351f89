"""Multipass: soil run over i times before is denser and stiffer, linearly in i.

Repetitive loading stiffens the pressure-sinkage response (Wong, Terramechanics and
Off-Road Vehicle Engineering 2010, ch. 2.4 and 5.3 "multi-pass"; Holm 1969, "Multi-pass
behaviour of pneumatic tires", J. Terramech. 6(3); Senatore, Wulfmeier, Vlahinic,
Andrade & Iagnemma 2012, "Investigation of stress and failure in granular soils for
lightweight robotic vehicle applications", J. Terramech. 49). Linear in the pass index
``i`` (0 = virgin soil): ``kc, kphi -> (1 + a_k i) kc, kphi`` and
``rho -> (1 + a_rho i) rho``. The default ``a_k`` reproduces the ExoMars BB2
single-wheel multipass numbers quoted in the swtlab issue (resistance at 180 N: about
18 N on virgin soil, about 15 N at multipass 2) with terramechanics/models/bb2_sand.toml;
linear growth holds for the first few passes only (the soil's densification saturates).
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from terramechanics.effects.base import Effect, FitParam


@dataclass(frozen=True)
class MultipassWong2010(Effect):
    """``stiffness_gain_per_pass`` a_k and ``density_gain_per_pass`` a_rho (per pass)."""

    stiffness_gain_per_pass: float = 0.22
    density_gain_per_pass: float = 0.02
    name = "multipass"
    law = "wong2010"
    fit = (FitParam("stiffness_gain_per_pass", 0.2, 0.0, 1.5),)

    def soil(self, soil, cond, wheel):
        i = np.asarray(cond.multipass, dtype=float)
        stiff = 1.0 + self.stiffness_gain_per_pass * i
        return replace(soil, kc=soil.kc * stiff, kphi=soil.kphi * stiff,
                       unit_weight_n_m3=soil.unit_weight_n_m3
                       * (1.0 + self.density_gain_per_pass * i))
