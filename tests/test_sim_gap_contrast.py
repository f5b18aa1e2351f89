"""The law-free check of a confident call on the design's level contrasts
(sim_gap.contrast_check): residuals with a known shift between twin runs, and model data
with a multipass that the call leaves out."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

import terramechanics as tm
from sim_gap import candidates
from sim_gap.contrast_check import contrast_problem, twin_differences
from sim_gap.fit import fit_candidate, sigmas, standardised_residuals
from sim_gap.simulated import Simulated

MARS = 3.71


def design(slip_jitter: float = 0.0, seed: int = 0) -> pd.DataFrame:
    """Two loads x four slips x multipass 0, 1 x gravity 9.81, 3.71 (32 runs)."""
    rng = np.random.default_rng(seed)
    grid = np.meshgrid([80.0, 250.0], [0.15, 0.3, 0.45, 0.6], [0, 1], [9.80665, MARS],
                       indexing="ij")
    load, slip, mp, g = (a.ravel() for a in grid)
    slip = slip + rng.uniform(-slip_jitter, slip_jitter, slip.size)
    points = pd.DataFrame({"source": "a", "load_set_n": load, "wheel_load_n": load,
                           "multipass": mp.astype(int), "gravity_mps2": g, "slip": slip})
    for q in ("dp_n", "torque_nm", "sinkage_m"):
        points[q], points[f"{q}_se"] = 0.0, 1.0
    return points


def residuals(points: pd.DataFrame, shift_sinkage: float, noise: float = 0.05,
              seed: int = 1) -> np.ndarray:
    """Noise, plus ``shift_sinkage`` sigmas on the sinkage of the multipass-1 runs."""
    r = np.random.default_rng(seed).normal(0.0, noise, (len(points), 3))
    r[points["multipass"].to_numpy() == 1, 2] += shift_sinkage
    return r


def test_twins_are_matched_on_everything_but_the_factor():
    points = design(slip_jitter=0.01)
    d = twin_differences(points, residuals(points, 1.0, noise=0.0), "multipass")
    np.testing.assert_allclose(d[1.0], np.tile([0.0, 0.0, 1.0], (16, 1)))
    g = twin_differences(points, residuals(points, 1.0, noise=0.0), "gravity_mps2")
    np.testing.assert_allclose(g[9.80665], 0.0)  # gravity twins share their multipass level


def test_a_shift_left_by_the_call_is_flagged_and_named():
    points = design()
    problem = contrast_problem(points, residuals(points, 1.0), ["reduced_gravity"])
    assert problem is not None
    assert "sinkage_m at multipass level 1" in problem and "+1.00 sigma" in problem
    assert "multipass" in problem.split("tied to the")[1]


@pytest.mark.parametrize("shift, effects", [
    (1.0, ["multipass"]),  # the call has the effect tied to that factor
    (0.0, []),  # no shift
    (0.1, []),  # consistent (z >> 4) but too small to change a conclusion
])
def test_no_flag_without_a_shift_that_matters_or_with_its_effect_called(shift, effects):
    points = design()
    assert contrast_problem(points, residuals(points, shift), effects) is None


def test_runs_without_a_twin_are_not_compared():
    points = design()
    points.loc[points["multipass"] == 1, "slip"] += 0.05  # no twin within 0.03 of slip
    assert twin_differences(points, residuals(points, 1.0), "multipass") == {}
    assert contrast_problem(points, residuals(points, 1.0), []) is None


BASE = tm.shipped_model("bb2_sand").with_effects(**{n: False for n in tm.EFFECTS})


def model_points(truth: tm.WheelModel, seed: int = 0) -> pd.DataFrame:
    """``truth`` at the design's conditions with noise of 0.3 % of the load (forces) and
    0.05 mm (sinkage)."""
    points = design()
    c = truth.curves(points["wheel_load_n"].to_numpy(), points["slip"].to_numpy(),
                     points["multipass"].to_numpy(), points["gravity_mps2"].to_numpy())
    rng = np.random.default_rng(seed)
    load = points["wheel_load_n"].to_numpy()
    for q, sd in {"dp_n": 0.003 * load, "torque_nm": 0.003 * load * 0.125,
                  "sinkage_m": np.full(load.shape, 5e-5)}.items():
        points[q] = c[q] + rng.normal(0.0, 1.0, load.size) * sd
        points[f"{q}_se"] = sd
    points.attrs.update(source="synthetic", wheel=truth.wheel, sinkage_relative=False)
    return points


@pytest.mark.parametrize("truth_effects, flagged", [
    ({"reduced_gravity": {"law": "wong_kobayashi2012", "bearing_exponent": 1.0},
      "multipass": {"law": "wong2010", "stiffness_gain_per_pass": 0.4}}, True),
    ({"reduced_gravity": {"law": "wong_kobayashi2012", "bearing_exponent": 1.0}}, False),
])
def test_reduced_gravity_called_alone_over_a_hidden_multipass(truth_effects, flagged):
    """The held-out bench's confident wrong call (seed 19 c003: Wong multipass + reduced
    gravity called reduced gravity): the reduced-gravity fit of such data leaves its
    residuals apart between the multipass levels; without the multipass it does not."""
    truth = BASE.with_soil(kphi=2.1e7).with_effects(**truth_effects)
    points = model_points(truth)
    sim = Simulated(BASE)
    sig = sigmas(points, sim.radius_m)
    call = candidates.candidate(BASE, ("reduced_gravity",), {"reduced_gravity": "reece1965"})
    fit = fit_candidate(sim, call, points, sig, max_nfev=40)
    r = standardised_residuals(points, sim.predict(points, fit.values), sig)
    problem = contrast_problem(points, r, ["reduced_gravity"])
    assert (problem is not None) == flagged
    if flagged:
        assert "multipass level 1" in problem
