"""The tiny protocol every effect follows: three hooks, each an identity by default."""

from __future__ import annotations

from typing import ClassVar

from terramechanics.state import Condition, Contact, ExtraForces, Geometry, SoilState
from terramechanics.wheel import Wheel


class Effect:
    """Base of the effects; a subclass is a frozen dataclass of its parameters.

    ``soil`` and ``geometry`` change what the stress integrals see (and so the
    sinkage); ``forces`` adds forces outside the integrals once the sinkage is solved.
    """

    name: ClassVar[str]
    terms: ClassVar[tuple[str, ...]] = ()  # names of the extra outputs of `forces`

    def soil(self, soil: SoilState, cond: Condition, wheel: Wheel) -> SoilState:
        return soil

    def geometry(self, geo: Geometry, cond: Condition, wheel: Wheel) -> Geometry:
        return geo

    def forces(self, contact: Contact, soil: SoilState, geo: Geometry, cond: Condition,
               wheel: Wheel) -> ExtraForces:
        return ExtraForces()
