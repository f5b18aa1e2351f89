"""eps_vol^P from the measured field (softflow.volumetric_strain) and alpha1/alpha2
(softflow.alpha12): closed-form fields, then frames rendered with a self-consistent k.

Tolerances are measured (docs/softflow.md, "alpha1 and alpha2"): on 7 renders like
these (seeds 11-41, 7 pairs, default engine) the worst eps error per bin was 0.029
and two runs pooled gave alpha1 within 8 % and alpha2 within 0.06 of the truth. That
strain (0.37-0.63) is not resolved to 0.01 by the estimate's own bound, so the analysis
gives no alpha1, alpha2 there (issue 21 item 3); a realistic 0.05 on an exact closed-form
field is, but a field measured from frames adds the flow engine's error (0.026, measured
on these renders), more than 0.01 alone.
"""

from __future__ import annotations

import dataclasses
import json

import numpy as np
import pytest

from softflow.alpha12 import fit_alpha12, fit_alpha12_across_runs
from softflow.field_analysis import analyse_frames
from softflow.flow_checks import EPS_RESOLUTION, eps_reason
from softflow.volumetric_strain import (accumulated_strain, local_linear_fit,
                                        smoothed_divergence, strain_by_beta)
from virtual_testbed.flow_render import BETA_GRID, FlowScene, render_flow

ALPHA1, ALPHA2 = 31.5, 0.3
U0 = 40.0  # px/s, soil coming from the right


def _compacting_flow(x: np.ndarray, y: np.ndarray,
                     strain: float = 0.4) -> tuple[np.ndarray, np.ndarray]:
    """Steady flow with a known strain: ``u = exp(-eps) curl psi`` conserves the mass
    ``exp(eps) u`` for any ``eps``; ``eps = 0`` upstream, wavy streamlines."""
    s = 0.5 * (1 - np.tanh((x - 190) / 15))
    ds = -0.5 / 15 / np.cosh((x - 190) / 15) ** 2
    eps = strain * s * (1 + 0.3 * np.sin(y / 25))
    dpsi_dx = U0 * 8 * (ds * np.sin(x / 20) + s * np.cos(x / 20) / 20)  # psi = -U0 (y - 8 s sin)
    return np.stack([-U0 * np.exp(-eps), -dpsi_dx * np.exp(-eps)], -1), eps


def test_plane_fit_is_exact_on_a_linear_field_next_to_a_mask():
    y, x = np.mgrid[0:60, 0:80].astype(float)
    field = np.stack([2 + 0.3 * x - 0.1 * y, -1 + 0.05 * x + 0.2 * y], -1)
    valid = np.hypot(x - 40, y - 30) > 15
    value, grad = local_linear_fit(field, valid)
    ring = valid & (np.hypot(x - 40, y - 30) < 18)
    assert np.allclose(value[ring], field[ring], atol=1e-9)
    assert np.allclose(grad[ring][:, 0], [0.3, -0.1]) and np.allclose(grad[ring][:, 1], [0.05, 0.2])


def test_strain_along_streamlines_matches_closed_form():
    y, x = np.mgrid[0:240, 0:320].astype(float)
    u, _ = _compacting_flow(x, y)
    u[np.hypot(x - 60, y - 120) < 30] = np.nan  # a hole, like the wheel mask
    points = np.array([[110, 60], [110, 180], [130, 120], [20, 60], [150, 200], [40, 120]])
    _, truth = _compacting_flow(points[:, 0], points[:, 1])
    v, div = smoothed_divergence(u)
    eps, left = accumulated_strain(v, div, points, np.array([-U0, 0.0]))
    # smoothing bias measured 0.003 (sigma 5 px); the last point's path ends on the hole
    assert np.abs(eps[:-1] - truth[:-1]).max() < 0.006 and np.isnan(eps[-1])
    # paths end near x = 312, where 1 - tanh((312 - 190) / 15) leaves 0.4 * 1e-7 of strain
    assert np.all(left[:-1] < 1e-6) and np.isnan(left[-1])
    assert np.all(np.isnan(accumulated_strain(v, div, points, np.array([-1.05 * U0, 0.0]))[0]))
    keep_out = x > 300  # every path has to cross it
    assert np.all(np.isnan(accumulated_strain(v, div, points, np.array([-U0, 0.0]),
                                              keep_out)[0]))


@pytest.mark.parametrize("strain, resolved", [(0.05, 10), (0.4, 1)])
def test_strain_bound_resolves_realistic_strain(strain, resolved):
    """Bins right of a hole (the wheel), 60 px from its centre: the bound covers the error
    against the closed form, and is within 0.01 at a realistic strain (measured bound
    0.0011-0.0025 at 0.05, 0.009-0.020 at 0.4: mostly the strain's spread across a bin)."""
    y, x = np.mgrid[0:240, 0:320].astype(float)
    u, _ = _compacting_flow(x, y, strain)
    u[np.hypot(x - 60, y - 120) < 30] = np.nan
    beta = np.deg2rad(np.arange(-45.0, 50.0, 10.0))
    eps, bound = strain_by_beta(u, (60.0, 120.0), 60.0, beta, np.deg2rad(10),
                                np.array([-U0, 0.0]))
    _, truth = _compacting_flow(60 + 60 * np.cos(beta), 120 - 60 * np.sin(beta), strain)
    assert np.all(np.abs(eps - truth) <= bound)
    reasons = [eps_reason(e, b) for e, b in zip(eps, bound)]
    assert sum(r is None for r in reasons) == resolved
    assert all(r.startswith("not resolvable") for r in reasons if r)


def test_alpha12_regression():
    eps = np.linspace(0.1, 0.6, 8)
    k = ALPHA1 / (eps + ALPHA2)
    fit = fit_alpha12(eps, k, 0.01 * k)
    assert fit["alpha1_per_m"] == pytest.approx(ALPHA1) and fit["alpha2"] == pytest.approx(ALPHA2)
    noisy = k * (1 + 0.01 * np.random.default_rng(1).standard_normal(8))
    fit = fit_alpha12(eps, noisy, 0.01 * k)
    assert fit["alpha1_ci95_per_m"][0] < ALPHA1 < fit["alpha1_ci95_per_m"][1]
    assert fit["alpha2_ci95"][0] < ALPHA2 < fit["alpha2_ci95"][1]
    assert fit_alpha12(eps[:2], k[:2], k[:2]) is None


@pytest.fixture(scope="module")
def runs():
    """Slip 0.2 and 0.6 with the same alpha1, alpha2: eps 0.50-0.63 and 0.37-0.62."""
    out = []
    for seed, slip in ((11, 0.2), (12, 0.6)):
        scene = FlowScene(alpha1_per_m=ALPHA1, alpha2=ALPHA2, seed=seed, slip=slip,
                          size_px=(512, 400), supersample=3)
        render = render_flow(scene, 8)
        result = analyse_frames(render.frames, render.t_s, scene.px_per_m,
                                wheel_radius_px=scene.wheel_radius_px)
        out.append((render, result))
    return out


def _truth_eps(render, beta):
    table = np.array([np.nan if e is None else e for e in render.truth["eps_vol_p"]])
    return np.interp(beta, BETA_GRID, np.nan_to_num(table, nan=-9.0))


@pytest.mark.slow  # the strain runs' frames rendered and their flow measured (module fixture)
@pytest.mark.slow_render
def test_renderer_truth_is_self_consistent_and_independent(runs):
    render, result = runs[0]
    truth = render.truth
    eps = np.array([np.nan if e is None else e for e in truth["eps_vol_p"]])
    k = np.array(render.scene.radial_decay_per_m)
    below = BETA_GRID <= 0
    assert truth["alpha1_per_m"] == ALPHA1 and truth["eps_depth_px"] == pytest.approx(20.0)
    assert np.allclose(k[below], ALPHA1 / (eps[below] + ALPHA2), rtol=1e-5)
    # the estimator's numerics on the exact displacement field agree with the renderer's
    # own (RK4 on the closed-form divergence): 0.008 is the sigma-5 smoothing bias
    exact = np.where(render.soil_mask[0][..., None], render.displacement_px[0], np.nan)
    beta = result.beta_rad[np.isfinite(result.eps_vol_p)]
    est, bound = strain_by_beta(exact * render.scene.fps, render.scene.wheel_center_px, 120.0,
                                beta, np.deg2rad(10),
                                np.array([-render.scene.velocity_mps * 1000, 0.0]))
    err = np.abs(est - _truth_eps(render, beta))
    assert err.max() < 0.015  # measured 0.010
    assert np.all(err <= bound) and np.all(bound > EPS_RESOLUTION)  # measured 0.027-0.038


@pytest.mark.slow  # the strain runs' frames rendered and their flow measured (module fixture)
@pytest.mark.slow_render
def test_eps_from_frames_against_truth(runs):
    for render, result in runs:
        ok = np.isfinite(result.eps_vol_p)
        beta = result.beta_rad[ok]
        assert ok.sum() >= 8 and beta.max() < 0  # the front half below the axle
        err = result.eps_vol_p[ok] - _truth_eps(render, beta)
        assert np.abs(err).max() < 0.05, err
        # measured: worst error 0.022 (slip 0.6: 0.030), smallest bound 0.038 (0.041)
        assert np.all(np.abs(err) <= result.eps_bound[ok])
        assert result.eps_source == "estimated" and result.eps_depth_m == pytest.approx(0.02)


@pytest.mark.slow  # the strain runs' frames rendered and their flow measured (module fixture)
@pytest.mark.slow_render
def test_alpha12_across_runs_against_truth(runs):
    """The regression on the estimate taken as it is (gate lifted), then the gate."""
    results = [r for _, r in runs]
    ungated = [dataclasses.replace(r, eps_reason=[]) for r in results]
    pooled = fit_alpha12_across_runs(ungated)
    assert pooled["runs"] == 2
    assert pooled["alpha1_per_m"] == pytest.approx(ALPHA1, rel=0.15)
    assert pooled["alpha2"] == pytest.approx(ALPHA2, abs=0.1)
    width = np.diff(pooled["alpha2_ci95"])[0]
    assert all(width < np.diff(fit_alpha12_across_runs([r])["alpha2_ci95"])[0] for r in ungated)


@pytest.mark.slow  # the strain runs' frames rendered and their flow measured (module fixture)
@pytest.mark.slow_render
def test_unresolved_strain_gives_no_alpha12(runs):
    results = [r for _, r in runs]
    assert fit_alpha12_across_runs(results) is None
    for result in results:
        assert result.alpha12 is None
        assert result.alpha12_reason.startswith("eps_vol^P not resolvable to 0.01 in ")
    data = json.loads(json.dumps(results[0].to_dict()))
    assert data["eps_vol_p_source"] == "estimated" and data["alpha1_alpha2"] is None
    assert data["alpha1_alpha2_reason"] == results[0].alpha12_reason
    rows = [row for row in data["per_beta"] if row["eps_vol_p"] is not None]
    assert len(rows) == np.isfinite(results[0].eps_vol_p).sum()
    assert all(row["eps_vol_p_bound"] > EPS_RESOLUTION
               and row["eps_vol_p_reason"].startswith("not resolvable") for row in rows)
