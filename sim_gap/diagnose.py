"""One gap diagnosis: where (residual map), which (candidates under each law of each
effect, held-out ranking, a verdict that must hold under every law tried) and how far
(held-out RMSE before and after). Pure: points and a simulation in, a dict out."""

from __future__ import annotations

from concurrent.futures import ProcessPoolExecutor
from dataclasses import dataclass

import numpy as np
import pandas as pd

import terramechanics as tm

from sim_gap import candidates as cands
from sim_gap.crossval import CrossValidated, contrasts, cross_validate, folds
from sim_gap.aliasing import SEPARATING_RUN, aliasing_problem
from sim_gap.contrast_check import contrast_problem
from sim_gap.decide import rank, unless
from sim_gap.discriminate import separating_test
from sim_gap.fit import quantities_of, sigmas, standardised_residuals
from sim_gap.identify import identification_problem
from sim_gap.laws import best_fitting_laws, reference_laws, robust_decide
from sim_gap.regions import largest_gap, residual_map
from sim_gap.shrink import shrink
from sim_gap.simulated import Simulated
from swtlab.domain.gravity import G0_MPS2

#: a standardised prediction change below this (max over points) makes an effect untestable
TESTABLE_SIGMA = 0.2
#: what each effect needs from a campaign to show (for the untestable list)
CONTRAST_NEEDED = {"multipass": "a second multipass level",
                   "reduced_gravity": "a gravity level other than standard gravity "
                                      f"({G0_MPS2:g} m/s^2)",
                   "grousers": "a wheel with grousers (a grouser count and height in the model)",
                   "slip_sinkage": "several slips", "wheel_flexibility": "a flexible wheel",
                   "bulldozing": "measurable sinkage"}


@dataclass(frozen=True)
class Settings:
    """``max_nfev``/``fold_nfev``: evaluations of a full / a fold fit; ``n_boot``: bootstrap
    replicates; ``jobs``: worker processes for the candidate fits; ``laws``: effect -> the
    laws its candidates may use (default: every law of the family; see
    ``sim_gap.candidates.allowed_laws``)."""

    max_nfev: int = 40
    fold_nfev: int = 12
    n_boot: int = 200
    jobs: int = 1
    seed: int = 0
    laws: dict[str, tuple[str, ...]] | None = None


def testable(sim: Simulated, points: pd.DataFrame, laws: dict[str, tuple[str, ...]]
             ) -> tuple[list[str], dict[str, str]]:
    """Split the effects of ``laws`` into those that change a prediction at these conditions
    under one of their laws and the others (with what the campaign would need)."""
    sig = sigmas(points, sim.radius_m)
    base = sim.predict(points, {})
    keep, dropped = [], {}
    for name, options in laws.items():
        change = 0.0
        for law in options:
            values = {f"effects.{name}.law": law,
                      **{p.name: p.start for p in cands.effect_params(name, law)}}
            pred = sim.predict(points, values)
            change = max([change] + [float(np.nanmax(np.abs(pred[q] - base[q]) / sig[q]))
                                     for q in quantities_of(points)])
        if change >= TESTABLE_SIGMA:
            keep.append(name)
        else:
            dropped[name] = (f"it changes no prediction at these conditions; the campaign "
                             f"needs {CONTRAST_NEEDED[name]}")
    return keep, dropped


def _cv(args) -> CrossValidated:
    sim, c, points, sig, settings, start = args
    return cross_validate(sim, c, points, sig, start, max_nfev=settings.max_nfev,
                          fold_nfev=settings.fold_nfev)


def _pair_start(c: cands.Candidate, singles: dict[str, CrossValidated]) -> dict[str, float]:
    """Start of a pair's fit: the better single's fitted values (same law) plus the other
    effect's fitted strength."""
    fits = sorted((singles[f"{e}({law})"] for e, law in zip(c.effects, c.laws)),
                  key=lambda cv: cv.full.chi2)
    return {**fits[1].full.values, **fits[0].full.values}


def _run_all(sim, candidate_list, points, sig, settings, starts=None
             ) -> dict[str, CrossValidated]:
    starts = starts or [None] * len(candidate_list)
    jobs = [(sim, c, points, sig, settings, s) for c, s in zip(candidate_list, starts)]
    if settings.jobs > 1 and len(jobs) > 1:
        with ProcessPoolExecutor(settings.jobs) as pool:
            done = list(pool.map(_cv, jobs))
    else:
        done = [_cv(j) for j in jobs]
    return {c.key: cv for c, cv in zip(candidate_list, done)}


def diagnose(points: pd.DataFrame, sim: Simulated, effects: list[str] | None = None,
             settings: Settings | None = None) -> dict:
    """The gap report's content (docs/gap-report.md) for measured ``points`` against ``sim``;
    ``effects``: the candidate effects (default: every effect the simulation lacks)."""
    settings = settings or Settings()
    asked = [e for e in (effects or sim.missing_effects()) if e in sim.missing_effects()]
    effects_ok, untestable = testable(sim, points,
                                      cands.allowed_laws(sim.model, asked, settings.laws))
    allowed = cands.for_loads(cands.allowed_laws(sim.model, effects_ok, settings.laws),
                              contrasts(points)["load"])
    sig = sigmas(points, sim.radius_m)
    n = len(points)
    results = _run_all(sim, cands.singles(sim.model, allowed), points, sig, settings)
    reference = reference_laws(results, n)
    pairs = cands.pairs(sim.model, allowed, reference)
    results.update(_run_all(sim, pairs, points, sig, settings,
                            [_pair_start(c, results) for c in pairs]))
    decision = robust_decide(results, allowed, best_fitting_laws(results, reference, n), n)
    chosen = results[decision["chosen"]].full
    decision = unless(decision, identification_problem(sim, chosen, points, sig),
                      "unidentifiable")
    decision = unless(decision, aliasing_problem(
        points, sim.model.wheel, list(chosen.candidate.effects),
        dict(zip(chosen.candidate.effects, chosen.candidate.laws)), chosen.values), "aliased")
    modelled = [e for e in tm.EFFECTS if e not in sim.missing_effects()]
    decision = unless(decision, contrast_problem(
        points, standardised_residuals(points, sim.predict(points, chosen.values), sig),
        list(chosen.candidate.effects) + modelled), "level_contrast")
    if untestable and decision["verdict"] == []:
        decision["reason"] += ("; not testable with this campaign, so neither found nor ruled "
                               "out: " + ", ".join(sorted(untestable)))
    regions = residual_map(points, sim.predict(points, {}),
                           sim.predict(points, results["soil_only"].full.values), sim.radius_m)
    if decision.get("aliased"):
        decision["separating_test"] = {"test": SEPARATING_RUN, "separation_sigma": None}
    elif decision["verdict"] == "inconclusive" and len(decision["leaders"]) == 2:
        a, b = (results[key].full.values for key in decision["leaders"])
        decision["separating_test"] = separating_test(sim, points, a, b)
    elif decision["verdict"] == "inconclusive":
        decision["separating_test"] = largest_gap(regions)
    return {
        "verdict": decision["verdict"], "decision": decision, "candidates": rank(results, n),
        "untestable_effects": untestable, "contrasts": contrasts(points),
        "folds": [name for name, _ in folds(points)],
        "shrink": shrink(sim, points, results["soil_only"], results[decision["chosen"]],
                         settings.n_boot, settings.seed),
        "regions": regions,
        "n_points": n, "quantities": quantities_of(points),
        "sinkage_relative": bool(points.attrs.get("sinkage_relative", False)),
    }
