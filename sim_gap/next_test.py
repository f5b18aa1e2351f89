"""The next test of an inconclusive diagnosis, chosen by its expected information gain about
which hypothesis (effect set) is right (Bayesian experimental design: Lindley 1956, "On a
measure of the information provided by an experiment", Ann. Math. Stat. 27:986-1005;
Chaloner & Verdinelli 1995, "Bayesian experimental design: a review", Statistical Science
10:273-304).

For a proposed test with outcome ``y`` (every quantity the campaign measures, at the test's
conditions) and the effect-set label ``H``::

    EIG = I(H; y) = H[y] - sum_h p(h) H[y | h]

Each hypothesis' predictive of ``y`` given the campaign is Gaussian, in the linearised model
of :mod:`sim_gap.evidence` at its MAP ``u*``:

- mean: the MAP prediction at the new conditions (``Simulated.predict``) plus the shared
  discrepancy's posterior mean there, given the MAP residuals of the campaign (the
  Kennedy & O'Hagan GP at the hypothesis' posterior-mean amplitude);
- covariance: ``J S_post J^T`` (the parameters' Laplace posterior, ``S_post = (S^-1 +
  J_o^T A^-1 J_o)^-1``, carried through a finite-difference Jacobian ``J`` at the MAP) + the
  noise and the nugget (its posterior RMS size) + each new run's own soil (the run soil's
  posterior RMS scatter through the soil columns of ``J``) + the discrepancy's posterior
  covariance.
  A free-form level effect and "outside the candidates" carry their discrepancy apart per
  level (the middle of its amplitude grid): known where the campaign ran that level, fresh
  at a level (a wheel, a pass, a gravity) it has not run. A multipass or gravity level the
  campaign has not run makes that factor's effect a hypothesis (it needs two levels), and
  that effect could carry whatever the new level shows: every hypothesis gets the fresh
  discrepancy apart there, so a new level tells the hypotheses apart only by what they
  predict there beyond it (not by the mere fact that something changes).

``p(y | H)`` is the mixture of the laws of ``H`` (their posterior weights); ``H[y]`` and
``H[y | H]`` are estimated by Monte Carlo over the mixture, :data:`DRAWS` draws per
hypothesis from a fixed seed (stratified: ``sum_h p(h) E_{y ~ h}[log p(y | H_h) - log
p(y)]``). Each draw's term is at most ``-log p(H_h)``, so the estimate never exceeds the
entropy of the labels' posterior, ``<= log2(number of labels)`` bits.

The diagnosis reads its evidence at a learning rate ``eta = 1/phi`` (quasi-likelihood,
:func:`sim_gap.decide.learning_rate`); a Gaussian likelihood to the power ``eta`` is one of
covariance ``C / eta``, so the new runs are read the same way: a campaign whose held-out runs
scatter ``sqrt(phi)`` times wider than its model says expects less from any test.

Only the leading hypotheses that together hold :data:`POSTERIOR_COVERED` of the posterior
enter (renormalised). The noise of a new run is the campaign's: per quantity, the median
ratio of the points' noise (:func:`sim_gap.fit.sigmas`: measured repeatability where there
are replicates) to the repeatability floor (:func:`sim_gap.vocabulary.model_error_floor`),
times the floor at the new conditions. A test's outcome is what the campaign measures, less
the motion resistance where drawbar pull and torque are measured (it is computed from them:
:func:`sim_gap.fit.independent_entries`) and a relative sinkage (its unknown zero is left out
of the predictive: the test then gains from forces and torque only).

The tests a lab can run, never at a condition the campaign already has (same wheel, set load
within :data:`LOAD_TOLERANCE`, multipass, gravity, slip within :data:`SLIP_TOLERANCE`)
except the replicates, which repeat measured conditions by design: a set load below, above
and between the tested ones; slips in the braked, low and high bands at the tested loads;
replicates where the leading hypotheses differ most; a smooth wheel on the same soil for a
lugged one; a second multipass level; a second gravity level. A plate-sinkage test is not
proposed: the fitted soil moduli are the wheel model's effective ones (they absorb its
error), so the model has no prediction of a plate's pressure-sinkage curve to compare, and
the campaign does not measure a plate's noise.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pandas as pd
from scipy.linalg import cho_solve, cholesky, solve_triangular
from scipy.special import logsumexp

from sim_gap.candidates import LEVEL_FACTOR, is_free_form, level_labels
from sim_gap.decide import set_label
from sim_gap.evidence import OFFSET_PRIOR_SD_M, Evidence, Observations, cross_kernel
from sim_gap.fit import (MapFit, independent_quantities, internal_bounds, quantities_of,
                         sigmas, to_values)
from sim_gap.hypotheses import OUTSIDE, param_prior
from sim_gap.points_csv import WHEEL_KEY
from sim_gap.simulated import Simulated
from sim_gap.vocabulary import model_error_floor
from swtlab_base.domain.gravity import MARS_GRAVITY_MPS2, MOON_GRAVITY_MPS2

#: posterior mass of the hypotheses entered in the mixture (the rest is left out)
POSTERIOR_COVERED = 0.99
#: Monte Carlo draws per hypothesis (the ranking of the tests is stable to a few 0.01 bit)
DRAWS = 400
SEED = 0
#: tests the page states
TOP_TESTS = 3
#: a proposed slip this close to a measured one (same wheel, load and levels) is that condition
SLIP_TOLERANCE = 0.02
#: a proposed set load within this fraction of a tested one is that load
LOAD_TOLERANCE = 0.05
#: slips proposed in each band
BAND_SLIPS = {"braked": (-0.4, -0.2, -0.1), "low": (0.03, 0.08, 0.15),
              "high": (0.6, 0.75, 0.9)}
#: slips run at a new load or level (where the driving curve bends)
LEVEL_SLIPS = (0.05, 0.2, 0.4, 0.7)
#: a load proposed below / above the tested ones (factors) and between two that differ by
#: more than this ratio
LOAD_BELOW, LOAD_ABOVE, LOAD_GAP_RATIO = 0.6, 1.5, 1.5
#: replicate runs: this many conditions, each run twice more
REPLICATE_CONDITIONS, REPLICATE_RUNS = 3, 2
#: gravity levels proposed when a campaign has one
PROPOSED_GRAVITY_MPS2 = (MARS_GRAVITY_MPS2, MOON_GRAVITY_MPS2)
#: factors whose effect becomes a hypothesis once a campaign has two of their levels
NEW_LEVEL_FACTORS = ("multipass", "gravity_mps2")
#: finite-difference step of the Jacobian, in units of each parameter's internal range
JACOBIAN_STEP = 1e-3


def _wheels(points: pd.DataFrame) -> pd.DataFrame:
    """One row per measured source: its name and wheel columns (when the points have them;
    points without sources are one, named "" as :func:`_levels` names it)."""
    cols = ["source"] + [c for c in WHEEL_KEY if c in points]
    if "source" not in points:
        return pd.DataFrame({"source": [""]})
    return points[cols].drop_duplicates("source").reset_index(drop=True)


def _grid(wheels: pd.DataFrame, loads, slips, multipass: int, gravity: float) -> pd.DataFrame:
    w, s = np.meshgrid(np.asarray(loads, float), np.asarray(slips, float), indexing="ij")
    grid = pd.DataFrame({"load_set_n": w.ravel(), "wheel_load_n": w.ravel(),
                         "slip": s.ravel(), "multipass": multipass, "gravity_mps2": gravity})
    return grid.merge(wheels, how="cross")


def _base_level(points: pd.DataFrame) -> tuple[int, float]:
    """The campaign's reference multipass and gravity levels (those of most points)."""
    return (int(points["multipass"].mode().iloc[0]),
            float(points["gravity_mps2"].round(6).mode().iloc[0]))


def _runs_text(grid: pd.DataFrame) -> str:
    return f"{len(grid)} run{'s' if len(grid) != 1 else ''}"


def _slips_text(slips) -> str:
    return ", ".join(f"{s:g}" for s in slips)


def _loads_text(loads) -> str:
    """``80 N``, ``56 and 186 N``, ``56, 120 and 186 N``."""
    names = [f"{w:.0f}" for w in loads]
    return (", ".join(names[:-1]) + " and " if len(names) > 1 else "") + names[-1] + " N"


def candidate_tests(points: pd.DataFrame, grousered: bool) -> list[dict]:
    """The tests a lab can run after this campaign: ``{kind, test, points}`` (the test in
    plain words, the conditions as points without measurements). ``grousered``: the
    campaign's wheel has lugs (a smooth wheel on the same soil is then a test). Conditions
    the campaign already has are removed, except from the replicates."""
    wheels = _wheels(points)
    mp, g = _base_level(points)
    loads = np.unique(points["load_set_n"].round(6))
    level_loads = loads[[0, -1]] if loads.size > 1 else loads
    out = []

    each = f" on each of the {len(wheels)} measured wheels" if len(wheels) > 1 else ""

    def add(kind, text, grid):
        grid = new_conditions(points, grid)
        if len(grid):
            where = "" if kind == "smooth wheel" else each
            out.append({"kind": kind, "test": f"{text}{where} ({_runs_text(grid)})",
                        "points": grid})

    below, above = round(LOAD_BELOW * loads[0]), round(LOAD_ABOVE * loads[-1])
    add("load", f"a set load of {below:.0f} N, below the tested ones, at slips "
        f"{_slips_text(LEVEL_SLIPS)}", _grid(wheels, [below], LEVEL_SLIPS, mp, g))
    add("load", f"a set load of {above:.0f} N, above the tested ones, at slips "
        f"{_slips_text(LEVEL_SLIPS)}", _grid(wheels, [above], LEVEL_SLIPS, mp, g))
    if loads.size > 1:
        ratios = loads[1:] / loads[:-1]
        i = int(np.argmax(ratios))
        if ratios[i] > LOAD_GAP_RATIO:
            between = round(float(np.sqrt(loads[i] * loads[i + 1])))
            add("load", f"a set load of {between:.0f} N, between {loads[i]:.0f} N and "
                f"{loads[i + 1]:.0f} N, at slips {_slips_text(LEVEL_SLIPS)}",
                _grid(wheels, [between], LEVEL_SLIPS, mp, g))
    for band, slips in BAND_SLIPS.items():
        what = {"braked": "braked (skid) slips", "low": "low slips",
                "high": "high slips"}[band]
        add("slips", f"{what} {_slips_text(slips)} at the tested loads "
            f"({_loads_text(loads)})", _grid(wheels, loads, slips, mp, g))
    if grousered and not (wheels.get("grouser_count", pd.Series([1])) == 0).any():
        smooth = wheels.assign(source="smooth wheel", grouser_count=0, grouser_height_m=0.0)
        add("smooth wheel", f"a smooth wheel (same rim, no grousers) on the same soil at "
            f"{_loads_text(level_loads)}, slips {_slips_text(LEVEL_SLIPS)}",
            _grid(smooth, level_loads, LEVEL_SLIPS, mp, g))
    if points["multipass"].nunique() == 1:
        add("multipass", f"a second pass in the same rut (multipass {mp + 1}) at "
            f"{_loads_text(level_loads)}, slips {_slips_text(LEVEL_SLIPS)}",
            _grid(wheels, level_loads, LEVEL_SLIPS, mp + 1, g))
    if points["gravity_mps2"].round(6).nunique() == 1:
        other = next(x for x in PROPOSED_GRAVITY_MPS2 if abs(x - g) > 0.05)
        add("gravity", f"another gravity level ({other:g} m/s^2: a gravity-offload rig or "
            f"a parabolic flight) at {_loads_text(level_loads)}, slips "
            f"{_slips_text(LEVEL_SLIPS)}", _grid(wheels, level_loads, LEVEL_SLIPS, mp, other))
    return out


def _condition_keys(frame: pd.DataFrame, cols: list[str]) -> pd.DataFrame:
    keys = frame[cols].copy()
    keys["gravity"] = frame["gravity_mps2"].round(3)
    return keys


def new_conditions(points: pd.DataFrame, grid: pd.DataFrame) -> pd.DataFrame:
    """The rows of ``grid`` whose condition the campaign does not have: no measured point of
    the same source and wheel, multipass and gravity level with a set load within
    :data:`LOAD_TOLERANCE` and a slip within :data:`SLIP_TOLERANCE`."""
    cols = [c for c in ("source", "multipass", *WHEEL_KEY) if c in points and c in grid]
    old_keys, new_keys = _condition_keys(points, cols), _condition_keys(grid, cols)
    old_load = points["load_set_n"].to_numpy(float)
    old_slip = points["slip"].to_numpy(float)
    keep = []
    for i in range(len(grid)):
        same = (old_keys == new_keys.iloc[i]).all(axis=1).to_numpy()
        near = (same & (np.abs(old_load / grid["load_set_n"].iloc[i] - 1) <= LOAD_TOLERANCE)
                & (np.abs(old_slip - grid["slip"].iloc[i]) <= SLIP_TOLERANCE))
        keep.append(not near.any())
    return grid[np.array(keep, bool)].reset_index(drop=True)


def _replicates(points: pd.DataFrame, spread: np.ndarray) -> dict | None:
    """Replicates at the :data:`REPLICATE_CONDITIONS` measured conditions (distinct: slip to
    0.01) where the leading hypotheses' predictions spread most (``spread``: per point, in
    noise units)."""
    cols = (["source"] if "source" in points else []) + [
        "load_set_n", "wheel_load_n", "slip", "multipass", "gravity_mps2"] + [
        c for c in WHEEL_KEY if c in points]
    order = np.argsort(-np.nan_to_num(spread, nan=-1.0))
    ranked = points.iloc[order][cols]
    same = ranked.assign(slip=ranked["slip"].round(2), gravity_mps2=ranked["gravity_mps2"].round(3))
    key = [c for c in same if c != "wheel_load_n"]  # the measured load differs run to run
    chosen = ranked[~same.duplicated(key)].iloc[:REPLICATE_CONDITIONS]
    if chosen.empty:
        return None
    grid = pd.concat([chosen] * REPLICATE_RUNS, ignore_index=True)
    named = "source" in points and points["source"].nunique() > 1
    passes = points["multipass"].nunique() > 1
    gravities = points["gravity_mps2"].round(4).nunique() > 1
    where = "; ".join((f"{r.source}: " if named else "") + f"{r.load_set_n:.0f} N, slip "
                      f"{r.slip:.2g}" + (f", multipass {r.multipass}" if passes else "")
                      + (f", {r.gravity_mps2:.3g} m/s^2" if gravities else "")
                      for r in chosen.itertuples())
    return {"kind": "replicates", "test": f"repeat the measured conditions {where}, "
            f"{REPLICATE_RUNS} more runs each ({_runs_text(grid)})", "points": grid}


def _noise_ratio(points: pd.DataFrame, radius_m: float) -> dict[str, float]:
    """Per quantity, the campaign's noise in units of the repeatability floor (median)."""
    sig = sigmas(points, radius_m)
    load = points["wheel_load_n"].to_numpy(float)
    out = {}
    for q, s in sig.items():
        measured = np.isfinite(points[q].to_numpy(float))
        ratio = s[measured] / model_error_floor(q, load[measured], radius_m)
        out[q] = float(np.nanmedian(ratio)) if ratio.size else 1.0
    return out


def _entries(grid: pd.DataFrame, quantities: list[str], radius_m: float
             ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Flat entries of a test's outcome (row-major over points x quantities): point index,
    quantity index, floor."""
    load = grid["wheel_load_n"].to_numpy(float)
    point, qi = np.divmod(np.arange(len(grid) * len(quantities)), len(quantities))
    floor = np.column_stack([model_error_floor(q, load, radius_m) for q in quantities]).ravel()
    return point, qi, floor


def _flat(pred: dict[str, np.ndarray], quantities: list[str]) -> np.ndarray:
    return np.column_stack([pred[q] for q in quantities]).ravel()


class _Hypothesis:
    """What the predictive of one hypothesis needs from the campaign: its MAP fit, the
    parameters' posterior covariance and the discrepancy's data (factored once)."""

    def __init__(self, sim: Simulated, points: pd.DataFrame, obs: Observations, f: MapFit,
                 e: Evidence, apart_by: str | None, apart_sd: float) -> None:
        self.f, self.apart_by, self.apart_sd = f, apart_by, apart_sd
        self.tau, self.nugget = e.tau_mean, e.nugget_rms
        self.groups = _levels(points, apart_by)[obs.point] if apart_by else None
        c = f.fit.candidate
        _, sd = param_prior(c, sim.model)
        soil = np.array([p.name.startswith("soil.") for p in c.params])
        # a new run's own soil (:func:`sim_gap.evidence.run_soil`): columns and spreads
        self.soil, self.soil_sd = soil, e.run_soil_rms * sd[soil]
        a = (np.diag(obs.sigma ** 2 + (self.nugget * obs.floor) ** 2)
             + OFFSET_PRIOR_SD_M ** 2 * obs.offsets @ obs.offsets.T
             + self.tau ** 2 * obs.kernel_shared)
        if obs.kernel_run is not None:
            a += e.run_soil_rms ** 2 * obs.kernel_run
        if apart_by:
            a += self.apart_sd ** 2 * np.where(self.groups[:, None] == self.groups[None, :],
                                               obs.kernel_shared, 0.0)
        self.lower = cholesky(a, lower=True, check_finite=False)
        xj = solve_triangular(self.lower, f.jac, lower=True, check_finite=False)
        precision = np.diag(1.0 / sd ** 2) + xj.T @ xj
        self.s_post = cho_solve((cholesky(precision, lower=True), True), np.eye(sd.size))
        residual = np.nan_to_num(obs.y - f.predicted)
        self.alpha = cho_solve((self.lower, True), residual, check_finite=False)
        self.lo, self.hi = internal_bounds(c)


def _prediction(sim: Simulated, h: _Hypothesis, grid: pd.DataFrame, quantities: list[str]
                ) -> tuple[np.ndarray, np.ndarray]:
    """The MAP prediction (flat) at ``grid`` and its finite-difference Jacobian."""
    c, u = h.f.fit.candidate, h.f.internal
    predict = sim.predictor(grid)
    mean = _flat(predict(to_values(c, u)), quantities)
    jac = np.zeros((mean.size, u.size))
    for i in range(u.size):
        step = JACOBIAN_STEP * (h.hi[i] - h.lo[i])
        step = -step if u[i] + step > h.hi[i] else step
        v = u.copy()
        v[i] += step
        jac[:, i] = (_flat(predict(to_values(c, v)), quantities) - mean) / step
    return mean, jac


def predictive(radius_m: float, points: pd.DataFrame, obs: Observations, h: _Hypothesis,
               grid: pd.DataFrame, prediction: tuple[np.ndarray, np.ndarray],
               quantities: list[str], noise_ratio: dict[str, float]
               ) -> tuple[np.ndarray, np.ndarray]:
    """Mean and covariance of a test's outcome (flat) under one hypothesis (module
    docstring), from its MAP ``prediction`` at ``grid`` and Jacobian (:func:`_prediction`)."""
    mean, jac = prediction
    point, qi, floor = _entries(grid, quantities, radius_m)
    noise = floor * np.hypot(np.array([noise_ratio[q] for q in quantities])[qi], h.nugget)
    new = (grid["slip"].to_numpy(float)[point], grid["wheel_load_n"].to_numpy(float)[point],
           qi, floor)
    old_slip = points["slip"].to_numpy(float)[obs.point]
    old_load = points["wheel_load_n"].to_numpy(float)[obs.point]
    old_q = np.array([quantities.index(q) if q in quantities else -1
                      for q in quantities_of(points)])[obs.quantity]
    k_nn = cross_kernel(new, new)
    k_no = cross_kernel(new, (old_slip, old_load, old_q, obs.floor))
    if h.apart_by is not None:  # plus the discrepancy apart per level (a new level: fresh)
        levels = _levels(grid, h.apart_by)[point]
        k_nn = k_nn * (h.tau ** 2 + h.apart_sd ** 2 * (levels[:, None] == levels[None, :]))
        k_no = k_no * (h.tau ** 2 + h.apart_sd ** 2 * (levels[:, None] == h.groups[None, :]))
    else:
        k_nn, k_no = h.tau ** 2 * k_nn, h.tau ** 2 * k_no
    w = solve_triangular(h.lower, k_no.T, lower=True, check_finite=False)
    cov = jac @ h.s_post @ jac.T + np.diag(noise ** 2) + k_nn - w.T @ w
    run_soil = jac[:, h.soil] * h.soil_sd
    cov += np.where(point[:, None] == point[None, :], run_soil @ run_soil.T, 0.0)
    mean = mean + k_no @ h.alpha
    for factor in NEW_LEVEL_FACTORS:  # a level not run: its effect can carry anything there
        if h.apart_by == factor:  # its own discrepancy apart is fresh there already
            continue
        old = set(_levels(points, factor))
        levels = _levels(grid, factor)[point]
        fresh = np.array([x not in old for x in levels])
        same = (levels[:, None] == levels[None, :]) & fresh[:, None] & fresh[None, :]
        cov = cov + h.apart_sd ** 2 * np.where(same, cross_kernel(new, new), 0.0)
    return mean, 0.5 * (cov + cov.T)


def _levels(frame: pd.DataFrame, by: str) -> np.ndarray:
    """Per row, its level of the factor ``by`` (a column; the source for "outside the
    candidates": an unknown effect seen on a source is expected to persist at that source's
    new multipass or gravity levels, where the factor's own effect may add to it; the
    evidence groups by source and level, :func:`sim_gap.evidence.observations`)."""
    return level_labels(frame, "source" if by == OUTSIDE else by)


def information_gain(means: list[np.ndarray], covs: list[np.ndarray], weights: np.ndarray,
                     labels: list[str], draws: int = DRAWS, seed: int = SEED) -> float:
    """``I(label; y)`` in bits for the Gaussian mixture ``sum_k weights_k N(means_k,
    covs_k)`` whose components carry ``labels``: stratified Monte Carlo, ``draws`` per
    component (module docstring)."""
    weights = np.asarray(weights, float) / np.sum(weights)
    rng = np.random.default_rng(seed)
    scale = np.sqrt(np.mean([np.diag(c) for c in covs], axis=0))  # units cancel in I(H; y)
    means = [m / scale for m in means]
    covs = [c / np.outer(scale, scale) for c in covs]
    factors = [cholesky(c + 1e-10 * np.eye(len(c)), lower=True) for c in covs]
    names = sorted(set(labels))
    label_of = np.array([names.index(x) for x in labels])
    label_weight = np.array([weights[label_of == j].sum() for j in range(len(names))])
    total = 0.0
    for k, (m, lk) in enumerate(zip(means, factors)):
        y = m + rng.standard_normal((draws, m.size)) @ lk.T
        log_pk = np.column_stack([_log_normal(y, mj, lj) for mj, lj in zip(means, factors)])
        log_joint = log_pk + np.log(weights)
        log_marginal = logsumexp(log_joint, axis=1)
        mine = label_of == label_of[k]
        log_given_label = logsumexp(log_joint[:, mine], axis=1) - np.log(
            label_weight[label_of[k]])
        total += weights[k] * float(np.mean(log_given_label - log_marginal))
    return max(total, 0.0) / np.log(2.0)


def _log_normal(y: np.ndarray, mean: np.ndarray, lower: np.ndarray) -> np.ndarray:
    z = solve_triangular(lower, (y - mean).T, lower=True, check_finite=False)
    return (-0.5 * np.sum(z ** 2, axis=0) - np.sum(np.log(np.diag(lower)))
            - 0.5 * mean.size * np.log(2.0 * np.pi))


def leading(hypotheses: list[dict], covered: float = POSTERIOR_COVERED) -> list[dict]:
    """The most probable hypotheses that together hold ``covered`` of the posterior."""
    ranked = sorted(hypotheses, key=lambda h: -h["probability"])
    cumulative = np.cumsum([h["probability"] for h in ranked])
    n = int(np.searchsorted(cumulative, covered * cumulative[-1])) + 1
    return ranked[:n]


def _apart(h: dict) -> str | None:
    """What the discrepancy apart per level of a free-form level effect or of "outside the
    candidates" goes by (None for the other hypotheses)."""
    if h["key"] == OUTSIDE:
        return OUTSIDE
    free = [e for e, law in h["laws"].items() if is_free_form(law)]
    return LEVEL_FACTOR[free[0]] if free else None


def next_tests(sim: Simulated, points: pd.DataFrame, obs: Observations,
               hypotheses: list[dict], fits: dict[str, MapFit], evidence: dict[str, Evidence],
               eta: float, apart_sd: float) -> list[dict]:
    """The tests of :func:`candidate_tests` (and the replicates) by expected information gain
    about the effect set: ``{kind, test, gain_bits, n_runs, conditions}``, largest gain
    first. ``hypotheses``: the report's (``key``, ``laws``, ``effects``, ``probability``);
    ``fits``: each named key's MAP fit (a free form: its base fit); ``evidence``: each key's
    (the discrepancy's and the nugget's posterior sizes); ``eta``: the diagnosis' learning
    rate (:func:`sim_gap.decide.learning_rate`); ``apart_sd``: the amplitude (floor units) of
    a discrepancy apart per level, for the free forms and "outside the candidates"."""
    lead = leading(hypotheses)
    if len({_label(h) for h in lead}) < 2:
        return []
    quantities = [q for q in quantities_of(points)
                  if not (q == "sinkage_m" and points.attrs.get("sinkage_relative"))]
    quantities = independent_quantities(quantities)
    ratio = _noise_ratio(points, sim.radius_m)
    models = [_Hypothesis(sim, points, obs, fits.get(h["key"], fits["soil_only"]),
                          evidence[h["key"]], _apart(h), apart_sd) for h in lead]
    weights = np.array([h["probability"] for h in lead])
    labels = [_label(h) for h in lead]
    grousered = _grousered(sim, points) and (sim.wheel_per_row or not sim.external)
    new_sim = sim if sim.external or sim.wheel_per_row else _per_row(sim)
    tests = candidate_tests(points, grousered)
    spread = _spread(sim, points, models, quantities, ratio)
    if (rep := _replicates(points, spread)) is not None:
        tests.append(rep)
    grids = [_with_wheel(sim, t["points"]) for t in tests]
    at = _predictions(new_sim, models, grids, quantities)
    out = []
    for t, grid, first in zip(tests, grids, at):
        if first is None:  # a tabulated simulation that does not reach these conditions
            continue
        pred = [predictive(sim.radius_m, points, obs, m, grid, f, quantities, ratio)
                for m, f in zip(models, first)]
        if not all(np.all(np.isfinite(m)) for m, _ in pred):
            continue
        gain = information_gain([m for m, _ in pred], [c / eta for _, c in pred], weights,
                                labels)
        out.append({"kind": t["kind"], "test": t["test"], "gain_bits": round(gain, 3),
                    "n_runs": len(grid), "conditions": _conditions(t["points"])})
    return sorted(out, key=lambda t: -t["gain_bits"])


def _predictions(sim: Simulated, models: list[_Hypothesis], grids: list[pd.DataFrame],
                 quantities: list[str]) -> list[list | None]:
    """Per test, each hypothesis' MAP prediction and Jacobian (:func:`_prediction`), all
    tests in one evaluation per parameter step; test by test (None where the simulation
    does not reach it) when a tabulated simulation refuses the whole."""
    try:
        whole = [_prediction(sim, m, pd.concat(grids, ignore_index=True), quantities)
                 for m in models]
    except ValueError:
        out = []
        for grid in grids:
            try:
                out.append([_prediction(sim, m, grid, quantities) for m in models])
            except ValueError:
                out.append(None)
        return out
    edges = np.cumsum([0] + [len(g) * len(quantities) for g in grids])
    return [[(mean[a:b], jac[a:b]) for mean, jac in whole]
            for a, b in zip(edges[:-1], edges[1:])]


def _label(h: dict) -> str:
    return OUTSIDE if h["key"] == OUTSIDE else set_label(h["effects"])


def _grousered(sim: Simulated, points: pd.DataFrame) -> bool:
    if "grouser_count" in points:
        return bool(((points["grouser_count"] > 0) & (points["grouser_height_m"] > 0)).any())
    return sim.wheel.grouser_count > 0 and sim.wheel.grouser_height_m > 0


def _per_row(sim: Simulated) -> Simulated:
    """``sim`` with each point on its own wheel (a smooth-wheel test beside the lugged)."""
    return replace(sim, wheel_per_row=True, _base_cache={})


def _with_wheel(sim: Simulated, grid: pd.DataFrame) -> pd.DataFrame:
    """``grid`` with the simulated wheel's columns where it lacks them."""
    w = sim.wheel
    own = dict(zip(WHEEL_KEY, (w.radius_m, w.width_m, w.grouser_count, w.grouser_height_m)))
    return grid.assign(**{k: v for k, v in own.items() if k not in grid})


def _spread(sim: Simulated, points: pd.DataFrame, models: list[_Hypothesis],
            quantities: list[str], ratio: dict[str, float]) -> np.ndarray:
    """Per measured point, the largest range of the hypotheses' MAP predictions over the
    quantities, in units of the campaign's noise."""
    load = points["wheel_load_n"].to_numpy(float)
    preds = [sim.predict(points, to_values(m.f.fit.candidate, m.f.internal)) for m in models]
    out = np.zeros(len(points))
    for q in quantities:
        stack = np.vstack([p[q] for p in preds])
        noise = ratio[q] * model_error_floor(q, load, sim.radius_m)
        out = np.fmax(out, np.ptp(stack, axis=0) / noise)
    return out


def _conditions(grid: pd.DataFrame) -> list[dict]:
    """A test's conditions as plain data (what a lab or the apart generator runs)."""
    cols = [c for c in ("source", "load_set_n", "slip", "multipass", "gravity_mps2",
                        *WHEEL_KEY) if c in grid]
    rows = grid[cols].to_dict("records")
    return [{k: (v.item() if hasattr(v, "item") else v) for k, v in r.items()} for r in rows]
