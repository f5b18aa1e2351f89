"""SOFT analysis of side-camera frames: wheel, flow, polar profiles, decay fits, grouser model.

Pipeline (issue items 2-5): track the wheel (:mod:`softflow.wheel_detect`), mask it,
measure and average the soil flow (:mod:`softflow.flow_engine`), go to the world
frame and resolve about the axle (:mod:`softflow.polar`), fit ``k(beta)`` and
``alpha3(beta)`` (:mod:`softflow.decay_fit`; their CIs by a jackknife over the frame pairs,
:func:`jackknife_ci`), and for a grousered wheel score the
effective-radius models (:mod:`softflow.grouser_models`). ``eps_vol^P(beta)`` is
given or estimated from the measured field (:mod:`softflow.volumetric_strain`), and
``1/k = eps/alpha1 + alpha2/alpha1`` is regressed over beta (alpha1, alpha2
constant; :mod:`softflow.alpha12`) to separate ``alpha1`` and ``alpha2``, over the
bins whose estimated ``eps`` is resolved to 0.01 (:func:`softflow.flow_checks.eps_reason`).
"""

from __future__ import annotations

from dataclasses import replace

import cv2
import numpy as np
from scipy.special import stdtrit

from softflow.alpha12 import fit_alpha12, rates_and_sigmas
from softflow.decay_fit import DecayFit, fit_decay_across
from softflow.flow_checks import (alpha12_reason, check_contact_fits, check_sled_velocity,
                                  eps_reason, fit_reason)
from softflow.flow_engine import EDGE_PX, average_flow
from softflow.flow_result import FlowResult, MeanField
from softflow.grouser_models import select_model
from softflow.polar import beta_bins, far_field_velocity, polar_coordinates, profiles, resolve
from softflow.threads import capped
from softflow.volumetric_strain import FLOW_FIELD_ERROR, strain_by_beta
from softflow.wheel_detect import (MASK_MARGIN_PX, smooth_pixels, soil_mask,
                                   track_wheel)

#: profiles start this far outside the grouser tips: the soil mask's margin, the flow engine's
#: edge band (``EDGE_PX``: no LK sums there) and the 4 px reach of the decay-rate flow window
#: (closer, the windows are one-sided and flatten the profile: alpha3 0.5-1.5 % lower on the
#: test scenes; second renderer, tuning seeds 900-915, EDGE_PX 2: fit start 12 / 14 / 16 px,
#: alpha3 mean error -1.7 / -1.1 / -1.0 %, within 5 % in 128 / 133 / 131 of 148 defined bins)
FIT_START_PX = MASK_MARGIN_PX + EDGE_PX + 4.0
BIN_WIDTH_DEG = 10.0
SLED_REFINEMENTS = 12  # at most; the offset shrinks about twofold each time
#: fewest frame pairs for the jackknife CI of the rates; with fewer the fit's own CI is kept
MIN_JACKKNIFE_PAIRS = 3
#: the rate of a beta bin is fitted together with its nearest neighbours that have profiles
#: (within ``RATE_BIN_REACH`` bins; :func:`fit_profiles`), this many bins in all: 3, the bin and
#: its two neighbours, or at the end of the contact region the next two inwards. The flow's pair
#: noise is correlated over about 16 px (a 10 deg bin is 15-35 px wide there), so it differs
#: partly from bin to bin while the rate varies slowly with the angle (second renderer, smooth
#: wheel, tuning seeds 900-915: k / alpha3 within 5 % in 110 / 133 of 120 / 148 defined contact
#: bins with each bin alone, 116 / 140 with 3 bins; 5 bins, rate linear: 116 / 141, but the rate's
#: curvature over 40 deg biases it, alpha3 mean -1.1 -> -1.8 %; 5 bins, quadratic: 113 / 136)
RATE_BINS = 3
RATE_BIN_REACH = 2


def fit_profiles(prof: list, rim_px: float, px_per_m: float, bins=None) -> list:
    """Decay fit of each beta bin's profile (:func:`softflow.decay_fit.fit_decay_across` with its
    ``RATE_BINS - 1`` nearest neighbours that have 5 or more points, within ``RATE_BIN_REACH``
    bins, the nearer first and, at equal distance, both); ``bins``: only these, the others None.
    """
    n = len(prof)
    rho = [(p[0] - rim_px) / px_per_m for p in prof]
    width = np.deg2rad(BIN_WIDTH_DEG)
    out = [None] * n
    for j in range(n) if bins is None else bins:
        steps = [d for k in range(1, RATE_BIN_REACH + 1) for d in (-k, k)]
        near = [0] + [d for d in steps if len(rho[(j + d) % n]) >= 5][:RATE_BINS - 1]
        near.sort()
        idx = [(j + d) % n for d in near]
        out[j] = fit_decay_across([rho[m] for m in idx], [prof[m][1] for m in idx],
                                  [prof[m][2] for m in idx], np.array(near, float) * width,
                                  near.index(0))
    return out


def _rates(fits: list[DecayFit | None]) -> np.ndarray:
    return np.array([f.rate_per_m if f and f.r2 > 0.5 else np.nan for f in fits])


@capped
def analyse_frames(frames: list[np.ndarray], t_s: np.ndarray, px_per_m: float,
                   direction: int = 1, wheel_center_px: tuple[float, float] | None = None,
                   wheel_radius_px: float | None = None, grouser_count: int | None = None,
                   grouser_height_px: float | None = None, engine: str = "deform-lk",
                   eps_vol_by_beta: np.ndarray | None = None,
                   frame_range: tuple[int, int] | None = None, source: str = "",
                   eps_depth_m: float | None = None, client=None) -> FlowResult:
    """Run the whole SOFT analysis on grey frames of the stable phase (2 or more).

    Without ``eps_vol_by_beta`` (per beta bin), ``eps_vol^P`` is estimated below the
    axle at ``eps_depth_m`` (default a fifth of the rim radius) outside the wheel.
    ``client``: a ``dask.distributed.Client`` whose workers compute the frame pairs' flows
    (the rest runs here; the same result).
    """
    if len(frames) < 2:
        raise ValueError("need at least two frames")
    poses = track_wheel(frames, direction, wheel_center_px, wheel_radius_px, grouser_count,
                        grouser_height_px)
    # no soil where the first frame is smooth (sky-like background, sled frame above the soil
    # surface): out of the flow and the profiles, 4 px beyond (the texture window)
    textured = ~cv2.dilate(smooth_pixels(frames[0]).astype(np.uint8), np.ones((9, 9), np.uint8)
                           ).astype(bool)
    masks = [soil_mask(frames[0].shape, poses[k]) & soil_mask(frames[0].shape, poses[k + 1])
             & textured for k in range(len(frames) - 1)]
    mean = average_flow(frames, np.asarray(t_s, float), masks, engine, client=client)
    center = tuple(np.mean([p.center_px for p in poses], axis=0))
    r_px, beta, theta = polar_coordinates(frames[0].shape, center, direction)
    v_cam = mean.velocity_px_per_s / px_per_m
    lowest = max(p.center_px[1] + p.radius_px + p.grouser_height_px for p in poses)
    # below the wheel there is soil, whatever lies above its surface (bin wall, sled frame)
    under = np.arange(frames[0].shape[0])[:, None] > lowest + MASK_MARGIN_PX
    if under.sum() < 0.05 * frames[0].shape[0]:  # too few rows below the wheel: all of them
        under = np.ones_like(under)
    usable = np.broadcast_to(under, r_px.shape)
    far, spread = far_field_velocity(v_cam, r_px, usable)
    rim = poses[0].radius_px
    r_min = rim + poses[0].grouser_height_px + FIT_START_PX
    centres = beta_bins(BIN_WIDTH_DEG)
    ok = np.isfinite(v_cam[..., 0]) & usable
    far_px = ok & (r_px >= np.quantile(r_px[ok], 0.85))
    check_sled_velocity(-far, spread, direction)
    sled, prof_r, prof_t, radial, tangential = world_profiles(
        v_cam, -far, r_px, beta, theta, far_px, centres, rim, r_min, px_per_m, direction)
    radial, tangential = jackknife_ci(radial, tangential, mean, sled, r_px, beta, theta, centres,
                                      rim, r_min, px_per_m, direction)
    speed = float(np.hypot(*sled))
    radial, radial_reason = _checked(radial, prof_r, np.abs(np.cos(centres)))  # |sin theta|
    tangential, tangential_reason = _checked(
        tangential, prof_t, [abs(f.amplitude) / speed if f else 0.0 for f in tangential])
    check_contact_fits(centres, radial, tangential)
    width = np.deg2rad(BIN_WIDTH_DEG)
    result = FlowResult(px_per_m, np.asarray(t_s, float),
                        frame_range or (0, len(frames) - 1), poses, mean,
                        (float(sled[0]), float(sled[1])), centres, radial, tangential,
                        prof_r, prof_t, engine=engine, source=source,
                        radial_reason=radial_reason, tangential_reason=tangential_reason)
    if eps_vol_by_beta is not None:
        result.eps_vol_p, result.eps_source = np.asarray(eps_vol_by_beta, float), "given"
    else:
        depth_m = rim / px_per_m / 5 if eps_depth_m is None else eps_depth_m
        below = centres < 0  # a bin has soil below the axle only
        result.eps_vol_p, result.eps_bound = np.full((2, len(centres)), np.nan)
        result.eps_vol_p[below], result.eps_bound[below] = strain_by_beta(
            mean.velocity_px_per_s, center, rim + poses[0].grouser_height_px + depth_m * px_per_m,
            centres[below], width, -np.asarray(sled) * px_per_m)
        result.eps_bound += FLOW_FIELD_ERROR  # the field is measured, not exact
        result.eps_reason = [eps_reason(e, b) if low else "not estimated above the axle"
                             for e, b, low in zip(result.eps_vol_p, result.eps_bound, below)]
        result.eps_source, result.eps_depth_m = "estimated", depth_m
    k_per_m, k_sigma_per_m = rates_and_sigmas(radial)
    result.alpha12 = fit_alpha12(result.resolved_eps(), k_per_m, k_sigma_per_m)
    if result.alpha12:
        result.alpha12["eps_source"] = result.eps_source
    else:
        result.alpha12_reason = alpha12_reason(result.eps_reason or [None] * len(centres),
                                               np.isfinite(k_per_m))
    if poses[0].grouser_count and poses[0].grouser_height_px > 0:
        result.grouser = _grouser_selection(result, frames[0].shape, direction, r_min)
    return result


def _model_velocity(fits_r: list, fits_t: list, r_px: np.ndarray, beta: np.ndarray,
                    theta: np.ndarray, rim_px: float, px_per_m: float,
                    direction: int) -> np.ndarray:
    """Bin-frame velocity (m/s, image axes) of the fitted profiles at the pixels; NaN in the bins
    without both fits (R2 > 0.5)."""
    n = len(fits_r)
    par = np.full((n, 4), np.nan)
    for i, (fr, ft) in enumerate(zip(fits_r, fits_t)):
        if fr and ft and fr.r2 > 0.5 and ft.r2 > 0.5:
            par[i] = fr.amplitude, fr.rate_per_m, ft.amplitude, ft.rate_per_m
    b = np.floor((beta + np.pi) / (2 * np.pi / n)).astype(int) % n
    rho = (r_px - rim_px) / px_per_m
    v_r = par[b, 0] * np.exp(-par[b, 1] * rho)
    v_t = par[b, 2] * np.exp(-par[b, 3] * rho)
    s, c = np.sin(theta), np.cos(theta)
    return np.stack([direction * (v_r * s + v_t * c), v_r * c - v_t * s], -1)


def world_profiles(v_cam: np.ndarray, sled: np.ndarray, r_px: np.ndarray, beta: np.ndarray,
                   theta: np.ndarray, far_px: np.ndarray, centres: np.ndarray, rim_px: float,
                   r_min_px: float, px_per_m: float, direction: int):
    """Sled velocity, profiles and decay fits (radial, tangential) in the bin frame.

    The far soil still moves a little (``exp(-k rho)`` at the largest ``rho`` in view: 0.05 %
    of ``V`` on the second renderer), and a sled velocity off by that much is an offset in
    every profile that bends its tail: on that renderer's exact field it put ``k`` up to 7 %
    and ``alpha3`` up to 70 % off. So ``V`` is refined with the fitted model (the polar
    module's far-field estimate, ``sled``, is the start): the median over the far pixels of
    the bin-frame velocity less the fitted model's is the offset, taken out and the profiles
    refitted until it settles (at most ``SLED_REFINEMENTS`` times)."""
    width = np.deg2rad(BIN_WIDTH_DEG)

    def fitted(sled):
        v_r, v_t = resolve(v_cam + sled, theta, direction)
        prof = [profiles(v, r_px, beta, centres, width, r_min_px) for v in (v_r, v_t)]
        return (*prof, *(fit_profiles(pr, rim_px, px_per_m) for pr in prof))

    prof_r, prof_t, radial, tangential = fitted(sled)
    for _ in range(SLED_REFINEMENTS):
        model = _model_velocity(radial, tangential, r_px, beta, theta, rim_px, px_per_m,
                                direction)
        resid = (v_cam + sled - model)[far_px & np.isfinite(model[..., 0])]
        if len(resid) < 50:
            break
        offset = np.median(resid, axis=0)
        sled = sled - offset
        prof_r, prof_t, radial, tangential = fitted(sled)
        if np.hypot(*offset) < 1e-6 * np.hypot(*sled):  # settled
            break
    return sled, prof_r, prof_t, radial, tangential


def jackknife_ci(radial: list, tangential: list, mean: MeanField, sled: np.ndarray,
                 r_px: np.ndarray, beta: np.ndarray, theta: np.ndarray, centres: np.ndarray,
                 rim_px: float, r_min_px: float, px_per_m: float,
                 direction: int) -> tuple[list, list]:
    """The fits with their 95 % CIs from leave-one-pair-out refits (jackknife over the frame
    pairs, Efron & Stein 1981: ``se^2 = (P-1)/P sum (k_i - mean k_i)^2``, ``t(0.975, P-1)``).

    The flow's error is spatially correlated (over about 16 px) and differs from pair to pair,
    so the fit's CI, from the scatter about one averaged profile, is too narrow: on the second
    renderer (tuning seeds 400-405, 12 frames) it held the truth in 55-60 % of the defined
    contact bins, the jackknife's in 97 %. The sled velocity is held at its final value. A bin
    where a leave-one-out fit fails gets an infinite CI (the checks then drop it). Fewer than
    ``MIN_JACKKNIFE_PAIRS`` pairs: the fits as they are."""
    pairs = mean.pair_velocities_px_per_s
    n_pairs = len(pairs)
    if n_pairs < MIN_JACKKNIFE_PAIRS:
        return radial, tangential
    width = np.deg2rad(BIN_WIDTH_DEG)
    total = np.nan_to_num(mean.velocity_px_per_s) * mean.count[..., None]
    rates = np.full((n_pairs, 2, len(centres)), np.nan)
    for i, pair in enumerate(pairs):
        valid = np.isfinite(pair[..., 0])
        left = mean.count - valid
        with np.errstate(invalid="ignore", divide="ignore"):
            loo = (total - np.where(valid[..., None], pair, 0)) / left[..., None]
        loo[left == 0] = np.nan
        for c, (v, fits) in enumerate(zip(resolve(loo / px_per_m + sled, theta, direction),
                                          (radial, tangential))):
            prof = profiles(v, r_px, beta, centres, width, r_min_px)
            refits = fit_profiles(prof, rim_px, px_per_m,
                                  np.flatnonzero([f is not None for f in fits]))
            for j, f in enumerate(refits):
                if f is not None:
                    rates[i, c, j] = f.rate_per_m
    t = stdtrit(n_pairs - 1, 0.975)
    out = []
    for c, fits in enumerate((radial, tangential)):
        k = rates[:, c]
        with np.errstate(invalid="ignore"):
            half = t * np.sqrt((n_pairs - 1) / n_pairs * np.sum((k - k.mean(0)) ** 2, 0))
        half[np.isnan(half)] = np.inf
        out.append([f and replace(f, ci95_per_m=(f.rate_per_m - h, f.rate_per_m + h),
                                  ci_dof=n_pairs - 1) for f, h in zip(fits, half)])
    return out[0], out[1]


def _checked(fits: list, profs: list, rim_fraction) -> tuple[list, list]:
    """Fits kept where :func:`softflow.flow_checks.fit_reason` finds nothing, and the reasons."""
    reasons = [fit_reason(f, len(p[0]), float(q)) for f, p, q in zip(fits, profs, rim_fraction)]
    return [None if r else f for f, r in zip(fits, reasons)], reasons


def _grouser_selection(result: FlowResult, shape: tuple[int, int], direction: int,
                       r_min: float) -> dict:
    """Per-pair samples (every 3rd pixel) in the world frame, scored per grouser model."""
    keys = ("r_px", "theta", "bin", "wheel_angle", "v_r", "v_t")
    parts = {k: [] for k in keys}
    width = np.deg2rad(BIN_WIDTH_DEG)
    for k, vel in enumerate(result.mean.pair_velocities_px_per_s):
        pose = result.poses[k]
        r_px, beta, theta = polar_coordinates(shape, pose.center_px, direction)
        sub = (slice(None, None, 3), slice(None, None, 3))
        v = vel[sub] / result.px_per_m + np.array(result.sled_velocity_mps)
        ok = np.isfinite(v[..., 0]) & (r_px[sub] >= r_min) & (r_px[sub] <= r_min + 60)
        vr, vt = resolve(v, theta[sub], direction)
        b = np.floor((beta[sub] + np.pi) / width).astype(int) % len(result.beta_rad)
        for key, arr in zip(keys, (r_px[sub], theta[sub], b,
                                   np.full(r_px[sub].shape, pose.grouser_angle_rad), vr, vt)):
            parts[key].append(arr[ok])
    samples = {k: np.concatenate(v) for k, v in parts.items()}
    p0 = result.poses[0]
    return select_model(samples, p0.radius_px, p0.grouser_height_px, p0.grouser_count,
                        {"r": _rates(result.radial), "t": _rates(result.tangential)},
                        result.px_per_m)
