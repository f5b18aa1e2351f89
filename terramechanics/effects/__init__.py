"""Switchable physical effects, each a family of published laws, one module per law.

The effect names are the vocabulary the sim-to-real diagnosis uses: ``grousers``,
``slip_sinkage``, ``reduced_gravity``, ``wheel_flexibility``, ``multipass``,
``bulldozing``. A model picks the law of each effect (``[effects.grousers] law =
"ding2011"`` in a model file); :data:`DEFAULT_LAWS` says which one a model without
``law`` gets. :data:`EFFECTS` maps each effect to its default law's class.
"""

from __future__ import annotations

from terramechanics.effects.base import Effect, FitParam
from terramechanics.effects.bulldozing_bekker1969 import BulldozingBekker1969
from terramechanics.effects.bulldozing_rankine_terzaghi1943 import BulldozingRankineTerzaghi1943
from terramechanics.effects.grousers_bekker1956 import GrousersBekker1956
from terramechanics.effects.grousers_ding2011 import GrousersDing2011
from terramechanics.effects.depth_varying import COEFFICIENT_UPPER, depth_varying
from terramechanics.effects.load_varying import STRENGTH, load_varying
from terramechanics.effects.lug_slip_sinkage import EXTENDED, lug_slip_sinkage
from terramechanics.effects.multipass_krenn_hirzinger2009 import MultipassKrennHirzinger2009
from terramechanics.effects.multipass_wong2010 import MultipassWong2010
from terramechanics.effects.reduced_gravity_reece1965 import ReducedGravityReece1965
from terramechanics.effects.reduced_gravity_wong_kobayashi2012 import (
    ReducedGravityWongKobayashi2012)
from terramechanics.effects.slip_sinkage_ding2011 import SlipSinkageDing2011
from terramechanics.effects.slip_sinkage_lyasko2010 import SlipSinkageLyasko2010
from terramechanics.effects.wheel_flexibility_bekker1969 import WheelFlexibilityBekker1969
from terramechanics.effects.wheel_flexibility_wong2010 import WheelFlexibilityWong2010

_ALL: tuple[type[Effect], ...] = (
    GrousersBekker1956, GrousersDing2011, SlipSinkageDing2011, SlipSinkageLyasko2010,
    ReducedGravityWongKobayashi2012, ReducedGravityReece1965, WheelFlexibilityWong2010,
    WheelFlexibilityBekker1969, MultipassWong2010, MultipassKrennHirzinger2009,
    BulldozingBekker1969, BulldozingRankineTerzaghi1943)

#: effect -> published law -> class, effects in the vocabulary's order
PUBLISHED_LAWS: dict[str, dict[str, type[Effect]]] = {}
for _cls in _ALL:
    PUBLISHED_LAWS.setdefault(_cls.name, {})[_cls.law] = _cls

#: effect -> law -> class: the published laws and, for the effects of
#: ``load_varying.STRENGTH``, each with its strength varying with the load (``law~load``),
#: for those of ``depth_varying.COEFFICIENT_UPPER`` with the rut depth (``law~depth``), and
#: the grouser laws of ``lug_slip_sinkage.EXTENDED`` with the lugs' slip-sinkage (``law~slip``)
LAWS: dict[str, dict[str, type[Effect]]] = {e: dict(laws) for e, laws in PUBLISHED_LAWS.items()}
for (_name, _law), _strength in STRENGTH.items():
    _varying = load_varying(PUBLISHED_LAWS[_name][_law], _strength)
    LAWS[_name][_varying.law] = _varying
for (_name, _law), _upper in COEFFICIENT_UPPER.items():
    _varying = depth_varying(PUBLISHED_LAWS[_name][_law], _upper)
    LAWS[_name][_varying.law] = _varying
for _name, _law in EXTENDED:
    _varying = lug_slip_sinkage(PUBLISHED_LAWS[_name][_law])
    LAWS[_name][_varying.law] = _varying


def published_law(name: str, law: str) -> str:
    """The published law that ``law`` of effect ``name`` is or extends."""
    return law_class(name, law).relaxes or law

#: the law a model gets when it names none
DEFAULT_LAWS: dict[str, str] = {
    "grousers": "bekker1956", "slip_sinkage": "ding2011",
    "reduced_gravity": "wong_kobayashi2012", "wheel_flexibility": "wong2010",
    "multipass": "wong2010", "bulldozing": "bekker1969"}

EFFECTS: dict[str, type[Effect]] = {name: LAWS[name][DEFAULT_LAWS[name]] for name in LAWS}

#: the order in which the effects' ``soil`` hooks act: multipass first, because its law
#: gives the soil that the earlier passes left (Krenn & Hirzinger's elastic reload
#: *replaces* the pressure-sinkage law), and the other effects then act on that soil: the
#: gravity scaling of its strength terms, the slip softening, the lugs. In the vocabulary
#: order a re-run rut under reduced gravity lost the gravity scaling of its stiffness, and
#: a slipping re-run wheel its Lyasko softening. The laws that only multiply commute.
SOIL_ORDER: tuple[str, ...] = ("multipass",) + tuple(n for n in LAWS if n != "multipass")


def law_class(name: str, law: str | None = None) -> type[Effect]:
    """The class of ``law`` of effect ``name`` (its default law when ``law`` is None)."""
    if name not in LAWS:
        raise KeyError(f"unknown effect {name!r}; known: {sorted(LAWS)}")
    law = DEFAULT_LAWS[name] if law is None else law
    if law not in LAWS[name]:
        raise KeyError(f"unknown law {law!r} of effect {name!r}; known: {sorted(LAWS[name])}")
    return LAWS[name][law]


def make_effect(name: str, law: str | None = None, **params: float) -> Effect:
    """Build ``law`` of effect ``name`` (default law if None) with its parameters."""
    return law_class(name, law)(**params)


__all__ = ["DEFAULT_LAWS", "EFFECTS", "Effect", "FitParam", "LAWS", "PUBLISHED_LAWS",
           "SOIL_ORDER", "law_class", "make_effect", "published_law"
           ] + [cls.__name__ for cls in _ALL]
