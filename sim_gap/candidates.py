"""Candidate explanations of the gap: soil-only recalibration, each missing effect, pairs,
each effect under each law of its family that the diagnosis may use.

Each candidate frees a few well-posed parameters: three soil parameters (Bekker k_phi,
friction angle, Janosi-Hanamoto K; Bekker 1969, Janosi & Hanamoto 1961) plus the strengths
that each effect's law declares with their bounds (``fit`` of the law class, e.g. two for
the Wong 2010 wheel flexibility: stiffness and hysteresis). The laws of an effect are
those of ``terramechanics.effects.LAWS`` (docs/model-file.md), all of them unless the
caller names a subset; an effect the simulation already has keeps the simulation's law.

Pairs are fitted on a one-at-a-time design over laws (Saltelli et al. 2008, Global
Sensitivity Analysis, ch. 2): every pair under the reference laws (each effect's law that
scored best alone), and every pair with one of its effects switched to another law; the
posterior sums each effect set over the laws it was fitted under (``sim_gap.decide``).
"""

from __future__ import annotations

from dataclasses import dataclass
from itertools import combinations

import numpy as np
import pandas as pd

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
    """Effects (vocabulary order), the law of each (same order) and the free parameters."""

    effects: tuple[str, ...]
    params: tuple[Param, ...]
    laws: tuple[str, ...] = ()

    @property
    def label(self) -> str:
        """The effect set, e.g. ``grousers+slip_sinkage`` or ``soil_only``."""
        return "+".join(self.effects) if self.effects else "soil_only"

    @property
    def key(self) -> str:
        """Effects with their laws, e.g. ``grousers(ding2011)+slip_sinkage(lyasko2010)``."""
        return "+".join(f"{e}({law})" for e, law in zip(self.effects, self.laws)) \
            if self.effects else "soil_only"

    def law_values(self) -> dict[str, str]:
        """``effects.<name>.law`` of each effect: switches the effect on under its law
        (``WheelModel.with_parameters``), so it must come before the strengths."""
        return {f"effects.{e}.law": law for e, law in zip(self.effects, self.laws)}


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


def allowed_laws(model: tm.WheelModel, effects: list[str],
                 laws: dict[str, tuple[str, ...]] | None = None) -> dict[str, tuple[str, ...]]:
    """Per effect, the laws a candidate may use: ``laws[effect]`` if given (each checked
    against the family), else the simulation's law of an effect it has, else every law of
    the family."""
    laws = laws or {}
    unknown = sorted(set(laws) - set(tm.LAWS))
    if unknown:
        raise KeyError(f"unknown effect(s) {unknown} in laws; known: {sorted(tm.LAWS)}")
    out = {}
    for e in effects:
        if e in laws:
            for law in laws[e]:
                tm.law_class(e, law)  # a clear error for an unknown law
            out[e] = tuple(laws[e])
        elif e in model.effects:
            out[e] = (model.effects[e].law,)
        else:
            out[e] = tuple(tm.LAWS[e])
        if not out[e]:
            raise ValueError(f"no law left for effect {e!r}")
    return out


#: set loads a generalised law (``law~load``, ``law~depth``, ``law~slip``) needs: two fix a
#: load or depth exponent, a third tests it (the rut depth follows the load most); with
#: fewer, few conditions, the candidates keep to the published laws
MIN_LOADS_FOR_GENERALISED_LAWS = 3


def for_loads(allowed: dict[str, tuple[str, ...]], n_loads: int) -> dict[str, tuple[str, ...]]:
    """``allowed`` without the generalised laws (load- or depth-varying, lugs with
    slip-sinkage) where the points have fewer than :data:`MIN_LOADS_FOR_GENERALISED_LAWS` set
    loads (an exponent would only restate the published law's strength at the loads there
    are), unless they are all an effect has."""
    if n_loads >= MIN_LOADS_FOR_GENERALISED_LAWS:
        return allowed
    return {e: tuple(law for law in laws if tm.law_class(e, law).relaxes is None) or laws
            for e, laws in allowed.items()}


def candidate(model: tm.WheelModel, effects: tuple[str, ...],
              laws: dict[str, str] | None = None) -> Candidate:
    """Soil parameters and the strengths of ``effects`` (vocabulary order) under ``laws``
    (effect -> law; default: the simulation's law of an effect it has, else the default
    law)."""
    effects = tuple(sorted(effects, key=list(tm.EFFECTS).index))
    laws = laws or {}
    chosen = tuple(laws.get(e) or (model.effects[e].law if e in model.effects
                                   else tm.DEFAULT_LAWS[e]) for e in effects)
    params = soil_params(model) + tuple(p for e, law in zip(effects, chosen)
                                        for p in effect_params(e, law))
    return Candidate(effects, params, chosen)


#: the law of an effect whose shape none of its laws has: a discrepancy apart per level of
#: the factor the campaign sets for it (:data:`LEVEL_FACTOR`), alone or beside one of its
#: laws (``law/free_form``: the law and what differs between the levels beyond it)
FREE_FORM = "free_form"
#: what joins a law and the free form beside it, as in ``krenn_hirzinger2009/free_form``
BESIDE_LAW = "/"
#: the column of the points that sets each level effect's factor
LEVEL_FACTOR = {"multipass": "multipass", "reduced_gravity": "gravity_mps2",
                "grousers": "source"}


def law_beside(law: str) -> str | None:
    """The law beside which ``law`` puts the free form (``krenn_hirzinger2009`` of
    ``krenn_hirzinger2009/free_form``), None for any other law."""
    suffix = BESIDE_LAW + FREE_FORM
    return law[:-len(suffix)] if law.endswith(suffix) else None


def is_free_form(law: str) -> bool:
    """Whether ``law`` is :data:`FREE_FORM`, alone or beside a law."""
    return law == FREE_FORM or law_beside(law) is not None


def level_labels(frame: pd.DataFrame, column: str) -> np.ndarray:
    """Per row, its level of the factor ``column`` as text (gravity to 1e-4 m/s^2; a frame
    without sources is one source, "")."""
    if column not in frame:
        return np.full(len(frame), "" if column == "source" else "nan", dtype=object)
    values = frame[column].round(4) if column == "gravity_mps2" else frame[column]
    return values.astype(str).to_numpy()


def with_free_form(c: Candidate, effect: str) -> Candidate:
    """``c`` with ``effect`` added under :data:`FREE_FORM` (no parameter of its own), or,
    where ``c`` has ``effect`` under a law, that law beside the free form."""
    if effect in c.effects:
        laws = tuple(f"{law}{BESIDE_LAW}{FREE_FORM}" if e == effect else law
                     for e, law in zip(c.effects, c.laws))
        return Candidate(c.effects, c.params, laws)
    order = list(tm.EFFECTS).index
    pairs_ = sorted(zip(c.effects + (effect,), c.laws + (FREE_FORM,)), key=lambda x: order(x[0]))
    return Candidate(tuple(e for e, _ in pairs_), c.params, tuple(law for _, law in pairs_))


def singles(model: tm.WheelModel, laws: dict[str, tuple[str, ...]]) -> list[Candidate]:
    """Soil only, then each effect of ``laws`` alone under each of its laws."""
    return [candidate(model, ())] + [candidate(model, (e,), {e: law})
                                     for e, options in laws.items() for law in options]


def pairs(model: tm.WheelModel, laws: dict[str, tuple[str, ...]],
          reference: dict[str, str]) -> list[Candidate]:
    """Every pair of the effects of ``laws`` (effects mask each other: a pair can win where
    neither single does) under the ``reference`` laws, and with one of its two effects under
    each of its other laws (one law changed at a time)."""
    out = []
    for a, b in combinations(laws, 2):
        out.append(candidate(model, (a, b), {a: reference[a], b: reference[b]}))
        for moved, kept in ((a, b), (b, a)):
            out += [candidate(model, (a, b), {moved: law, kept: reference[kept]})
                    for law in laws[moved] if law != reference[moved]]
    return out
