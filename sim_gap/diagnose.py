"""One gap diagnosis: where (residual map), which (the posterior probability of every
hypothesis: no missing effect, each effect under each law of its family, pairs, an effect
outside the candidates; :mod:`sim_gap.evidence`, :mod:`sim_gap.decide`), what the siblings
show (:mod:`sim_gap.siblings`) and how far the gap shrinks (held-out RMSE before and after).
Pure: points and a simulation in, a dict out."""

from __future__ import annotations

from concurrent.futures import ProcessPoolExecutor
from dataclasses import dataclass, replace

import numpy as np
import pandas as pd
from scipy.special import logsumexp
from threadpoolctl import threadpool_limits

from terramechanics.model import BRAKED_LAWS
from sim_gap import candidates as cands
from sim_gap.bagging import N_BAGS, BagModel, bagged_posterior
from sim_gap.crossval import contrasts, folds, held_out
from sim_gap.decide import by_effect, by_effect_set, decide, learning_rate
from sim_gap.evidence import (TAU_GRID, Evidence, apart_by, covariances,
                              held_out_dispersion, level_groups, log_evidence,
                              observations, run_soil, same_partition, soil_drift)
from sim_gap.fit import (MapFit, fit_map, internal_bounds, quantities_of, sigmas, strengths,
                         to_values)
from sim_gap.hypotheses import (OUTSIDE, admissible, hypothesis_priors, mid_range, param_prior,
                                set_prior)
from sim_gap.next_test import TOP_TESTS, next_tests
from sim_gap.regions import largest_gap, residual_map
from sim_gap.shrink import shrink
from sim_gap.siblings import contrasts as sibling_contrasts
from sim_gap.simulated import Simulated
from sim_gap.vocabulary import model_error_floor
from swtlab_base.domain.gravity import G0_MPS2

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
    """``max_nfev``/``fold_nfev``: evaluations of a MAP fit / a held-out fold fit (the
    shrink's two candidates); ``n_boot``: bootstrap replicates of the shrink; ``n_bags``:
    bootstrap copies of the bagged posterior (:mod:`sim_gap.bagging`); ``jobs``: worker processes
    for the candidate fits; ``laws``: effect -> the laws its candidates may use (default:
    every law of the family; see
    ``sim_gap.candidates.allowed_laws``)."""

    max_nfev: int = 40
    fold_nfev: int = 40
    n_boot: int = 200
    jobs: int = 1
    seed: int = 0
    laws: dict[str, tuple[str, ...]] | None = None
    n_bags: int = N_BAGS


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


def _fit(args) -> MapFit:
    sim, c, points, sig, settings, start = args
    with threadpool_limits(limits=1, user_api="blas"):  # in a worker process too
        return fit_map(sim, c, points, sig, param_prior(c, sim.model), start,
                       settings.max_nfev)


def _pair_start(c: cands.Candidate, singles: dict[str, MapFit]) -> dict[str, float]:
    """Start of a pair's fit: the better single's fitted values (same law) plus the other
    effect's fitted strength."""
    fits = sorted((singles[f"{e}({law})"] for e, law in zip(c.effects, c.laws)),
                  key=lambda f: f.fit.chi2)
    return {**strengths(fits[1].fit.values), **strengths(fits[0].fit.values)}


def _fit_all(sim, candidate_list, points, sig, settings, starts=None) -> dict[str, MapFit]:
    starts = starts or [None] * len(candidate_list)
    jobs = [(sim, c, points, sig, settings, s) for c, s in zip(candidate_list, starts)]
    if settings.jobs > 1 and len(jobs) > 1:
        with ProcessPoolExecutor(settings.jobs) as pool:
            done = list(pool.map(_fit, jobs))
    else:
        done = [_fit(j) for j in jobs]
    return {c.key: f for c, f in zip(candidate_list, done)}


def _evidence(cov, obs, sim: Simulated, f: MapFit) -> Evidence:
    """The evidence of fit ``f`` with its prior truncated to its parameters' ranges."""
    centre, sd = param_prior(f.fit.candidate, sim.model)
    lo, hi = internal_bounds(f.fit.candidate)
    return log_evidence(cov, obs.y, f.predicted, f.jac, f.internal - centre, sd,
                        (lo - centre, hi - centre))


def _braked_law(sim: Simulated, points: pd.DataFrame, obs, fit_sig, settings: Settings
                ) -> tuple[Simulated, dict, dict[str, MapFit]]:
    """``sim`` with the base model's braked branch (:data:`terramechanics.model.BRAKED_LAWS`)
    whose soil-only recalibration has the larger evidence, where the points have braked or
    towed runs (slip < 0), and the log evidence of each (empty without such runs). The two
    published treatments of a braked wheel (Wong & Reece 1967 part II; part I at the signed
    slip, Ishigami et al. 2007) are two forms of the base model with equal prior weight: the
    choice is made once, by the evidence of soil recalibration alone (type II), before any
    effect is fitted, so no effect can pick the branch that suits it. Also returns the
    chosen branch's soil-only fit under its key (the first of the singles, not fitted
    twice), none without braked runs."""
    if not (points["slip"].to_numpy(float) < 0).any():
        return sim, {}, {}
    trials, scores, soils = {}, {}, {}
    for law in BRAKED_LAWS:
        trial = replace(sim, model=replace(sim.model, braked_law=law), _base_cache={})
        soil = _fit_all(trial, [cands.candidate(trial.model, ())], points, fit_sig,
                        settings)["soil_only"]
        obs_law = run_soil(obs, soil.jac, param_prior(soil.fit.candidate, trial.model)[1])
        trials[law], soils[law] = trial, soil
        scores[law] = _evidence(covariances(obs_law), obs_law, trial, soil).log_evidence
    best = max(scores, key=scores.__getitem__)
    return (trials[best], {"braked_law": best, "soil_only_log_evidence": scores},
            {"soil_only": soils[best]})


def _reference_laws(fits: dict[str, MapFit], evidence: dict[str, Evidence]) -> dict[str, str]:
    """Per effect, the law of its single with the largest evidence."""
    best: dict[str, tuple[float, str]] = {}
    for key, f in fits.items():
        c = f.fit.candidate
        if len(c.effects) == 1 and (c.effects[0] not in best
                                    or evidence[key].log_evidence > best[c.effects[0]][0]):
            best[c.effects[0]] = (evidence[key].log_evidence, c.laws[0])
    return {e: law for e, (_, law) in best.items()}


def outside_amplitudes(sim: Simulated, points: pd.DataFrame, obs,
                       singles: list[cands.Candidate]) -> np.ndarray:
    """Amplitudes (floor units) of the discrepancy apart per source and level that stands for
    an effect outside the candidates: a priori as large as the candidate effects are, i.e.
    log-uniform from half the smallest to twice the largest RMS change (in floor units) that
    one candidate effect makes at the middle of its declared ranges, over five values."""
    base = sim.predict(points, {})
    quantities = quantities_of(points)
    base_flat = np.column_stack([base[q] for q in quantities])[obs.where]
    sizes = []
    for c in singles:
        if not c.effects:
            continue
        pred = sim.predict(points, to_values(c, mid_range(c, sim.model)))
        change = np.column_stack([pred[q] for q in quantities])[obs.where] - base_flat
        sizes.append(float(np.sqrt(np.nanmean((change / obs.floor) ** 2))))
    sizes = [s for s in sizes if np.isfinite(s) and s > 0] or [float(TAU_GRID[-1])]
    lo, hi = max(0.5 * min(sizes), TAU_GRID[0]), max(2.0 * max(sizes), TAU_GRID[0])
    return np.geomspace(lo, max(hi, lo), 5)


def _levels(points: pd.DataFrame, effect: str) -> np.ndarray | None:
    """Per point, the level of the factor that sets ``effect`` (``cands.LEVEL_FACTOR``): the
    multipass level, the gravity level, or the lugs of the source's wheel; None where the
    points hold fewer than two levels."""
    if effect == "grousers":
        wheels = points.attrs.get("wheels") or {}
        if "source" not in points or not wheels:
            return None
        levels = np.array([f"{w.grouser_count} x {w.grouser_height_m:g} m" if (
            w := wheels.get(s)) else "unknown" for s in points["source"]])
    else:
        levels = cands.level_labels(points, cands.LEVEL_FACTOR[effect])
    return levels if len(set(levels.tolist())) >= 2 else None


def _bag(sim: Simulated, obs, cov, f: MapFit, e: Evidence) -> BagModel:
    """What the bagged posterior needs of hypothesis fit ``f`` with evidence ``e`` on the
    covariances ``cov`` of ``obs`` (:mod:`sim_gap.bagging`)."""
    centre, sd = param_prior(f.fit.candidate, sim.model)
    lo, hi = internal_bounds(f.fit.candidate)
    return BagModel(obs, tuple(map(float, cov.sizes[e.best_grid])), f.predicted, f.jac,
                    f.internal - centre, sd, (lo - centre, hi - centre),
                    e.log_evidence - e.log_at_best)


def _bases(fits: dict[str, MapFit], reference: dict[str, str]) -> list[MapFit]:
    """Soil recalibration alone and each candidate effect under its reference law: what a
    free-form effect or an effect outside the candidates acts on."""
    return [fits["soil_only"]] + [fits[f"{e}({law})"] for e, law in reference.items()]


def free_forms(sim: Simulated, obs, fits: dict[str, MapFit], reference: dict[str, str],
               free_levels: dict[str, np.ndarray], amplitudes: np.ndarray
               ) -> dict[str, tuple[cands.Candidate, MapFit, Evidence, BagModel]]:
    """Each level effect (multipass, reduced gravity, grousers with a sibling wheel) with a
    shape none of its laws has: the discrepancy apart per level of its factor, sized as the
    candidate effects are (``amplitudes``), on top of soil recalibration alone, of each
    other effect under its reference law, or of the effect's own reference law (what
    differs between the levels beyond that law); ``free_levels``: effect -> its factor's
    level per point (:func:`_levels`). An effect is what differs between the
    levels of its factor, whatever its shape: "multipass, in a form the laws lack" is a
    member of the multipass family, not an effect outside the candidates (which therefore
    does not take this form where the effect's factor is the only one that varies:
    :func:`outside_forms`)."""
    out = {}
    for effect, levels in free_levels.items():
        apart = apart_by(obs, levels)
        cov = covariances(apart, amplitudes)
        for base in _bases(fits, reference):
            c = cands.with_free_form(base.fit.candidate, effect)
            e = _evidence(cov, obs, sim, base)
            out[c.key] = (c, base, e, _bag(sim, apart, cov, base, e))
    return out


#: what each form of the outside hypothesis stands for (the verdict's reason names the one
#: that carries most of its evidence)
OUTSIDE_FORMS = {"levels": ("a difference between sources or levels, or an error alike on "
                            "all of them, that no candidate makes"),
                 "velocity": "a difference between travel velocities (no candidate depends on "
                             "the velocity)",
                 "drift": "a soil that drifts through the campaign (read from the runs' start "
                          "times)"}


def outside_forms(sim: Simulated, points: pd.DataFrame, obs, amplitudes: np.ndarray,
                  soil: MapFit, free_levels: list[np.ndarray]) -> dict[str, tuple]:
    """The forms of the hypothesis "an effect outside the candidates", each the observations
    with its second discrepancy and that discrepancy's sizes: apart per source and level
    (sized as the candidate effects are, ``amplitudes``, as are the other forms), or common
    to every source and level where the sources and levels differ in one level effect's
    factor alone (``free_levels``: the levels of each effect with a free form,
    :func:`free_forms`): what differs between the levels of that factor is that effect by
    definition, and its free form is the same model on the same bases, so an effect outside
    the candidates is what acts alike on every level there; apart per
    set travel velocity, where the runs have two or more (no candidate law depends on the
    velocity, so a rate effect in the soil or the rig is outside them); a soil that drifts
    through the campaign (:func:`sim_gap.evidence.soil_drift`), where every run's start
    time is known. One size prior for every form: an effect outside the candidates is a
    priori as large as the candidate effects are, whatever its form."""
    groups = level_groups(points)
    if any(same_partition(groups, levels) for levels in free_levels):
        obs = replace(obs, kernel_grouped=obs.kernel_shared)
    forms = {"levels": (obs, amplitudes)}
    if "velocity_set_mps" in points:
        velocity = points["velocity_set_mps"].to_numpy(float).round(6)
        if np.isfinite(velocity).all() and np.unique(velocity).size >= 2:
            forms["velocity"] = (apart_by(obs, velocity), amplitudes)
    if "started_unix_h" in points:
        drift = soil_drift(obs, points["started_unix_h"].to_numpy(float), soil.jac,
                           param_prior(soil.fit.candidate, sim.model)[1])
        if drift is not None:
            forms["drift"] = (drift, amplitudes)
    return forms


def outside(sim: Simulated, obs, forms: dict[str, tuple], fits: dict[str, MapFit],
            reference: dict[str, str], n_admissible: int
            ) -> tuple[MapFit, Evidence, list[tuple[BagModel, float]], dict[str, float],
                       dict[str, float]]:
    """The hypothesis "an effect outside the candidates" on top of soil recalibration alone
    or of one candidate effect under its reference law, in each of its ``forms``
    (:func:`outside_forms`) with equal prior weight. Its prior
    (:func:`sim_gap.hypotheses.outside_prior`) is that of an effect outside the vocabulary
    at work beside any of the candidates, so its evidence is the mixture over forms and
    bases weighted by the forms' weights and the bases' effect sets' priors
    (:func:`sim_gap.hypotheses.set_prior`). Returns the most probable term's fit, the
    mixture's evidence (with that term's discrepancy sizes), each term's bagging model with
    its weight, each form's share of the evidence and, per effect, the share of the bases
    that hold it."""
    bases = _bases(fits, reference)
    log_weight = np.log([set_prior(f.fit.candidate.effects, n_admissible) for f in bases])
    log_weight -= logsumexp(log_weight) + np.log(len(forms))
    terms, each, bags, form_of = [], [], [], []
    for name, (form_obs, sizes) in forms.items():
        cov = covariances(form_obs, sizes)
        for f, w in zip(bases, log_weight):
            e = _evidence(cov, obs, sim, f)
            terms.append(w + e.log_evidence)
            each.append((f, e))
            bags.append((_bag(sim, form_obs, cov, f, e), float(np.exp(w))))
            form_of.append(name)
    terms = np.array(terms)
    best = int(np.argmax(terms))
    total = float(logsumexp(terms))
    shares = {name: float(np.exp(logsumexp(terms[[f == name for f in form_of]]) - total))
              for name in forms}
    effects = {e for f in bases for e in f.fit.candidate.effects}
    with_effect = {e: float(np.exp(logsumexp(terms[[e in f.fit.candidate.effects
                                                    for f, _ in each]]) - total))
                   for e in effects}
    return each[best][0], replace(each[best][1], log_evidence=total), bags, shares, with_effect


def _leading_sets(hypotheses: list[dict]) -> list[str]:
    """The most probable hypothesis (key) of each of the two most probable effect sets, when
    both are named (outside the candidates has no prediction to separate)."""
    sets = by_effect_set(hypotheses)[:2]
    if len(sets) < 2 or any(s["label"] == OUTSIDE for s in sets):
        return []
    return [max((h for h in hypotheses if h["key"] != OUTSIDE
                 and "+".join(h["effects"]) == ("+".join(s["effects"]))),
                key=lambda h: h["probability"])["key"] for s in sets]


def _separation(sim, points, obs, fits: dict[str, MapFit], a: str, b: str) -> float:
    """Largest difference of two hypotheses' predictions at the measured conditions, in
    units of the noise and discrepancy floor."""
    d = fits[a].predicted - fits[b].predicted
    return float(np.nanmax(np.abs(d) / np.hypot(obs.sigma, obs.floor)))


def _bagged(bags: dict[str, BagModel], outside_bags: list[tuple[BagModel, float]],
            prior: dict[str, float], eta: float, settings: Settings) -> dict[str, float]:
    """The bagged posterior (:mod:`sim_gap.bagging`) of the named hypotheses and of
    "outside the candidates", the latter over its bases (their priors split by weight)."""
    models = dict(bags)
    split = {k: v for k, v in prior.items() if k != OUTSIDE}
    for i, (bag, weight) in enumerate(outside_bags):
        models[f"{OUTSIDE}@{i}"] = bag
        split[f"{OUTSIDE}@{i}"] = prior[OUTSIDE] * weight
    bagged = bagged_posterior(models, split, eta, settings.n_bags, settings.seed)
    out = {k: bagged[k] for k in bags}
    out[OUTSIDE] = sum(bagged[f"{OUTSIDE}@{i}"] for i in range(len(outside_bags)))
    return out


def _dispersion(sim: Simulated, obs, cov, fits: dict[str, MapFit],
                evidence: dict[str, Evidence], candidate_of: dict[str, cands.Candidate]
                ) -> float:
    """Held-out dispersion (:func:`sim_gap.evidence.held_out_dispersion`) of the named
    hypothesis with the largest evidence among those on the campaign's covariance (not the
    free forms, whose covariance is apart per level), at its most probable discrepancy,
    nugget and run soil."""
    best = max((k for k in evidence if k != OUTSIDE
                and not any(map(cands.is_free_form, candidate_of[k].laws))),
               key=lambda k: evidence[k].log_evidence)
    f = fits[best]
    centre, sd = param_prior(f.fit.candidate, sim.model)
    return held_out_dispersion(cov, evidence[best].best_grid, obs.y, f.predicted, f.jac,
                               f.internal - centre, sd, obs.point)


def _fit_noise(points: pd.DataFrame, sig: dict[str, np.ndarray], radius_m: float
               ) -> dict[str, np.ndarray]:
    """The MAP fits' noise: the measured noise with the discrepancy at the middle of its grid
    (one floor) in quadrature, as if independent."""
    load = points["wheel_load_n"].to_numpy(float)
    return {q: np.hypot(s, model_error_floor(q, load, radius_m)) for q, s in sig.items()}


def diagnose(points: pd.DataFrame, sim: Simulated, effects: list[str] | None = None,
             settings: Settings | None = None) -> dict:
    """The gap report's content (docs/gap-report.md) for measured ``points`` against ``sim``;
    ``effects``: the candidate effects (default: every effect the simulation lacks). BLAS
    runs on one thread: its matrices (a few hundred entries) factor faster alone than split
    over cores that the candidate fits already keep busy."""
    with threadpool_limits(limits=1, user_api="blas"):
        return _diagnose(points, sim, effects, settings or Settings())


def _diagnose(points: pd.DataFrame, sim: Simulated, effects: list[str] | None,
              settings: Settings) -> dict:
    asked = [e for e in (effects or sim.missing_effects()) if e in sim.missing_effects()]
    admitted, excluded = admissible(asked, points)
    effects_ok, untestable = testable(sim, points,
                                      cands.allowed_laws(sim.model, admitted, settings.laws))
    untestable.update({e: f"not a hypothesis here: it needs {need}"
                       for e, need in excluded.items()})
    allowed = cands.for_loads(cands.allowed_laws(sim.model, effects_ok, settings.laws),
                              contrasts(points)["load"])
    sig = sigmas(points, sim.radius_m)
    obs = observations(points, sig, sim.radius_m)
    fit_sig = _fit_noise(points, sig, sim.radius_m)
    sim, base_model, fits = _braked_law(sim, points, obs, fit_sig, settings)
    single_list = cands.singles(sim.model, allowed)
    fits.update(_fit_all(sim, [c for c in single_list if c.key not in fits], points, fit_sig,
                         settings))
    obs = run_soil(obs, fits["soil_only"].jac,
                   param_prior(fits["soil_only"].fit.candidate, sim.model)[1])
    cov = covariances(obs)
    evidence = {k: _evidence(cov, obs, sim, f) for k, f in fits.items()}
    reference = _reference_laws(fits, evidence)
    pairs = cands.pairs(sim.model, allowed, reference)
    pair_fits = _fit_all(sim, pairs, points, fit_sig, settings,
                         [_pair_start(c, fits) for c in pairs])
    evidence.update({k: _evidence(cov, obs, sim, f) for k, f in pair_fits.items()})
    fits.update(pair_fits)
    candidate_of = {k: f.fit.candidate for k, f in fits.items()}
    amplitudes = outside_amplitudes(sim, points, obs, single_list)
    bags = {k: _bag(sim, obs, cov, f, evidence[k]) for k, f in fits.items()}
    free_levels = {e: levels for e in reference if e in cands.LEVEL_FACTOR
                   and (levels := _levels(points, e)) is not None}
    for key, (c, base, e, bag) in free_forms(sim, obs, fits, reference, free_levels,
                                             amplitudes).items():
        candidate_of[key], fits[key], evidence[key], bags[key] = c, base, e, bag
    forms = outside_forms(sim, points, obs, amplitudes, fits["soil_only"],
                          list(free_levels.values()))
    fits[OUTSIDE], evidence[OUTSIDE], outside_bags, form_shares, outside_effects = outside(
        sim, obs, forms, fits, reference, len(allowed))
    prior = hypothesis_priors(list(candidate_of.values()), len(allowed))
    eta = learning_rate(_dispersion(sim, obs, cov, fits, evidence, candidate_of))
    probability = _bagged(bags, outside_bags, prior, eta, settings)
    hypotheses = sorted(
        [_hypothesis(k, candidate_of.get(k), fits.get(k, fits["soil_only"]), evidence[k],
                     prior[k], probability[k]) for k in evidence],
        key=lambda h: -h["probability"])
    leaders = _leading_sets(hypotheses)
    separation = (_separation(sim, points, obs, fits, *leaders) if len(leaders) == 2 else None)
    decision = decide(hypotheses, separation, eta)
    decision["reason"] += _discrepancy_text(points, sim, evidence[decision["chosen"]])
    form, share = max(form_shares.items(), key=lambda kv: kv[1])
    if hypotheses[0]["key"] == OUTSIDE and len(forms) > 1 and share > 0.5:
        decision["reason"] += (f"; {share:.0%} of the outside hypothesis' evidence is "
                               f"{OUTSIDE_FORMS[form]}")
    chosen = fits[decision["chosen"]].fit
    if untestable and decision["verdict"] == []:
        decision["reason"] += ("; not testable with this campaign, so neither found nor ruled "
                               "out: " + ", ".join(sorted(untestable)))
    soil_values = fits["soil_only"].fit.values
    regions = residual_map(points, sim.predict(points, {}), sim.predict(points, soil_values),
                           sim.radius_m)
    if decision["verdict"] == "inconclusive":
        decision["admissible_tests"] = next_tests(
            sim, points, obs, hypotheses, fits, evidence, eta,
            float(np.sqrt(amplitudes[0] * amplitudes[-1])))
        decision["next_tests"] = decision["admissible_tests"][:TOP_TESTS]
    elif decision["verdict"] == OUTSIDE:
        decision["separating_test"] = largest_gap(regions)
    before = held_out(sim, fits["soil_only"].fit.candidate, points, sig, None,
                      settings.fold_nfev)
    after = (before if chosen.candidate.key == "soil_only" else
             held_out(sim, chosen.candidate, points, sig, None, settings.fold_nfev))
    predictions = {"simulation": sim.predict(points, {}), "soil_only": sim.predict(
        points, soil_values), decision["chosen"]: sim.predict(points, chosen.values)}
    return {
        "verdict": decision["verdict"], "decision": decision, "hypotheses": hypotheses,
        "effect_sets": by_effect_set(hypotheses),
        "effect_probabilities": by_effect(hypotheses, list(allowed), outside_effects),
        "untestable_effects": untestable, "contrasts": contrasts(points),
        "sibling_contrasts": sibling_contrasts(points, sig, predictions),
        "folds": [name for name, _ in folds(points)],
        "shrink": shrink(sim, points, before, after, settings.n_boot, settings.seed),
        "regions": regions, "noise": _noise_source(points), "base_model": base_model,
        "points": _curves(points, sig, predictions),
        "n_points": len(points), "quantities": quantities_of(points),
        "sinkage_relative": bool(points.attrs.get("sinkage_relative", False)),
    }


def _curves(points: pd.DataFrame, sig: dict[str, np.ndarray],
            predictions: dict[str, dict[str, np.ndarray]]) -> list[dict]:
    """Per measured point: its source and conditions, each quantity's value and noise, and
    each prediction (the simulation as given, after soil recalibration, after the chosen
    hypothesis) for the page's curves."""
    source = points["source"] if "source" in points else [points.attrs.get("source", "")] * len(
        points)
    rows = []
    for i in range(len(points)):
        row = {"source": str(source[i]), "load_n": float(points["load_set_n"].iloc[i]),
               "multipass": int(points["multipass"].iloc[i]),
               "gravity_mps2": float(points["gravity_mps2"].iloc[i]),
               "slip": float(points["slip"].iloc[i])}
        for q in quantities_of(points):
            value = float(points[q].iloc[i])
            if np.isfinite(value):
                row[q] = {"measured": value, "sigma": float(sig[q][i]),
                          **{name: float(pred[q][i]) for name, pred in predictions.items()}}
        rows.append(row)
    return rows


def _discrepancy_text(points: pd.DataFrame, sim: Simulated, e: Evidence) -> str:
    """What the chosen hypothesis leaves to the base model's discrepancy, in newtons of
    drawbar pull at the mean load (posterior mean amplitude times the floor)."""
    load = float(points["wheel_load_n"].mean())
    newtons = e.tau_mean * float(model_error_floor("dp_n", np.array([load]), sim.radius_m)[0])
    text = (f"; it leaves a smooth base-model discrepancy of about {newtons:.2g} N of drawbar "
            f"pull at {load:.0f} N ({e.tau_mean:.2g} times the repeatability floor)")
    if e.tau_weights[-1] > 0.5:
        text += (", at the top of the discrepancy's prior range: the simulation misses the "
                 "measurements by more than the base-model error the diagnosis allows for")
    return text


def _noise_source(points: pd.DataFrame) -> dict[str, str]:
    """Per quantity, where its noise comes from: measured replicates or the assumed floor."""
    out = {}
    for q in quantities_of(points):
        col = f"{q}_repeat_sd"
        measured = col in points and np.isfinite(points[col].to_numpy(float)).any()
        out[q] = ("measured: the spread of replicate runs" if measured else
                  "assumed: nothing measured the repeatability, so the floor of "
                  "sim_gap.vocabulary.model_error_floor is used")
    return out


def _hypothesis(key: str, c: cands.Candidate | None, f: MapFit, e: Evidence, prior: float,
                probability: float) -> dict:
    """One hypothesis of the report: candidate ``c`` (None: outside the candidates) with the
    fit ``f`` its evidence rests on."""
    outside = key == OUTSIDE
    return {"key": key, "label": OUTSIDE if outside else c.label,
            "effects": [] if outside else list(c.effects),
            "laws": {} if outside else dict(zip(c.effects, c.laws)),
            "n_params": f.fit.n_params, "log_evidence": e.log_evidence, "prior": prior,
            "probability": probability, "discrepancy_tau": e.tau_mean,
            "chi2": f.fit.chi2, "parameters": strengths(f.fit.values)}
