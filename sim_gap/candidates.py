"""Candidate explanations of the gap: soil-only recalibration, each missing effect, pairs.

Each candidate frees a few well-posed parameters: three soil parameters (Bekker k_phi,
friction angle, Janosi-Hanamoto K; Bekker 1969, Janosi & Hanamoto 1961) plus the strengths
that each effect's law declares with their bounds (``fit`` of the law class, e.g. two for
the default wheel flexibility: stiffness and hysteresis). A candidate uses the law the
simulation model has for an effect, else the effect's default law (see
``terramechanics.effects`` and docs/model-file.md).
"""

from __future__ import annotations

from dataclasses import dataclass
from itertools import combinations

import terramechanics as tm


@dataclass(frozen=True)
class Param:
    """A free parameter under its dotted model name, its start value and bounds; ``log``:
    fitted on a log scale."""

    name: str
    start: float
    lower: float
    upper: float
    log: bool = False


@dataclass(frozen=True)
class Candidate:
    effects: tuple[str, ...]
    params: tuple[Param, ...]

    @property
    def label(self) -> str:
        return "+".join(self.effects) if self.effects else "soil_only"


def soil_params(model: tm.WheelModel) -> tuple[Param, ...]:
    """k_phi and K within a factor 5 of the simulation's, friction angle within 10 deg."""
    s = model.soil
    kphi = max(s.kphi, 1e3)
    phi = s.friction_angle_deg
    return (Param("soil.kphi", kphi, kphi / 5, kphi * 5, True),
            Param("soil.friction_angle_deg", phi, max(phi - 10, 5.0), min(phi + 10, 60.0)),
            Param("soil.shear_modulus_m", s.shear_modulus_m, s.shear_modulus_m / 5,
                  s.shear_modulus_m * 5, True))


def effect_params(name: str, law: str | None = None) -> tuple[Param, ...]:
    """The strength parameters the law (default: the effect's default law) declares."""
    return tuple(Param(f"effects.{name}.{p.name}", p.start, p.lower, p.upper, p.log)
                 for p in tm.law_class(name, law).fit)


def candidate(model: tm.WheelModel, effects: tuple[str, ...]) -> Candidate:
    """Soil parameters and the strengths of ``effects`` (kept in the vocabulary's order)."""
    effects = tuple(sorted(effects, key=list(tm.EFFECTS).index))
    laws = {e: model.effects[e].law if e in model.effects else None for e in effects}
    params = soil_params(model) + tuple(p for e in effects for p in effect_params(e, laws[e]))
    return Candidate(tuple(effects), params)


def singles(model: tm.WheelModel, effects: list[str]) -> list[Candidate]:
    """Soil only, then each effect alone."""
    return [candidate(model, ())] + [candidate(model, (e,)) for e in effects]


def pairs(model: tm.WheelModel, effects: list[str]) -> list[Candidate]:
    """Every pair of ``effects`` (effects mask each other: a pair can win where neither
    single does)."""
    return [candidate(model, pair) for pair in combinations(effects, 2)]
