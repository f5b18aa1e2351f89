"""The hypotheses of a gap diagnosis and what is believed of them before the data: the
parameters' priors, the prior probability of each effect set, and what the lab already
knows (which effects a campaign can carry at all).

Parameter priors (Gaussian in the fitted coordinates, log for the moduli):

- soil: centred on the simulation's own soil (the lab's best guess) with the spread of the
  published soils (:func:`sim_gap.priors.soil_prior`: how far one soil is from another when
  it was not measured);
- an effect's strengths: the range its law declares (``fit`` of each law class, the
  published range its docstring cites) taken as a Gaussian whose +-2 sigma is that range:
  centre the middle, standard deviation a quarter of the range (95 % of the prior inside the
  published range);
- except a strength that cannot be negative (declared lower end zero: a bulldozing, slip-
  sinkage, multipass or hysteresis coefficient, whose zero is that term's absence): a
  half-normal centred on zero whose 2 sigma is the published upper end (95 % inside the
  range, as above). Such a strength is known only by how large it can be, so the prior
  decreases from zero instead of vanishing there: a prior centred mid-range (a "non-local"
  prior; Johnson & Rossell 2010, "On the use of non-local prior densities in Bayesian
  hypothesis tests", JRSS B 72:143-170) makes a weak effect count as evidence for its
  absence and calls it absent with confidence, where a prior centred on the absence (Kass &
  Raftery 1995, "Bayes factors", JASA 90:773-795, sec. 5) leaves it undecided until the data
  can tell.

Effect-set priors: each effect that the campaign can carry (:func:`admissible`) is present
with one unknown probability ``p`` shared by them, uniform on [0, 1]; integrated over ``p``,
a set of ``k`` of the ``n`` admissible effects has prior ``k! (n - k)! / (n + 1)!``: every
number of missing effects, 0 to ``n``, is equally likely, and the sets of one size share
its mass (Scott & Berger 2010, "Bayes and empirical-Bayes multiplicity adjustment in the
variable-selection problem", Ann. Statist. 38:2587-2619: the beta-binomial prior, which
adjusts for the number of candidates instead of fixing each effect's chance). A lab
diagnoses a gap because it does not know how many effects the simulation lacks; a fixed
chance per effect would decide that for it (0.25 per effect puts 42 % on "none" among three
effects, where the uniform size prior puts 25 %). Sets of three or more effects are not
enumerated; their prior mass goes to the hypothesis "outside the candidates", together
with :data:`P_OTHER_EFFECT`, the stated prior that an effect not in the vocabulary is at
work. Within an effect set the prior is split equally over the law assignments fitted, so
a family with more laws gets no more prior mass.
"""

from __future__ import annotations

import math
from itertools import combinations

import numpy as np
import pandas as pd

import terramechanics as tm
from sim_gap.candidates import Candidate
from sim_gap.priors import soil_prior

#: prior probability that an effect outside the vocabulary is at work
P_OTHER_EFFECT = 0.1
#: the key of the hypothesis "an effect outside the candidates (or more than two)"
OUTSIDE = "outside_candidates"
#: what a campaign or wheel needs before an effect is a hypothesis (for the report)
NEEDS = {"wheel_flexibility": "a wheel with a declared radial stiffness (a flexible wheel)",
         "grousers": "a wheel with grousers",
         "multipass": "two multipass levels",
         "reduced_gravity": "two gravity levels"}


def param_prior(c: Candidate, model: tm.WheelModel) -> tuple[np.ndarray, np.ndarray]:
    """Prior centre and standard deviation of ``c``'s parameters, internal coordinates."""
    soil = {p.name: p for p in soil_prior(model.wheel.width_m)}
    centre, sd = [], []
    for p in c.params:
        to = np.log if p.log else float
        if p.name in soil:
            centre.append(to(p.start))
            sd.append(soil[p.name].spread)
        elif not p.log and p.lower == 0.0:
            centre.append(0.0)
            sd.append(0.5 * p.upper)
        else:
            lo, hi = _internal_range(p)
            centre.append(0.5 * (lo + hi))
            sd.append(0.25 * (hi - lo))
    return np.array(centre, float), np.array(sd, float)


def mid_range(c: Candidate, model: tm.WheelModel) -> np.ndarray:
    """``c``'s parameters at the middle of their declared ranges (soil: its prior centre),
    internal coordinates: how large each effect is a priori, for sizing what an effect
    outside the candidates may do (:func:`sim_gap.diagnose.outside_amplitudes`)."""
    centre, _ = param_prior(c, model)
    soil = {p.name for p in soil_prior(model.wheel.width_m)}
    return np.array([centre[i] if p.name in soil else 0.5 * sum(_internal_range(p))
                     for i, p in enumerate(c.params)], float)


def _internal_range(p) -> tuple[float, float]:
    """A parameter's declared range in internal coordinates (log for a log parameter)."""
    to = np.log if p.log else float
    return float(to(p.lower)), float(to(p.upper))


def _wheels(points: pd.DataFrame) -> list:
    wheels = points.attrs.get("wheels") or {}
    return list(wheels.values()) or [w for w in [points.attrs.get("wheel")] if w is not None]


def admissible(effects: list[str], points: pd.DataFrame) -> tuple[list[str], dict[str, str]]:
    """Split ``effects`` into those the lab's declarations and the campaign's levels allow and
    the others with what they would need: wheel flexibility only on a wheel with a declared
    stiffness, grousers only on a wheel with grousers, multipass and reduced gravity only
    with two levels of their factor (one level cannot tell the effect from the soil). A
    source whose wheel is unknown allows every wheel effect."""
    wheels = _wheels(points)
    known = bool(wheels)
    allowed = {
        "wheel_flexibility": not known or any(
            getattr(w, "stiffness_n_per_mm", None) for w in wheels),
        "grousers": not known or any(w.grouser_count > 0 and w.grouser_height_m > 0
                                     for w in wheels),
        "multipass": points["multipass"].nunique() >= 2,
        "reduced_gravity": points["gravity_mps2"].round(6).nunique() >= 2}
    keep = [e for e in effects if allowed.get(e, True)]
    return keep, {e: NEEDS[e] for e in effects if not allowed.get(e, True)}


def set_prior(effects: tuple[str, ...], n_admissible: int) -> float:
    """Prior probability of exactly the effect set ``effects`` among ``n_admissible``."""
    k = len(effects)
    return ((1.0 - P_OTHER_EFFECT) * math.factorial(k) * math.factorial(n_admissible - k)
            / math.factorial(n_admissible + 1))


def outside_prior(n_admissible: int) -> float:
    """Prior probability of "outside the candidates": an effect outside the vocabulary, or
    three or more of the admissible ones."""
    enumerated = sum(set_prior(s, n_admissible) for k in range(3)
                     for s in combinations(range(n_admissible), k))
    return 1.0 - enumerated


def hypothesis_priors(candidates: list[Candidate], n_admissible: int) -> dict[str, float]:
    """Prior probability of each candidate (key) and of :data:`OUTSIDE`: its effect set's
    prior split equally over the candidates of that set."""
    by_set: dict[tuple[str, ...], list[str]] = {}
    for c in candidates:
        by_set.setdefault(c.effects, []).append(c.key)
    out = {key: set_prior(effects, n_admissible) / len(keys)
           for effects, keys in by_set.items() for key in keys}
    out[OUTSIDE] = outside_prior(n_admissible)
    return out
