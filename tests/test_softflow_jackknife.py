"""The rates' jackknife CIs (softflow.field_analysis.jackknife_ci) on a field with known rates and
per-pair, spatially correlated noise (the kind the flow engine leaves on the second renderer)."""

from __future__ import annotations

import numpy as np
from scipy import ndimage

from softflow.field_analysis import fit_profiles, jackknife_ci
from softflow.flow_result import MeanField
from softflow.polar import beta_bins, group_value_order, polar_coordinates, profiles

PX_PER_M, RIM_PX, K_PER_M, A3_PER_M = 1000.0, 40.0, 50.0, 65.0
SLED = np.array([0.04, 0.0])


def _field(pairs: int, noise_mps: float, seed: int):
    """Camera-frame velocity per pair (px/s): v_r, v_theta exponential in the bin frame, plus
    Gaussian-smoothed (6 px) noise of ``noise_mps`` RMS drawn anew for each pair."""
    shape, center = (220, 240), (120.0, 40.0)
    r_px, beta, theta = polar_coordinates(shape, center, 1)
    rho = (r_px - RIM_PX) / PX_PER_M
    v_r, v_t = 0.02 * np.exp(-K_PER_M * rho), -0.03 * np.exp(-A3_PER_M * rho)
    world = np.stack([v_r * np.sin(theta) + v_t * np.cos(theta),
                      v_r * np.cos(theta) - v_t * np.sin(theta)], -1)
    cam = (world - SLED) * PX_PER_M
    cam[r_px < RIM_PX + 8] = np.nan
    rng = np.random.default_rng(seed)
    out = []
    for _ in range(pairs):
        noise = ndimage.gaussian_filter(rng.standard_normal(shape + (2,)), (6, 6, 0))
        out.append(cam + noise / noise.std() * noise_mps * PX_PER_M)
    return out, r_px, beta, theta


def test_jackknife_ci_holds_the_rates():
    pairs, r_px, beta, theta = _field(10, 0.0008, seed=3)
    mean = np.mean(pairs, axis=0)
    field = MeanField(mean, np.where(np.isfinite(mean[..., 0]), len(pairs), 0), 0.0,
                      [p.astype(np.float32) for p in pairs])
    centres, r_min = beta_bins(10.0), RIM_PX + 12
    fits = []
    for c in range(2):
        world = mean / PX_PER_M + SLED
        comp = (world[..., 0] * np.sin(theta) + world[..., 1] * np.cos(theta) if c == 0
                else world[..., 0] * np.cos(theta) - world[..., 1] * np.sin(theta))
        fits.append(fit_profiles(profiles(comp, r_px, beta, centres, np.deg2rad(10), r_min),
                                 RIM_PX, PX_PER_M))
    radial, tangential = jackknife_ci(fits[0], fits[1], field, SLED, r_px, beta, theta,
                                      centres, RIM_PX, r_min, PX_PER_M, 1)
    cover_jk, cover_fit = [], []
    for jk, own, rate in [(j, o, K_PER_M) for j, o in zip(radial, fits[0])] \
            + [(j, o, A3_PER_M) for j, o in zip(tangential, fits[1])]:
        if jk is None:
            continue
        assert jk.rate_per_m == own.rate_per_m and jk.ci_dof == 9
        cover_jk.append(jk.ci95_per_m[0] <= rate <= jk.ci95_per_m[1])
        cover_fit.append(own.ci95_per_m[0] <= rate <= own.ci95_per_m[1])
    assert len(cover_jk) >= 40
    assert np.mean(cover_jk) >= 0.9, np.mean(cover_jk)
    assert np.mean(cover_fit) < np.mean(cover_jk)  # the fit's own CI misses correlated noise


def test_group_value_order_is_lexsort():
    """profiles' sort by (group, value, position): lexsort's permutation, ties and -0.0 too."""
    rng = np.random.default_rng(0)
    for n in (0, 1, 2, 3, 5000):
        groups = rng.integers(0, 40, n)
        values = np.round(rng.normal(size=n), 1)  # many ties
        values[np.flatnonzero(values == 0)[::2]] = -0.0  # beside +0.0
        assert np.array_equal(group_value_order(values, groups), np.lexsort((values, groups)))
