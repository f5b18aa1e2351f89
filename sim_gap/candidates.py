"""Candidate explanations of the gap: soil-only recalibration, each missing effect, pairs.

Each candidate frees a few well-posed parameters: three soil parameters (Bekker k_phi,
friction angle, Janosi-Hanamoto K; Bekker 1969, Janosi & Hanamoto 1961) plus one strength
per effect (two for wheel flexibility: stiffness and hysteresis), with the bounds below.
The effects and their parameters are those of ``terramechanics.effects`` (see their
docstrings and docs/model-file.md).
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


#: strength parameters of each effect: (dotted suffix, start, lower, upper, log)
EFFECT_PARAMS: dict[str, tuple[tuple[str, float, float, float, bool], ...]] = {
    "grousers": (("shear_radius_factor", 0.5, 0.0, 1.5, False),),
    "slip_sinkage": (("n1", 0.3, 0.0, 1.5, False),),
    "reduced_gravity": (("bearing_exponent", 1.0, 0.0, 2.5, False),),
    "wheel_flexibility": (("radial_stiffness_n_m", 3e4, 5e3, 5e5, True),
                          ("hysteresis_coefficient", 0.02, 0.0, 0.1, False)),
    "multipass": (("stiffness_gain_per_pass", 0.2, 0.0, 1.5, False),),
    "bulldozing": (("coefficient", 0.5, 0.0, 5.0, False),),
}


def soil_params(model: tm.WheelModel) -> tuple[Param, ...]:
    """k_phi and K within a factor 5 of the simulation's, friction angle within 10 deg."""
    s = model.soil
    kphi = max(s.kphi, 1e3)
    phi = s.friction_angle_deg
    return (Param("soil.kphi", kphi, kphi / 5, kphi * 5, True),
            Param("soil.friction_angle_deg", phi, max(phi - 10, 5.0), min(phi + 10, 60.0)),
            Param("soil.shear_modulus_m", s.shear_modulus_m, s.shear_modulus_m / 5,
                  s.shear_modulus_m * 5, True))


def effect_params(name: str) -> tuple[Param, ...]:
    return tuple(Param(f"effects.{name}.{p}", *rest) for p, *rest in EFFECT_PARAMS[name])


def candidate(model: tm.WheelModel, effects: tuple[str, ...]) -> Candidate:
    """Soil parameters and the strengths of ``effects`` (kept in the vocabulary's order)."""
    effects = tuple(sorted(effects, key=list(tm.EFFECTS).index))
    params = soil_params(model) + tuple(p for e in effects for p in effect_params(e))
    return Candidate(tuple(effects), params)


def singles(model: tm.WheelModel, effects: list[str]) -> list[Candidate]:
    """Soil only, then each effect alone."""
    return [candidate(model, ())] + [candidate(model, (e,)) for e in effects]


def pairs(model: tm.WheelModel, effects: list[str]) -> list[Candidate]:
    """Every pair of ``effects`` (effects mask each other: a pair can win where neither
    single does)."""
    return [candidate(model, pair) for pair in combinations(effects, 2)]
