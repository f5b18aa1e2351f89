"""Switchable physical effects, one per module, named by a fixed vocabulary.

The names in :data:`EFFECTS` are the ones the sim-to-real diagnosis uses:
``grousers``, ``slip_sinkage``, ``reduced_gravity``, ``wheel_flexibility``,
``multipass``, ``bulldozing``.
"""

from __future__ import annotations

from terramechanics.effects.base import Effect
from terramechanics.effects.bulldozing import Bulldozing
from terramechanics.effects.grousers import Grousers
from terramechanics.effects.multipass import Multipass
from terramechanics.effects.reduced_gravity import ReducedGravity
from terramechanics.effects.slip_sinkage import SlipSinkage
from terramechanics.effects.wheel_flexibility import WheelFlexibility

EFFECTS: dict[str, type[Effect]] = {cls.name: cls for cls in (
    Grousers, SlipSinkage, ReducedGravity, WheelFlexibility, Multipass, Bulldozing)}


def make_effect(name: str, **params: float) -> Effect:
    """Build the effect called ``name`` with its parameters (defaults for the others)."""
    if name not in EFFECTS:
        raise KeyError(f"unknown effect {name!r}; known: {sorted(EFFECTS)}")
    return EFFECTS[name](**params)


__all__ = ["EFFECTS", "Effect", "make_effect", "Bulldozing", "Grousers", "Multipass",
           "ReducedGravity", "SlipSinkage", "WheelFlexibility"]
