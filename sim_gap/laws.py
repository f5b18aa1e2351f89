"""Robustness of a verdict to the law of each effect.

Each effect is a family of published laws (``terramechanics.effects.LAWS``); real physics
follows none of them exactly. A verdict is confident only if the decision rule
(``sim_gap.decide``) gives the same confident verdict under every law assignment that
could have made the data: the reference assignment and each effect switched to each of
its other laws, one at a time (a one-at-a-time sensitivity design, Saltelli et al. 2008,
Global Sensitivity Analysis: The Primer, ch. 2). The reference is the assignment of the
best candidate of all (:func:`best_fitting_laws`: its effects' laws, the others each at
the law that scored best alone); until 0.7.0 it was each effect's best law alone, and a
pair whose effects fit best under other laws than alone was judged under laws the data
reject. An assignment whose best candidate loses to the reference's best by the margin of
a confident call (``Z_CONFIDENT`` paired SE and ``MIN_GAIN`` of its held-out loss) is
*refuted by the data*: it is listed, and does not vote. Any disagreement among the others
makes the verdict ``inconclusive``, naming the laws that disagree. Nothing here (nor in
``decide``) reads the shrink: a large shrink never raises confidence.
"""

from __future__ import annotations

import numpy as np

from sim_gap.crossval import CrossValidated
from sim_gap.decide import MIN_GAIN, Z_CONFIDENT, decide, gain, paired_z, rank


def reference_laws(singles: dict[str, CrossValidated], n_points: int) -> dict[str, str]:
    """Per effect, the law whose single candidate has the lowest mean held-out loss."""
    best: dict[str, tuple[float, str]] = {}
    for cv in singles.values():
        c = cv.full.candidate
        if len(c.effects) != 1:
            continue
        loss = float(cv.run_losses(n_points).mean())
        if c.effects[0] not in best or loss < best[c.effects[0]][0]:
            best[c.effects[0]] = (loss, c.laws[0])
    return {e: law for e, (_, law) in best.items()}


def best_fitting_laws(results: dict[str, CrossValidated], reference: dict[str, str],
                      n_points: int) -> dict[str, str]:
    """``reference`` with the laws of the candidate that has the lowest mean held-out loss of
    all (pairs included): the assignment under which the best explanation was found, the
    centre of the one-at-a-time law check. Effects mask each other, so a pair's best laws
    can differ from each effect's best law alone (bench seed 22 c005 in family: Lyasko
    slip-sinkage with Wong's flexible wheel at 0.08 sigma RMS, while Bekker's flexibility
    scored better alone)."""
    best = min(results.values(), key=lambda cv: cv.run_losses(n_points).mean())
    c = best.full.candidate
    return {**reference, **dict(zip(c.effects, c.laws))}


def assignments(allowed: dict[str, tuple[str, ...]], reference: dict[str, str]
                ) -> list[dict[str, str]]:
    """The reference laws, then each effect under each of its other laws (one at a time)."""
    return [dict(reference)] + [{**reference, e: law} for e, options in allowed.items()
                                for law in options if law != reference[e]]


def under(results: dict[str, CrossValidated], laws: dict[str, str]
          ) -> dict[str, CrossValidated]:
    """The candidates whose every effect has its law in ``laws``, by effect-set label."""
    return {cv.full.candidate.label: cv for cv in results.values()
            if all(laws.get(e) == law for e, law in zip(cv.full.candidate.effects,
                                                        cv.full.candidate.laws))}


def key_of(label: str, laws: dict[str, str]) -> str:
    """The candidate key (effects with their laws) of effect-set ``label`` under ``laws``."""
    if label == "soil_only":
        return label
    return "+".join(f"{e}({laws[e]})" for e in label.split("+"))


def _changed(laws: dict[str, str], reference: dict[str, str]) -> dict[str, str]:
    return {e: law for e, law in laws.items() if reference[e] != law}


def _text(verdict) -> str:
    return verdict if isinstance(verdict, str) else ("+".join(verdict) or "no missing effect")


def robust_decide(results: dict[str, CrossValidated], allowed: dict[str, tuple[str, ...]],
                  reference: dict[str, str], n_points: int) -> dict:
    """The decision under every assignment; confident only if they all agree. Returns the
    reference assignment's decision (leaders and chosen as candidate keys) with
    ``law_sensitivity``: the laws tried, each assignment's verdict, the disagreeing laws."""
    tried = []
    for laws in assignments(allowed, reference):
        sub = under(results, laws)
        losses = {label: cv.run_losses(n_points) for label, cv in sub.items()}
        d = decide(rank(sub, n_points), losses)
        tried.append({"laws_changed": _changed(laws, reference), "verdict": d["verdict"],
                      "chosen": key_of(d["chosen"], laws), "reason": d["reason"],
                      "leaders": [key_of(label, laws) for label in d["leaders"]],
                      "decision": d, "best": min(losses.values(), key=np.mean)})
    ref = tried[0]
    for t in tried:
        t["z_best_vs_reference"] = paired_z(t["best"], ref["best"]) if t is not ref else 0.0
        t["refuted"] = (t["z_best_vs_reference"] >= Z_CONFIDENT
                        and gain(t["best"], ref["best"]) >= MIN_GAIN)
    disagree = [t for t in tried[1:] if not t["refuted"] and (
        t["verdict"] != ref["verdict"] or t["verdict"] == "inconclusive")]
    sensitivity = {
        "reference_laws": reference, "laws_tried": {e: list(v) for e, v in allowed.items()},
        "assignments": [{k: t[k] for k in ("laws_changed", "verdict", "chosen", "reason",
                                           "z_best_vs_reference", "refuted")}
                        for t in tried],
        "refuted": [{"effect": e, "law": law, "z_best_vs_reference": t["z_best_vs_reference"]}
                    for t in tried if t["refuted"] for e, law in t["laws_changed"].items()],
        "disagreeing": [{"effect": e, "law": law, "verdict": t["verdict"],
                         "chosen": t["chosen"]}
                        for t in disagree for e, law in t["laws_changed"].items()],
        "robust": ref["verdict"] != "inconclusive" and not disagree,
        "one_law_only": all(len(v) == 1 for v in allowed.values())}
    out = {**ref["decision"], "chosen": ref["chosen"], "leaders": ref["leaders"],
           "law_sensitivity": sensitivity}
    if sensitivity["refuted"] and ref["verdict"] != "inconclusive" and not disagree:
        out["reason"] += ("; under " + ", ".join(f"{r['effect']} {r['law']}"
                                                   for r in sensitivity["refuted"])
                          + " the best explanation loses to this one by the margin of a "
                          "confident call: refuted by the data, so not counted")
    if ref["verdict"] == "inconclusive" or not disagree:
        return out
    rivals = [k for t in disagree for k in [t["chosen"], *t["leaders"]] if k != ref["chosen"]]
    swaps = "; ".join(f"with {e} under {law} it is {_text(t['verdict'])} ({t['chosen']})"
                      for t in disagree for e, law in t["laws_changed"].items())
    return {**out, "verdict": "inconclusive", "leaders": [ref["chosen"], *rivals[:1]],
            "law_dependent": True,
            "reason": f"the call depends on the shape of an effect's law: under the "
                      f"best-fitting laws the verdict is {_text(ref['verdict'])} "
                      f"({ref['chosen']}), but {swaps}"}
