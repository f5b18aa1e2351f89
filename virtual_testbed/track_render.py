"""Top-view photos of a grousered wheel's track with the grouser marks a known slip lays down.

A height field (sand + compacted track + grouser grooves) is shaded by a low sun,
cast shadows included, then seen through a camera (rotation, mild keystone, blur,
noise, contrast). The grooves come from the wheel kinematics: grouser ``k`` reaches
bottom dead centre at wheel angle ``2*pi*k/n`` while the hub has travelled
``r*(1 - s)*2*pi*k/n`` (driving slip ``s = (r*omega - v)/(r*omega)``, ``r`` the radius
without grousers, raw-run spec); the groove shape is the lower envelope of the tip's
trochoid at radius ``r + h``, flattened to the sand's angle of repose.
The truth is returned apart (:func:`write_track_render` writes it to ``*.truth.json``).
Never imports an estimator.
"""

from __future__ import annotations

import json
from dataclasses import asdict, dataclass, replace
from pathlib import Path

import cv2
import numpy as np
from scipy.ndimage import gaussian_filter1d, maximum_filter1d, uniform_filter1d

from swtlab_base.atomic import write_atomically
from virtual_testbed.rig import BB2_WHEEL

TRUTH_SCHEMA = "swtlab.virtual_testbed.track_render/1"
_STEP_M = 2e-5  # resolution of the along-track groove profile


@dataclass(frozen=True)
class TrackNuisance:
    """Scene and camera knobs; the defaults give a clean photo."""

    size_px: tuple[int, int] = (640, 480)  # width, height
    track_angle_deg: float = 0.0  # direction of travel in the image, x right, y down
    track_offset_px: float = 0.0  # track centre line off the image centre, across the track
    track_width_m: float = 0.112
    sinkage_m: float = 0.01  # rim bottom below the undisturbed surface
    grouser_thickness_m: float = 0.003
    repose_deg: float = 33.0  # groove walls steeper than this collapse
    mark_depth_jitter: float = 0.1  # relative spread of groove depth, mark to mark
    mark_fade: float = 0.0  # slow along-track fading of the grooves, 0..1
    mark_position_jitter: float = 0.01  # standard deviation, fraction of the spacing
    missing_fraction: float = 0.0  # grooves filled back in
    doubled_fraction: float = 0.0  # grousers that re-bite a fraction of a pitch later
    smeared_fraction: float = 0.0  # grooves smeared along the track
    sand_roughness: float = 1.0  # scales the sand height texture
    track_tone: float = 0.92  # albedo of the compacted track relative to the sand
    sun_elevation_deg: float = 25.0
    sun_azimuth_deg: float = 30.0  # direction the light comes from, in the image
    contrast: float = 1.0
    brightness: float = 0.0  # offset in grey levels
    noise_std: float = 2.0  # grey levels
    blur_px: float = 0.0  # Gaussian sigma
    perspective: float = 0.0  # keystone: relative scale change at the image border
    perspective_azimuth_deg: float = 90.0  # direction in which the scale changes
    marks: bool = True  # False: the same track with no grouser marks


def random_nuisance(seed: int, size_px: tuple[int, int] = (640, 480)) -> TrackNuisance:
    """A random but plausible photo: any rotation, low sun, defects, noise, blur, keystone.

    The sun shines within 50 degrees of the track axis: light along the grooves shades
    nothing (a photo for this method is taken with the sun ahead or behind the wheel).
    """
    rng = np.random.default_rng(seed)
    u = rng.uniform
    track_deg = u(0, 360)
    return TrackNuisance(
        size_px=size_px, track_angle_deg=track_deg, track_offset_px=u(-0.05, 0.05) * min(size_px),
        sinkage_m=u(0.004, 0.02), grouser_thickness_m=u(0.002, 0.005), repose_deg=u(28, 38),
        mark_depth_jitter=u(0.05, 0.3), mark_fade=u(0, 0.5), mark_position_jitter=u(0, 0.02),
        missing_fraction=u(0, 0.15), doubled_fraction=u(0, 0.1), smeared_fraction=u(0, 0.2),
        sand_roughness=u(0.5, 1.5), track_tone=u(0.85, 1.1), sun_elevation_deg=u(12, 40),
        sun_azimuth_deg=track_deg + u(-50, 50) + 180 * rng.integers(2),
        contrast=u(0.5, 1.2), brightness=u(-30, 20),
        noise_std=u(1, 6), blur_px=u(0, 1.2), perspective=u(0, 0.015),
        perspective_azimuth_deg=u(0, 360))


def mark_spacing_m(slip: float, radius_m: float, grouser_count: int) -> float:
    """Hub travel per grouser pitch, ``2*pi*r*(1 - s)/n`` (r without grousers)."""
    return 2.0 * np.pi * radius_m * (1.0 - slip) / grouser_count


def groove_profile(slip: float, radius_m: float, grouser_height_m: float,
                   thickness_m: float) -> tuple[np.ndarray, np.ndarray]:
    """Depth below the rim bottom cut by one grouser plate, against along-track position
    relative to the tip's bottom-dead-centre point (lower envelope of its trochoid)."""
    r_tip = radius_m + grouser_height_m
    phi = np.linspace(-1.0, 1.0, 8001) * np.arccos(radius_m / r_tip)
    x_m = radius_m * (1.0 - slip) * phi - r_tip * np.sin(phi)  # decreasing for 0 <= s < 1
    depth_m = r_tip * np.cos(phi) - radius_m
    half_m = np.abs(x_m).max() + thickness_m
    grid_m = np.arange(-half_m, half_m + _STEP_M, _STEP_M)
    depth = np.interp(grid_m, x_m[::-1], depth_m[::-1], left=0.0, right=0.0)
    return grid_m, maximum_filter1d(depth, max(1, round(thickness_m / _STEP_M)))


def _collapse(height_m: np.ndarray, repose_deg: float) -> np.ndarray:
    """Raise groove bottoms until no slope exceeds the angle of repose (cone envelope)."""
    rise = np.tan(np.radians(repose_deg)) * _STEP_M * np.arange(height_m.size)
    forward = np.maximum.accumulate(height_m + rise) - rise
    backward = (np.maximum.accumulate((height_m - rise)[::-1]) + rise[::-1])[::-1]
    return np.maximum(forward, backward)


def _along_profile(slip, radius_m, grouser_count, grouser_height_m, nz, half_len_m, rng):
    """Track surface height (m) along the track on a fine grid, and the true mark centres.

    Every grouser cuts the same groove (rigid wheel, steady sinkage); what the sand does
    afterwards varies mark to mark: the relief about its one-pitch mean is scaled (fading,
    filled-in marks), blurred (smeared marks) or gets a second, narrow re-bite (doubled).
    """
    spacing_m = mark_spacing_m(slip, radius_m, grouser_count)
    rel_m, groove = groove_profile(slip, radius_m, grouser_height_m, nz.grouser_thickness_m)
    grid_m = np.arange(-half_len_m, half_len_m, _STEP_M)
    k = np.arange(np.floor(-half_len_m / spacing_m) - 2, np.ceil(half_len_m / spacing_m) + 3)
    centres_m = (k + rng.uniform() + rng.normal(0, nz.mark_position_jitter, k.size)) * spacing_m
    depth = np.zeros_like(grid_m)
    ridge_m = 0.25 * grouser_height_m * slip  # sand the grouser throws back, heaped at the cusp
    ridge_sigma_m = max(nz.grouser_thickness_m, 0.12 * spacing_m)
    for c_m in centres_m if nz.marks else []:
        i0 = int(round((c_m + rel_m[0] + half_len_m) / _STEP_M))
        lo, hi = max(i0, 0), min(i0 + rel_m.size, grid_m.size)
        if lo < hi:
            np.maximum(depth[lo:hi], groove[lo - i0:hi - i0], out=depth[lo:hi])
            x = (grid_m[lo:hi] - c_m - spacing_m / 2) / ridge_sigma_m
            depth[lo:hi] -= ridge_m * np.exp(-0.5 * x * x)
    fade = 1 - nz.mark_fade * (0.5 + 0.5 * np.sin(centres_m / (7 * spacing_m) + rng.uniform(0, 6)))
    scale = fade * np.clip(1 + rng.normal(0, nz.mark_depth_jitter, k.size), 0.3, 1.5)
    scale[rng.uniform(size=k.size) < nz.missing_fraction] = 0.05
    smeared = (rng.uniform(size=k.size) < nz.smeared_fraction).astype(float)
    mean = uniform_filter1d(depth, int(round(spacing_m / _STEP_M)), mode="nearest")
    depth = mean + np.interp(grid_m, centres_m, scale) * (depth - mean)
    depth = _smear(depth, np.interp(grid_m, centres_m, smeared), 0.15 * spacing_m / _STEP_M)
    doubled = centres_m[rng.uniform(size=k.size) < nz.doubled_fraction] if nz.marks else []
    relief_m = np.ptp(depth)
    for c_m in doubled:  # a narrow re-bite 0.25-0.45 pitch later, 30-70 % of the relief deep
        x = (grid_m - c_m - rng.uniform(0.25, 0.45) * spacing_m) / nz.grouser_thickness_m
        depth += rng.uniform(0.3, 0.7) * relief_m * np.exp(-x * x)
    return grid_m, _collapse(-depth, nz.repose_deg), centres_m, spacing_m


def _smear(depth: np.ndarray, blend: np.ndarray, sigma: float) -> np.ndarray:
    """``(1 - blend) * depth + blend * gaussian_filter1d(depth, sigma)``, the filter taken only
    over the runs where ``blend > 0``, each with the filter's reach (4 sigma) either side: the
    same numbers, with the work in proportion to the smeared stretch (the profile holds some
    100 000 samples, the kernel 1 000-4 000; most marks are not smeared)."""
    reach = int(4 * sigma) + 1
    out = depth.copy()
    edges = np.flatnonzero(np.diff(np.r_[0, blend > 0, 0]))
    for start, stop in zip(edges[::2], edges[1::2]):
        lo, hi = max(start - reach, 0), min(stop + reach, depth.size)
        smooth = gaussian_filter1d(depth[lo:hi], sigma)[start - lo:stop - lo]
        out[start:stop] = (1 - blend[start:stop]) * depth[start:stop] + blend[start:stop] * smooth
    return out


def _fractal(shape, rng, sigmas_px, amplitudes):
    """Isotropic multi-scale noise: sum of Gaussian-filtered white noise, each unit RMS
    (coarse scales drawn on a coarser grid and resized)."""
    out = np.zeros(shape, np.float32)
    for sigma, amp in zip(sigmas_px, amplitudes):
        factor = max(1, int(sigma // 3))
        small = rng.standard_normal((shape[0] // factor + 1, shape[1] // factor + 1))
        layer = cv2.GaussianBlur(small.astype(np.float32), (0, 0), sigma / factor)
        if factor > 1:
            layer = cv2.resize(layer, (shape[1], shape[0]), interpolation=cv2.INTER_CUBIC)
        layer = layer[:shape[0], :shape[1]]
        out += amp * layer / (layer.std() + 1e-12)
    return out


def _smoothstep(x):
    """0 below -1, 1 above 1, smooth in between."""
    return np.clip(0.5 + 0.5 * x, 0, 1) ** 2 * (3 - 2 * np.clip(0.5 + 0.5 * x, 0, 1))


def _shade(height_m, albedo, px_per_m, elevation_deg, ambient=0.25):
    """Lambert shading with cast shadows, light coming from +x of the canvas."""
    gy, gx = np.gradient(height_m * px_per_m)
    e = np.radians(elevation_deg)
    lambert = (np.sin(e) - gx * np.cos(e)) / np.sqrt(1 + gx**2 + gy**2)
    tan_e = np.tan(e) / px_per_m  # rise of a sun ray per pixel towards +x
    ray = height_m - tan_e * np.arange(height_m.shape[1])[None, :]
    horizon = np.maximum.accumulate(ray[:, ::-1], axis=1)[:, ::-1]
    lit = ray >= horizon - 1e-9
    lit = cv2.GaussianBlur(lit.astype(np.float32), (0, 0), 0.7)  # penumbra
    return albedo * (ambient + (1 - ambient) * np.clip(lambert, 0, None) * lit)


def render_track(slip: float, radius_m: float = BB2_WHEEL.radius_m,
                 grouser_count: int = BB2_WHEEL.grouser_count,
                 grouser_height_m: float = BB2_WHEEL.grouser_height_m,
                 px_per_m: float = 1000.0, seed: int = 0,
                 nuisance: TrackNuisance | None = None, **knobs) -> tuple[np.ndarray, dict]:
    """Grey uint8 photo of the track of a wheel (default: the testbed's BB2-like wheel) and
    its truth (slip, spacing, scale, geometry).

    ``knobs`` override fields of ``nuisance`` (default :class:`TrackNuisance`).
    ``px_per_m`` is the ground scale at the image centre (the keystone keeps it there).
    """
    if not 0.0 <= slip < 1.0:
        raise ValueError("the renderer lays driving-slip tracks, 0 <= slip < 1")
    nz = replace(nuisance or TrackNuisance(), **knobs)
    rng = np.random.default_rng(seed)
    width, height = nz.size_px
    side = int(np.ceil(np.hypot(width, height) * (1 + 2 * nz.perspective))) + 16
    half_len_m = 0.5 * side / px_per_m + 0.1
    grid_m, along_m, centres_m, spacing_m = _along_profile(
        slip, radius_m, grouser_count, grouser_height_m, nz, half_len_m, rng)

    # canvas: light from +x; the track runs at (track angle - sun azimuth) on it
    rel = np.radians(nz.track_angle_deg - nz.sun_azimuth_deg)
    v, u = np.mgrid[0:side, 0:side].astype(np.float32) - (side - 1) / 2
    a_m = (u * np.cos(rel) + v * np.sin(rel)) / px_per_m
    c_m = (-u * np.sin(rel) + v * np.cos(rel) - nz.track_offset_px) / px_per_m
    half_w = nz.track_width_m / 2
    edge = max(0.002, 0.5 * nz.sinkage_m / np.tan(np.radians(nz.repose_deg)))  # wall at repose
    inside = _smoothstep((half_w - np.abs(c_m)) / edge)
    grooved = _smoothstep((half_w - 0.006 - np.abs(c_m)) / edge)
    berm = 0.4 * nz.sinkage_m * np.exp(-(((np.abs(c_m) - half_w - 0.012) / 0.01) ** 2))
    groove_m = np.interp(a_m, grid_m, along_m).astype(np.float32)
    sand = _fractal((side, side), rng, [0.7, 3, 12, 50],
                    np.array([0.08, 0.2, 0.5, 1.5]) * 1e-3 * nz.sand_roughness)
    surface_m = (-nz.sinkage_m * inside + grooved * groove_m + berm
                 + sand * (1 - 0.7 * inside))
    albedo = (0.6 * (1 + _fractal((side, side), rng, [0.6, 40], [0.08, 0.06]))
              * (1 + (nz.track_tone - 1) * inside))
    shaded = _shade(surface_m, albedo, px_per_m, nz.sun_elevation_deg)

    # camera: canvas -> image rotation by the sun azimuth, then a keystone about the centre
    az = np.radians(nz.sun_azimuth_deg)
    centre = np.array([(width - 1) / 2, (height - 1) / 2])
    rot = np.array([[np.cos(az), -np.sin(az), 0], [np.sin(az), np.cos(az), 0], [0, 0, 1]])
    to_canvas_origin = np.array([[1, 0, -(side - 1) / 2], [0, 1, -(side - 1) / 2], [0, 0, 1]])
    g = nz.perspective / (0.5 * min(width, height))
    pa = np.radians(nz.perspective_azimuth_deg)
    keystone = np.array([[1, 0, 0], [0, 1, 0], [g * np.cos(pa), g * np.sin(pa), 1]])
    to_image = np.array([[1, 0, centre[0]], [0, 1, centre[1]], [0, 0, 1]])
    homography = to_image @ keystone @ rot @ to_canvas_origin
    img = cv2.warpPerspective(shaded.astype(np.float32), homography, (width, height),
                              flags=cv2.INTER_LINEAR, borderMode=cv2.BORDER_REFLECT)
    img = 255 * img * nz.contrast + nz.brightness + 40 * (1 - nz.contrast)
    if nz.blur_px > 0:
        img = cv2.GaussianBlur(img, (0, 0), nz.blur_px)
    img = img + rng.normal(0, nz.noise_std, img.shape)
    image = np.clip(np.round(img), 0, 255).astype(np.uint8)

    def to_px(a_m, c_m):  # track coordinates (m) -> image pixels
        ca, sa = np.cos(rel), np.sin(rel)
        uu = a_m * px_per_m * ca - (c_m * px_per_m + nz.track_offset_px) * sa + (side - 1) / 2
        vv = a_m * px_per_m * sa + (c_m * px_per_m + nz.track_offset_px) * ca + (side - 1) / 2
        p = homography @ np.array([uu, vv, np.ones_like(uu)])
        return (p[:2] / p[2]).T

    ruler_m = 0.25 * min(width, height) / px_per_m
    scale_points = to_px(np.array([-ruler_m, ruler_m]), np.zeros(2))
    truth = {
        "schema": TRUTH_SCHEMA, "seed": seed, "slip": float(slip), "radius_m": radius_m,
        "grouser_count": grouser_count, "grouser_height_m": grouser_height_m,
        "px_per_m": px_per_m, "spacing_m": spacing_m,
        "spacing_if_tip_radius_m": mark_spacing_m(slip, radius_m + grouser_height_m, grouser_count),
        "track_angle_deg": float(nz.track_angle_deg % 360),
        "scale_points_px": scale_points.round(3).tolist(), "scale_distance_m": 2 * ruler_m,
        "mark_centres_m": centres_m.round(6).tolist(),
        "nuisance": asdict(nz),
    }
    return image, truth


def write_track_render(path: str | Path, slip: float, **kwargs) -> tuple[Path, Path]:
    """Render and write ``path`` (PNG) and its truth apart as ``<stem>.truth.json``."""
    path = Path(path)
    image, truth = render_track(slip, **kwargs)
    encoded, data = cv2.imencode(Path(path).suffix or ".png", image)
    if not encoded:
        raise OSError(f"could not encode {path}")
    write_atomically(path, data.tobytes())
    truth_path = path.with_suffix(".truth.json")
    write_atomically(truth_path, json.dumps(truth, indent=1))
    return path, truth_path
