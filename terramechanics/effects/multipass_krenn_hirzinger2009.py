"""Multipass after the Soil Contact Model: a run-over rut reloads elastically.

Krenn & Hirzinger (2009) "SCM - A soil contact model for multi-body system
simulations", 11th European Regional Conference of the ISTVS, Bremen (the model of
Chrono's SCMTerrain, parameter ``elastic_K``), after Wong's repetitive-loading tests
(Wong, Terramechanics and Off-Road Vehicle Engineering 2010, ch. 2.4): soil that was
pressed down plastically to some pressure responds to a later load elastically,
``sigma = K_e dz`` from the rut bottom, with ``K_e`` (Pa/m) far above the Bekker
modulus, until that pressure is exceeded; then it yields along the virgin Bekker
curve. A wheel running again with the same load in its own rut (multipass index
``i >= 1``) meets such soil: here its pressure-sinkage becomes ``K_e dz`` (kc -> 0,
kphi -> K_e, n0 -> 1), the same for every later pass; the other effects then act on
that soil (``terramechanics.SOIL_ORDER``: reduced gravity scales K_e, slip-sinkage adds
its slope or softening). Neglects the yield beyond the earlier pressure, so it holds
while the reloading pressure stays near the first pass's (``K_e`` not far above the soil's
secant
stiffness at the first-pass sinkage; below that secant it would be softer than virgin
soil, which SCM forbids: K_e > kphi). The default K_e = 2.7e7 Pa/m (1.5 x the example's
kphi) reproduces the ExoMars BB2 resistance at multipass 2 (about 15 N at 180 N, swtlab
issue) with terramechanics/models/bb2_sand.toml.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from terramechanics.effects.base import Effect, FitParam


@dataclass(frozen=True)
class MultipassKrennHirzinger2009(Effect):
    """``elastic_stiffness_pa_m`` K_e of the reloading soil (Pa/m)."""

    elastic_stiffness_pa_m: float = 2.7e7
    name = "multipass"
    law = "krenn_hirzinger2009"
    fit = (FitParam("elastic_stiffness_pa_m", 3e7, 1e6, 1e9, log=True),)

    def soil(self, soil, cond, wheel):
        rerun = np.asarray(cond.multipass) >= 1
        return replace(soil, kc=np.where(rerun, 0.0, soil.kc),
                       kphi=np.where(rerun, self.elastic_stiffness_pa_m, soil.kphi),
                       n0=np.where(rerun, 1.0, soil.n0))
