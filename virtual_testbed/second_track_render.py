"""A second top-view track renderer, written apart from ``track_render`` (no shared code): issue 21.

The ground is drawn in ground coordinates (metres; ``u`` along the track, ``v`` across)
and seen through a pinhole-like map: scale ``px_per_m`` at the image centre, a keystone
(projective, relative scale change ``perspective`` at the image half-diagonal along
``perspective_azimuth_deg``), then a rotation by ``track_angle_deg``. Grouser marks lie
``d = 2 pi r (1 - s) / n`` apart along the track (raw-run spec slip, ``r`` without
grousers; RUAG's single-wheel method), each displaced by ``position_jitter * d`` (i.i.d.,
about 1 %), some erased (filled in) and some smeared along the track. A mark is a groove
of the grouser thickness: a shaded wall then a lit wall across the track width. Sand:
painted speckles of mixed sizes; light: a low-order uneven illumination field; imaging:
blur, noise, JPEG at ``jpeg_quality``. Never imports an estimator.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass

import cv2
import numpy as np
from scipy import ndimage


@dataclass(frozen=True)
class SecondTrackScene:
    width_px: int = 640
    height_px: int = 480
    px_per_m: float = 700.0
    radius_m: float = 0.125  # without grousers
    grousers: int = 12
    slip: float = 0.3
    track_width_m: float = 0.11
    groove_m: float = 0.004
    track_angle_deg: float = 0.0
    perspective: float = 0.01
    perspective_azimuth_deg: float = 90.0
    position_jitter: float = 0.01
    erased_fraction: float = 0.1
    smeared_fraction: float = 0.15
    marks: bool = True
    light_unevenness: float = 0.3
    noise_std: float = 3.0
    blur_px: float = 0.8
    jpeg_quality: int = 80
    seed: int = 0


def spacing_m(scene: SecondTrackScene) -> float:
    return 2 * np.pi * scene.radius_m * (1 - scene.slip) / scene.grousers


def _ground_of_pixels(scene: SecondTrackScene) -> tuple[np.ndarray, np.ndarray]:
    """Ground coordinates (m, centred) of every pixel: rotation, then the keystone undone."""
    w, h = scene.width_px, scene.height_px
    y, x = np.mgrid[0:h, 0:w].astype(np.float64)
    a = np.deg2rad(scene.track_angle_deg)
    px, py = x - (w - 1) / 2, y - (h - 1) / 2
    qx = np.cos(a) * px + np.sin(a) * py  # along the track, pixels
    qy = -np.sin(a) * px + np.cos(a) * py
    half = 0.5 * np.hypot(w, h)
    b = np.deg2rad(scene.perspective_azimuth_deg - scene.track_angle_deg)
    ax, ay = np.cos(b), np.sin(b)
    kappa = scene.perspective / half
    along = qx * ax + qy * ay  # undo q' = q / (1 - kappa q.a)
    flat = along / (1 + kappa * along)
    factor = 1 - kappa * flat
    return qx * factor / scene.px_per_m, qy * factor / scene.px_per_m


def _mark_profile(scene: SecondTrackScene, rng: np.random.Generator, u_grid: np.ndarray,
                  length_m: float) -> np.ndarray:
    """Height-shading contribution of the marks along the track on ``u_grid`` (m)."""
    d = spacing_m(scene)
    n = int(length_m / d) + 4
    start = -rng.uniform(0, d) - (n // 2) * d
    out = np.zeros_like(u_grid)
    g = scene.groove_m
    for i in range(n):
        if rng.uniform() < scene.erased_fraction:
            continue
        u0 = start + i * d + scene.position_jitter * d * rng.standard_normal()
        width = g * (rng.uniform(2.0, 3.5) if rng.uniform() < scene.smeared_fraction else 1.0)
        depth = rng.uniform(0.6, 1.0)
        s = (u_grid - u0) / width
        out += depth * (-np.exp(-((s + 0.35) / 0.3) ** 2) + 0.7 * np.exp(-((s - 0.4) / 0.3) ** 2))
    return out


def render_second_track(scene: SecondTrackScene) -> tuple[np.ndarray, dict]:
    """A grey top view (JPEG-decoded) and its truth."""
    rng = np.random.default_rng(scene.seed)
    u, v = _ground_of_pixels(scene)
    w, h = scene.width_px, scene.height_px
    # sand: speckles of mixed sizes on a ground canvas, 2 px per mm
    res = 2000.0
    u0, v0 = u.min() - 0.01, v.min() - 0.01
    cw, ch = int((u.max() + 0.01 - u0) * res) + 2, int((v.max() + 0.01 - v0) * res) + 2
    canvas = np.full((ch, cw), 0.5, np.float32)
    # some 100 000 speckles, each from its own draws in turn: rng.uniform(lo, hi) is lo + (hi - lo)
    # * rng.random() and rng.normal(m, s) is m + s * rng.standard_normal() (the same numbers),
    # and a scalar rng.random() takes 0.8 us where rng.uniform's argument checks take 2.7 us:
    # this loop was most of the render
    random, standard_normal, circle = rng.random, rng.standard_normal, cv2.circle
    for _ in range(int(0.02 * cw * ch)):
        circle(canvas, (int(cw * random()), int(ch * random())),
               int(np.exp(0.7 + 0.5 * standard_normal())), 0.2 + (0.8 - 0.2) * random(), -1)
    canvas = cv2.GaussianBlur(canvas, (0, 0), 1.0)
    sand = ndimage.map_coordinates(canvas, [(v - v0) * res, (u - u0) * res], order=1)
    across = np.clip((scene.track_width_m / 2 - np.abs(v)) / 0.004, 0, 1)  # inside the track
    grey = 120 + 60 * (sand - 0.5) * (1 - 0.6 * across) - 12 * across
    if scene.marks:
        u_grid = np.linspace(u.min() - 0.01, u.max() + 0.01, 40000)
        prof = _mark_profile(scene, rng, u_grid, u.max() - u.min() + 0.02)
        grey = grey + 55 * np.interp(u, u_grid, prof) * across
    yy, xx = np.mgrid[0:h, 0:w] / max(w, h)
    wave = np.sin(3 * yy + rng.uniform(0, 6)) * np.cos(2 * xx + rng.uniform(0, 6))
    light = 1 + scene.light_unevenness * (0.5 * (xx - 0.5) + 0.3 * wave)
    img = grey * light
    if scene.blur_px:
        img = cv2.GaussianBlur(img, (0, 0), scene.blur_px)
    img = img + scene.noise_std * rng.standard_normal(img.shape)
    ok, enc = cv2.imencode(".jpg", np.clip(np.rint(img), 0, 255).astype(np.uint8),
                           [cv2.IMWRITE_JPEG_QUALITY, scene.jpeg_quality])
    if not ok:
        raise RuntimeError("JPEG encoding failed")
    truth = {"schema": "swtlab.virtual_testbed.second_track_render/1", "scene": asdict(scene),
             "slip": scene.slip, "spacing_m": spacing_m(scene)}
    return cv2.imdecode(enc, cv2.IMREAD_GRAYSCALE), truth


def random_second_track(seed: int, slip: float, size_px: tuple[int, int] = (640, 480)
                        ) -> SecondTrackScene:
    """Random nuisances; the scale keeps 10 or more marks in view at zero slip."""
    rng = np.random.default_rng(seed)
    return SecondTrackScene(width_px=size_px[0], height_px=size_px[1],
                            px_per_m=float(rng.uniform(0.75, 1.1) * size_px[0]), slip=slip,
                            track_angle_deg=float(rng.uniform(0, 180)),
                            perspective=float(rng.uniform(0, 0.015)),
                            perspective_azimuth_deg=float(rng.uniform(0, 360)),
                            erased_fraction=float(rng.uniform(0, 0.15)),
                            smeared_fraction=float(rng.uniform(0, 0.2)),
                            light_unevenness=float(rng.uniform(0.1, 0.4)),
                            noise_std=float(rng.uniform(1, 4)),
                            blur_px=float(rng.uniform(0.3, 1.2)),
                            seed=seed)
