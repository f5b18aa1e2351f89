"""Posterior probabilities of the hypotheses and the verdict.

``P(H | data) = P(H) Z_H^eta / sum_H' P(H') Z_H'^eta`` with the evidences ``Z`` of
:mod:`sim_gap.evidence`, the priors of :mod:`sim_gap.hypotheses` and the learning rate
``eta`` (:func:`learning_rate`) of a generalised posterior (Bissiri, Holmes & Walker 2016,
"A general framework for updating belief distributions", JRSS B 78:1103-1130). With
``eta = 1`` this is Bayes' rule, which grows overconfident when every hypothesis is
misspecified (Grünwald & van Ommen 2017, Bayesian Analysis 12:1069-1103): the base model
is another solver than the lab's wheel, and what one run's soil does to its drawbar pull,
torque and sinkage together is not in the noise model, so the evidence counts the same
information several times. The report's probabilities are this posterior bagged over
bootstrap copies of the campaign's runs (:mod:`sim_gap.bagging`): misspecified hypotheses
make Bayes' rule concentrate on whichever one the particular runs favour. An effect set's
probability is the sum over the laws it was fitted under (a family of laws is one
hypothesis about the physics, its laws are ways to draw it); an effect's probability is the
sum over the sets that contain it.

The verdict names the most probable effect set (or "outside the candidates") only when its
probability is at least :data:`CALL_PROBABILITY`; otherwise it is ``inconclusive`` with the
leading hypotheses and their probabilities. Derivation of 0.9 (a decision cost; Berger 1985,
Statistical Decision Theory and Bayesian Analysis, ch. 4): calling a hypothesis costs
``C_wrong`` when it is wrong, saying ``inconclusive`` costs ``C_more`` (another test), so a
call pays when ``(1 - p) C_wrong < C_more``. A wrong call sends a lab to model the wrong
effect and costs about ten times a further test series: ``p > 1 - 1/10``.
"""

from __future__ import annotations

import numpy as np

from sim_gap.hypotheses import OUTSIDE

#: the probability at which the verdict names a hypothesis (module docstring)
CALL_PROBABILITY = 0.9


def learning_rate(dispersion: float) -> float:
    """The power on the evidence: ``1 / phi``, at most one, with ``phi`` the held-out
    dispersion of the most probable named hypothesis' own model (noise, run soil, nugget,
    discrepancy and parameters; :func:`sim_gap.evidence.held_out_dispersion`).
    Quasi-likelihood divides the log likelihood of an overdispersed model by its dispersion
    (Wedderburn 1974, Biometrika 61:439-447; McCullagh & Nelder 1989, Generalized Linear
    Models, sec. 9.2): a model whose held-out runs scatter ``sqrt(phi)`` times wider than its
    covariance says learns ``phi`` times less from each of them. The dispersion is that of
    the model whose evidence is tempered, measured on runs it did not see: measured against
    the noise alone it would count the discrepancy and the run soil the model already
    carries as misfit a second time. A model whose held-out runs scatter as it says
    (``phi <= 1``) keeps Bayes' rule."""
    return float(min(1.0, 1.0 / dispersion)) if dispersion > 0 else 1.0


def posterior(log_evidence: dict[str, float], prior: dict[str, float],
              eta: float = 1.0) -> dict[str, float]:
    """Posterior probability of each hypothesis key at learning rate ``eta``."""
    keys = list(log_evidence)
    logs = np.array([eta * log_evidence[k] + np.log(prior[k]) for k in keys])
    p = np.exp(logs - logs.max())
    return dict(zip(keys, (p / p.sum()).tolist()))


def set_label(effects) -> str:
    return "+".join(effects) if effects else "soil_only"


def by_effect_set(hypotheses: list[dict]) -> list[dict]:
    """``{label, effects, probability}`` per effect set (laws summed), most probable first."""
    sets: dict[str, dict] = {}
    for h in hypotheses:
        label = OUTSIDE if h["key"] == OUTSIDE else set_label(h["effects"])
        entry = sets.setdefault(label, {"label": label, "effects": list(h["effects"]),
                                        "probability": 0.0})
        entry["probability"] += h["probability"]
    return sorted(sets.values(), key=lambda s: -s["probability"])


def by_effect(hypotheses: list[dict], effects: list[str],
              outside_bases: dict[str, float] | None = None) -> dict[str, float]:
    """Probability that each effect is part of the explanation: the named hypotheses that
    hold it, and the part of "outside the candidates" whose base holds it
    (``outside_bases``: effect -> the share of the outside hypothesis' evidence on bases with
    that effect; an effect outside the vocabulary may act beside one inside it)."""
    outside = sum(h["probability"] for h in hypotheses if h["key"] == OUTSIDE)
    return {e: float(sum(h["probability"] for h in hypotheses
                         if h["key"] != OUTSIDE and e in h["effects"])
                     + outside * (outside_bases or {}).get(e, 0.0)) for e in effects}


def _words(label: str) -> str:
    """An effect set in plain words (``grousers+slip_sinkage`` -> ``grousers + slip
    sinkage``)."""
    return {"soil_only": "no missing effect", OUTSIDE: "an effect outside the candidates"
            }.get(label, label.replace("+", " + ").replace("_", " "))


def decide(hypotheses: list[dict], separation_sigma: float | None = None,
           eta: float = 1.0) -> dict:
    """The verdict from ``hypotheses`` (each with ``key``, ``effects``, ``probability``).
    ``separation_sigma``: the largest standardised difference between the two leading named
    hypotheses' predictions at the measured conditions (None if not computed; below one
    sigma the reason says the points cannot tell them apart). Returns
    ``verdict`` (effects, ``"outside_candidates"`` or ``"inconclusive"``), ``chosen`` (the most
    probable named hypothesis' key), ``probability`` (of the leading set), ``leaders``
    (the two leading sets with their probabilities), ``call_probability`` and ``reason``."""
    sets = by_effect_set(hypotheses)
    named = [h for h in hypotheses if h["key"] != OUTSIDE]
    lead = sets[0]
    in_lead = [h for h in named if set_label(h["effects"]) == lead["label"]] or named
    chosen = max(in_lead, key=lambda h: h["probability"])["key"]
    leaders = [{"label": s["label"], "probability": s["probability"]} for s in sets[:2]]
    out = {"chosen": chosen, "probability": lead["probability"], "leaders": leaders,
           "call_probability": CALL_PROBABILITY, "learning_rate": eta,
           "leaders_separation_sigma": separation_sigma}
    p = f"{lead['probability']:.2f}"
    if lead["probability"] >= CALL_PROBABILITY:
        verdict = OUTSIDE if lead["label"] == OUTSIDE else list(lead["effects"])
        reason = (f"{_words(lead['label'])} has probability {p} (a verdict needs "
                  f"{CALL_PROBABILITY:g})")
        if lead["label"] == OUTSIDE:
            reason += ("; no candidate effect, alone or in pairs, carries the gap the "
                       "soil leaves")
        return {**out, "verdict": verdict, "reason": reason}
    second = sets[1] if len(sets) > 1 else None
    reason = f"no hypothesis reaches probability {CALL_PROBABILITY:g}: {_words(lead['label'])} " \
             f"{p}"
    if second is not None:
        reason += f", {_words(second['label'])} {second['probability']:.2f}"
        if separation_sigma is not None and separation_sigma < 1.0:
            reason += (f"; their predictions differ by at most {separation_sigma:.1f} σ "
                       "at the measured conditions: these points cannot tell them apart")
    return {**out, "verdict": "inconclusive", "reason": reason}
