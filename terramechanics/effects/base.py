"""The tiny protocol every effect law follows: three hooks, each an identity by default."""

from __future__ import annotations

from dataclasses import dataclass, fields
from typing import ClassVar

from terramechanics.state import Condition, Contact, ExtraForces, Geometry, SoilState
from terramechanics.wheel import Wheel


@dataclass(frozen=True)
class FitParam:
    """A parameter of a law that a fit may free: its start value, bounds, log scale or not."""

    name: str
    start: float
    lower: float
    upper: float
    log: bool = False


class Effect:
    """Base of the effect laws; a subclass is a frozen dataclass of its parameters.

    ``name`` is the effect (the diagnosis vocabulary), ``law`` the published law that
    implements it (one module per law, named after its source; a generalised law names
    the published law it extends in ``relaxes``). ``soil`` and
    ``geometry`` change what the stress integrals see (and so the sinkage); ``forces``
    adds forces outside the integrals once the sinkage is solved. ``fit`` lists the
    strength parameters a gap fit frees, with their bounds.
    """

    name: ClassVar[str]
    law: ClassVar[str]
    relaxes: ClassVar[str | None] = None  # the published law a generalised law extends
    terms: ClassVar[tuple[str, ...]] = ()  # names of the extra outputs of `forces`
    fit: ClassVar[tuple[FitParam, ...]] = ()

    def soil(self, soil: SoilState, cond: Condition, wheel: Wheel) -> SoilState:
        return soil

    def geometry(self, geo: Geometry, soil: SoilState, cond: Condition,
                 wheel: Wheel) -> Geometry:
        return geo

    def forces(self, contact: Contact, soil: SoilState, geo: Geometry, cond: Condition,
               wheel: Wheel) -> ExtraForces:
        return ExtraForces()


def published_with(effect: Effect, cls: type[Effect], name: str, value) -> Effect:
    """The published law ``cls`` with ``effect``'s values of its fields and ``name`` set to
    ``value`` (an array: one per condition): how a generalised law acts."""
    return cls(**{**{f.name: getattr(effect, f.name) for f in fields(cls)}, name: value})
