"""A bulldozing law whose resistance varies as a power of the rut depth.

``law~depth`` is the bulldozing law ``law`` with its ``coefficient`` multiplied at each
condition by ``(z / z_ref)^a``, ``z`` the wheel's sinkage, ``a`` the ``depth_exponent``
(free in a gap fit, within +-1.5; 0 gives the published law exactly) and ``z_ref`` =
:data:`REFERENCE_DEPTH_M`. Like ``law~load`` (``load_varying``) it is a varying-coefficient
model (Hastie & Tibshirani 1993, J. R. Statist. Soc. B 55(4):757-796): the law keeps its
mechanism (a passive earth pressure on the rut front) and the data set how it grows with
the depth.

Why the depth, and why the wider size: the two published bulldozing laws differ in both.
Rankine's passive pressure on a vertical wall (Terzaghi 1943) grows as ``z^2`` in
cohesionless soil; Bekker's (1969, after Hegedus) blade with its wedge about as ``z^1.5``
on shallow ruts (its ``1/sin(alpha)``, ``alpha ~ 2 sqrt(z/D)``), and it is 17-180 times
Rankine's on planetary-wheel ruts. Rankine's published law is bounded at 5 times the
formula because with the size alone it carried Bekker's truths by a flexible-wheel patch
of the shape (``bulldozing_rankine_terzaghi1943``); with the depth exponent the shape is
the law's own, so its depth form is allowed :data:`COEFFICIENT_UPPER` (up to the low end of
Bekker's size against Rankine's, 17, with a margin). ``python -m bench law_mimic``
measures how far each law's depth form comes to the other law's truths.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from terramechanics.effects.base import Effect, FitParam, published_with

#: the rut depth at which a depth-varying law's coefficient is its published one (m)
REFERENCE_DEPTH_M = 0.01
#: suffix of a depth-varying law's name
SUFFIX = "~depth"
#: (effect, law) -> the upper bound of the depth form's coefficient (that of the published
#: law where it stays; module doc)
COEFFICIENT_UPPER: dict[tuple[str, str], float] = {
    ("bulldozing", "bekker1969"): 5.0,
    ("bulldozing", "rankine_terzaghi1943"): 20.0}


def depth_varying(cls: type[Effect], coefficient_upper: float) -> type[Effect]:
    """The law ``cls`` with its ``coefficient`` times ``(z / z_ref)^depth_exponent``,
    fitted within ``[0, coefficient_upper]``."""
    published = {p.name: p for p in cls.fit}
    if set(published) != {"coefficient"}:
        raise ValueError(f"{cls.__name__}: a depth-varying law needs a law whose one fitted "
                         f"strength is its coefficient, not {sorted(published)}")

    @dataclass(frozen=True)
    class DepthVarying(cls):  # type: ignore[valid-type, misc]
        depth_exponent: float = 0.0
        law = cls.law + SUFFIX
        relaxes = cls.law
        fit = (replace(published["coefficient"], upper=coefficient_upper),
               FitParam("depth_exponent", 0.0, -1.5, 1.5))

        def forces(self, contact, soil, geo, cond, wheel):
            depth = np.maximum(np.asarray(contact.sinkage_m, float), 1e-12)
            scale = (depth / REFERENCE_DEPTH_M) ** self.depth_exponent
            return published_with(self, cls, "coefficient", self.coefficient * scale).forces(
                contact, soil, geo, cond, wheel)

    DepthVarying.__name__ = DepthVarying.__qualname__ = cls.__name__ + "DepthVarying"
    DepthVarying.__doc__ = (f"{cls.__name__} with its coefficient times (z / "
                            f"{REFERENCE_DEPTH_M * 1000:g} mm)^depth_exponent (module doc).")
    return DepthVarying
