"""A grouser law with the lugs' slip-sinkage: the soil under a lugged wheel loses bearing as
it slips.

``law~slip`` is the grouser law ``law`` (one without a lug sinkage of its own: Bekker's)
with the soil under the lugged wheel softened as in Lyasko's slip-sinkage law (Lyasko 2010,
J. Terramechanics 47(1):21-31, ``K_s = (1 + i)/(1 - 0.5 i)``, the shear-induced loss of
bearing, ``slip_sinkage_lyasko2010``), raised to ``g h / r``: ``kc, kphi -> kc, kphi
K_s^(-g (h / r) (n + 1/2))``, ``h`` the grouser height, ``r`` the radius, ``g`` the
``lug_slip_gain`` (free in a gap fit, 0-30; 0 gives the published law exactly). The
lugs carry the shear down to their tips, so the sheared, loosened layer under a slipping
wheel deepens with their height: lugged wheels sink more with slip than smooth ones on the
same soil (Ding et al. 2011, J. Terramechanics 48(1):27-45: at 80 N their 10 mm lug wheel
sank 6 times deeper at s = 0.6 than at s = 0, the smooth wheel 3.5 times).

Why: of the two grouser laws only Ding et al.'s has a lug sinkage (its sinkage exponent
grows with slip and lug height), so with Ding's law held out no candidate reached a lugged
wheel that digs in (docs/gap-report.md, seeds 32, 34, 35). Lyasko's factor is of another
shape than Ding's exponent: it multiplies the static sinkage by a factor of slip alone,
where Ding's ratio also depends on the load and the soil's stiffness. ``python -m bench
law_mimic`` measures how far it comes to Ding's lugs and how little it explains of the
other effects.
"""

from __future__ import annotations

from dataclasses import dataclass

from terramechanics.effects.base import Effect, FitParam
from terramechanics.effects.slip_sinkage_lyasko2010 import SlipSinkageLyasko2010

#: suffix of a grouser law with the lugs' slip-sinkage
SUFFIX = "~slip"
#: the grouser laws so extended (Ding et al.'s has a lug sinkage of its own)
EXTENDED: tuple[tuple[str, str], ...] = (("grousers", "bekker1956"),)


def lug_slip_sinkage(cls: type[Effect]) -> type[Effect]:
    """The grouser law ``cls`` with the lugs' slip-sinkage of Lyasko's form (module doc)."""

    @dataclass(frozen=True)
    class LugSlipSinkage(cls):  # type: ignore[valid-type, misc]
        lug_slip_gain: float = 0.0
        law = cls.law + SUFFIX
        relaxes = cls.law
        fit = cls.fit + (FitParam("lug_slip_gain", 3.0, 0.0, 30.0),)

        def soil(self, soil, cond, wheel):
            lyasko = SlipSinkageLyasko2010(
                coefficient=self.lug_slip_gain * wheel.grouser_height_m / wheel.radius_m)
            return lyasko.soil(super().soil(soil, cond, wheel), cond, wheel)

    LugSlipSinkage.__name__ = LugSlipSinkage.__qualname__ = cls.__name__ + "LugSlipSinkage"
    LugSlipSinkage.__doc__ = (f"{cls.__name__} with the soil softened by Lyasko's K_s^(g h/r) "
                              "(module doc); ``lug_slip_gain`` g.")
    return LugSlipSinkage
