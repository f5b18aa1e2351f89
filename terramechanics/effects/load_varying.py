"""A published law whose strength varies as a power of the wheel load.

``law~load`` is the law ``law`` with its strength parameter ``p`` replaced at each
condition by ``p (W / W_ref)^a``, ``a`` the ``load_exponent`` (free in a gap fit, within
+-2; 0 gives the published law exactly) and ``W_ref`` = :data:`REFERENCE_LOAD_N`. This is a
varying-coefficient model (Hastie & Tibshirani 1993, "Varying-coefficient models",
J. R. Statist. Soc. B 55(4):757-796): the law keeps its mechanism and its dependence on slip
and sinkage, and the data set how its strength scales with the load.

Why the load: the published laws of one family differ most in how the effect scales with
the load. Ding et al.'s slip-sinkage changes the sinkage exponent, so the sinkage ratio
depends on the load; Lyasko's multiplies the sinkage by a factor of slip alone. Wong's
flexible wheel deflects linearly with the load, Bekker's flat contact about as its square
above a threshold. ``python -m bench law_mimic`` measures how far the other law, with and
without the exponent, comes to a truth made by one (docs/gap-report.md, "The blind
check"). The families so relaxed are those of :data:`STRENGTH` (the parameter that scales
with the load); the others' laws differ in ways a load exponent does not reach (measured
in the same bench: bulldozing's coefficient is bounded, the lug laws differ in slip).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from terramechanics.effects.base import Effect, FitParam, published_with

#: the load at which a load-varying law's strength is its published parameter (N)
REFERENCE_LOAD_N = 100.0
#: suffix of a load-varying law's name
SUFFIX = "~load"
#: (effect, law) -> the strength parameter that varies with the load
STRENGTH: dict[tuple[str, str], str] = {
    ("slip_sinkage", "ding2011"): "n1",
    ("slip_sinkage", "lyasko2010"): "coefficient",
    ("wheel_flexibility", "wong2010"): "radial_stiffness_n_m",
    ("wheel_flexibility", "bekker1969"): "ground_pressure_pa"}


def load_varying(cls: type[Effect], strength: str) -> type[Effect]:
    """The law ``cls`` with ``strength`` times ``(W / W_ref)^load_exponent``."""
    if strength not in {p.name for p in cls.fit}:
        raise ValueError(f"{cls.__name__}: {strength!r} is not a fitted strength")

    @dataclass(frozen=True)
    class LoadVarying(cls):  # type: ignore[valid-type, misc]
        load_exponent: float = 0.0
        law = cls.law + SUFFIX
        relaxes = cls.law
        fit = cls.fit + (FitParam("load_exponent", 0.0, -2.0, 2.0),)

        def at(self, cond) -> Effect:
            """The published law with this law's strength at each condition's load."""
            scale = (np.asarray(cond.load_n, float) / REFERENCE_LOAD_N) ** self.load_exponent
            return published_with(self, cls, strength, getattr(self, strength) * scale)

        def soil(self, soil, cond, wheel):
            return self.at(cond).soil(soil, cond, wheel)

        def geometry(self, geo, soil, cond, wheel):
            return self.at(cond).geometry(geo, soil, cond, wheel)

        def forces(self, contact, soil, geo, cond, wheel):
            return self.at(cond).forces(contact, soil, geo, cond, wheel)

    LoadVarying.__name__ = LoadVarying.__qualname__ = cls.__name__ + "LoadVarying"
    LoadVarying.__doc__ = (f"{cls.__name__} with ``{strength}`` times (W / "
                           f"{REFERENCE_LOAD_N:g} N)^load_exponent (module doc).")
    return LoadVarying
