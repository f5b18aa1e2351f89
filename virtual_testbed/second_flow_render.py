"""A second side-camera renderer, written apart from ``flow_render`` (no shared code; issue 21).

What differs from the first renderer, on purpose:

- **grains**: opaque ellipses painted over each other (painter's order), log-normal
  sizes (median ``grain_px``, spread 0.45), aspect ratios 1-2.5, orientations
  clustered about ``grain_tilt_deg`` (anisotropic), grey levels uniform;
- **scene**: soil only below ``soil_top_px`` (the free surface); above it a smooth
  "sky" gradient, the bin wall (textured planks fixed in the bin, so moving at ``-V``
  in the image), or the sled frame (a dark bar with bolts, fixed in the camera);
- **imaging**: motion blur along the local soil displacement (exposure ``blur_fraction``
  of the frame interval, 7 samples), glass reflections fixed in the camera (they ride
  with the sled), vignetting, illumination flicker, noise, and JPEG at ``jpeg_quality``.

Soil motion (steady in the camera, smooth wheel, bin frame about the axle; the
SOFT velocity-field model of the McGill/Concordia reduced-gravity tests quoted in
issue 21): ``v_r = V sin(th) exp(-k (r - R))``, ``v_th = (V cos(th) - R w) exp(-a3 (r - R))``,
``th`` from the downward vertical towards travel; in the camera the bin-frame
velocity minus ``V``. The per-frame map is ``p -> p + u(p) dt`` (so ``u dt`` is the
exact pair displacement); frame ``n`` shows the texture at ``phi^-n(x)``, the inverse
map applied ``n`` times (fixed-point iteration, 12 steps, error < 1e-6 px). The decay
laws are this module's own: ``k(th) = k0 (1 + 0.2 sin(th + 0.4))``,
``a3(th) = a0 (1 + 0.15 cos(2 th))``.

Grousers (``grouser_count`` > 0; this module's own kinematics, not the effective-radius
models of the first renderer): ``grouser_count`` straight bars ``grouser_width_px`` wide,
standing ``grouser_height_px`` out of the rim, drawn as uniform grey and turning with the
wheel. The soil between them is carried by the wheel (rigid rotation about the axle, steady
in the camera), and outside the tip circle ``R_t = R + h`` the soil is sheared by the tips:
the laws above with the depth counted from ``R_t`` and the tips' speed ``w R_t`` in place of
``R w`` (slip still defined on the rim, ``R w = V / (1 - slip)``). The two agree at ``R_t``
(both the rigid-body velocity of the wheel there), and at fixed ``th`` the profiles are still
``exp(-rate (r - R))`` with the same rates, only their amplitudes change.
"""

from __future__ import annotations

import json
from dataclasses import asdict, dataclass
from pathlib import Path

import cv2
import numpy as np
from scipy import ndimage

from swtlab_base.atomic import write_atomically

BACKGROUNDS = ("sky", "wall", "frame")


@dataclass(frozen=True)
class SecondScene:
    """One steady smooth-wheel scene of the second renderer."""

    width_px: int = 320
    height_px: int = 256
    px_per_m: float = 1000.0
    fps: float = 20.0
    axle_px: tuple[float, float] = (160.0, 96.0)
    rim_px: float = 72.0
    speed_mps: float = 0.04
    slip: float = 0.3
    direction: int = 1  # +1: travel to the image right
    k0_per_m: float = 50.0
    a30_per_m: float = 65.0
    soil_top_px: float | None = None  # free surface; None: axle + 0.55 R
    background: str = "sky"
    grain_px: float = 3.0
    grain_tilt_deg: float = 30.0
    blur_fraction: float = 0.4
    reflections: int = 3
    vignette: float = 0.3
    flicker: float = 0.02
    noise_std: float = 2.5
    jpeg_quality: int = 80
    supersample: int = 3
    grouser_count: int = 0
    grouser_height_px: float = 0.0
    grouser_width_px: float = 5.0
    grouser_grey: float = 70.0
    seed: int = 0

    @property
    def surface_px(self) -> float:
        return self.axle_px[1] + 0.55 * self.rim_px if self.soil_top_px is None \
            else self.soil_top_px

    @property
    def tip_px(self) -> float:
        """Radius of the grouser tips (the rim without grousers)."""
        return self.rim_px + (self.grouser_height_px if self.grouser_count else 0.0)

    @property
    def omega_radps(self) -> float:
        return self.speed_mps / (1.0 - self.slip) / (self.rim_px / self.px_per_m)


def radial_rate_per_m(scene: SecondScene, theta: np.ndarray) -> np.ndarray:
    return scene.k0_per_m * (1.0 + 0.2 * np.sin(theta + 0.4))


def tangential_rate_per_m(scene: SecondScene, theta: np.ndarray) -> np.ndarray:
    return scene.a30_per_m * (1.0 + 0.15 * np.cos(2.0 * theta))


def camera_velocity_px(scene: SecondScene, x: np.ndarray, y: np.ndarray):
    """Camera-frame soil displacement per frame (px) at image points (x, y)."""
    ex, ey = x - scene.axle_px[0], y - scene.axle_px[1]
    dist = np.sqrt(ex * ex + ey * ey)
    th = np.arctan2(scene.direction * ex, ey)
    depth_m = np.clip(dist - scene.tip_px, 0.0, None) / scene.px_per_m
    v = scene.speed_mps
    # carried by the wheel between the grousers, sheared by the tips outside them
    rim_speed = scene.omega_radps * np.clip(dist, scene.rim_px, scene.tip_px) / scene.px_per_m
    radial = v * np.sin(th) * np.exp(-radial_rate_per_m(scene, th) * depth_m)
    tangential = (v * np.cos(th) - rim_speed) * np.exp(-tangential_rate_per_m(scene, th) * depth_m)
    along = radial * np.sin(th) + tangential * np.cos(th) - v  # along travel
    down = radial * np.cos(th) - tangential * np.sin(th)
    k = scene.px_per_m / scene.fps
    return scene.direction * along * k, down * k


def _inverse_step(scene: SecondScene, x: np.ndarray, y: np.ndarray):
    """``p`` with ``p + u(p) = (x, y)``."""
    px, py = x.copy(), y.copy()
    for _ in range(12):
        ux, uy = camera_velocity_px(scene, px, py)
        px, py = x - ux, y - uy
    return px, py


def _grain_canvas(scene: SecondScene, rng: np.random.Generator, x0: float, y0: float,
                  w: int, h: int, t: int) -> np.ndarray:
    """Painted grains on a canvas of ``t`` texels per pixel covering ``[x0, x0+w) x [y0, y0+h)``."""
    canvas = np.full((h * t, w * t), 0.5, np.float32)
    count = int(0.16 * w * h)
    cx = rng.uniform(0, w * t, count)
    cy = rng.uniform(0, h * t, count)
    size = scene.grain_px * t * np.exp(0.45 * rng.standard_normal(count)) / 2
    aspect = rng.uniform(1.0, 2.5, count)
    tilt = scene.grain_tilt_deg + 25.0 * rng.standard_normal(count)
    grey = rng.uniform(0.1, 1.0, count)
    shift = 4
    for i in range(count):
        a = max(size[i] * np.sqrt(aspect[i]), 0.6)
        b = max(size[i] / np.sqrt(aspect[i]), 0.6)
        cv2.ellipse(canvas, (int(cx[i] * 16), int(cy[i] * 16)), (int(a * 16), int(b * 16)),
                    float(tilt[i]), 0, 360, float(grey[i]), -1, cv2.LINE_AA, shift)
    return cv2.GaussianBlur(canvas, (0, 0), 0.35 * t)  # band limit: 0.35 px


def _wall_pattern(x_world: np.ndarray, y: np.ndarray, rng_phase: np.ndarray) -> np.ndarray:
    """Bin-wall planks: horizontal boards 24 px high with wood grain, 0..1."""
    board = np.floor(y / 24.0)
    grain = 0.5 + 0.2 * np.sin(x_world / 3.1 + 2.0 * np.sin(y / 5.0 + board)) \
        + 0.15 * np.sin(x_world / 1.7 + rng_phase[0] + board * 1.3)
    seam = np.exp(-((y - 24.0 * np.round(y / 24.0)) ** 2) / 2.0)
    return np.clip(grain - 0.4 * seam, 0, 1)


def render_second(scene: SecondScene,
                  n_frames: int = 6) -> tuple[list[np.ndarray], np.ndarray, dict]:
    """Frames (uint8, grey, JPEG-decoded), their times and the truth."""
    if scene.background not in BACKGROUNDS:
        raise ValueError(f"background {scene.background!r}; known: {BACKGROUNDS}")
    rng = np.random.default_rng(scene.seed)
    w, h, s = scene.width_px, scene.height_px, scene.supersample
    t = 4  # texels per pixel of the grain canvas
    travel_px = scene.speed_mps * scene.px_per_m / scene.fps
    reach = int(np.ceil(travel_px * (n_frames + 1) * 2)) + 12
    x0, y0 = -reach, -reach
    cw, ch = w + 2 * reach, h + 2 * reach
    canvas = _grain_canvas(scene, rng, x0, y0, cw, ch, t)
    coeff = ndimage.spline_filter(canvas.astype(np.float64), order=3)
    sub = (np.arange(s) + 0.5) / s - 0.5
    xs = (np.arange(w)[:, None] + sub).ravel()
    ys = (np.arange(h)[:, None] + sub).ravel()
    gx, gy = np.meshgrid(xs, ys)
    ux, uy = camera_velocity_px(scene, gx, gy)
    px, py = np.meshgrid(np.arange(w, dtype=float), np.arange(h, dtype=float))
    # imaging that does not change from frame to frame
    refl = np.zeros((h, w))
    for _ in range(scene.reflections):
        ang, off = rng.uniform(0.3, 1.2), rng.uniform(0, w)
        dist = (px - off) * np.cos(ang) + py * np.sin(ang)
        refl += rng.uniform(12, 30) * np.exp(-dist ** 2 / (2 * rng.uniform(6, 20) ** 2))
    rr = np.hypot(px - w / 2, py - h / 2) / np.hypot(w / 2, h / 2)
    vignette = 1.0 - scene.vignette * rr ** 2
    phase = rng.uniform(0, 2 * np.pi, 1)
    surface = scene.surface_px + 1.5 * np.sin(gx / 37.0 + phase[0])
    ax, ay = scene.axle_px
    dist = np.hypot(gx - ax, gy - ay)
    wheel_cover = np.clip(scene.rim_px - dist + 0.5, 0, 1)
    frames, times = [], np.arange(n_frames) / scene.fps
    qx, qy = gx, gy
    for n in range(n_frames):
        if n:  # phi^-n = phi^-1 applied to phi^-(n-1)
            qx, qy = _inverse_step(scene, qx, qy)
        taps = np.linspace(-0.5, 0.5, 7) * scene.blur_fraction
        soil = np.zeros_like(gx)
        for tau in taps:
            cx = (qx - tau * ux - x0) * t + (t - 1) / 2
            cy = (qy - tau * uy - y0) * t + (t - 1) / 2
            soil += ndimage.map_coordinates(coeff, [cy, cx], order=3, prefilter=False,
                                            mode="nearest")
        soil = 40 + 170 * soil / len(taps)
        above = _background(scene, gx, gy, n * travel_px, phase)
        in_soil = np.clip(gy - surface + 0.5, 0, 1)
        img = above * (1 - in_soil) + soil * in_soil
        angle = scene.omega_radps * times[n]
        img = img * (1 - wheel_cover) + _wheel_grey(scene, gx, gy, angle) * wheel_cover
        bars = _grouser_cover(scene, gx, gy, angle)
        img = img * (1 - bars) + scene.grouser_grey * bars
        img = img.reshape(h, s, w, s).mean(axis=(1, 3))
        img = (img + refl) * vignette * (1 + scene.flicker * rng.standard_normal())
        img += scene.noise_std * rng.standard_normal(img.shape)
        ok, enc = cv2.imencode(".jpg", np.clip(np.rint(img), 0, 255).astype(np.uint8),
                               [cv2.IMWRITE_JPEG_QUALITY, scene.jpeg_quality])
        if not ok:
            raise RuntimeError("JPEG encoding failed")
        frames.append(cv2.imdecode(enc, cv2.IMREAD_GRAYSCALE))
    return frames, times, scene_truth(scene)


def _background(scene: SecondScene, x, y, shift_px: float, phase) -> np.ndarray:
    """Grey level above the free surface."""
    sky = 175 + 25 * (y / scene.height_px) + 8 * np.sin(x / 90.0 + phase[0])
    if scene.background == "sky":
        return sky
    if scene.background == "wall":  # fixed in the bin: moves by -V in the camera
        return 60 + 120 * _wall_pattern(x + scene.direction * shift_px, y, phase)
    bar = (y > 0.15 * scene.height_px) & (y < 0.32 * scene.height_px)  # the sled frame
    bolts = np.hypot((x % 40) - 20, y - 0.235 * scene.height_px) < 4
    return np.where(bar, np.where(bolts, 140.0, 45.0), sky)


def _wheel_grey(scene: SecondScene, x, y, angle: float) -> np.ndarray:
    """A smooth hub: dark tyre band, five soft spokes, turning with the wheel."""
    ex, ey = x - scene.axle_px[0], y - scene.axle_px[1]
    r = np.hypot(ex, ey) / scene.rim_px
    phi = np.arctan2(scene.direction * ex, ey) + angle
    spokes = 15 * np.cos(5 * phi) * (r < 0.7)
    return np.where(r > 0.88, 55.0, 100.0 + spokes)


def _grouser_cover(scene: SecondScene, x, y, angle: float) -> np.ndarray:
    """Coverage 0..1 of the grouser bars (grouser 0 at ``th = -angle``, the wheel turned by
    ``angle``); 0 everywhere without grousers."""
    if not scene.grouser_count:
        return np.zeros_like(x)
    ex, ey = x - scene.axle_px[0], y - scene.axle_px[1]
    dist = np.hypot(ex, ey)
    pitch = 2 * np.pi / scene.grouser_count
    rel = np.arctan2(scene.direction * ex, ey) + angle
    across = dist * np.abs(np.sin(rel - pitch * np.round(rel / pitch)))
    return (np.clip(scene.grouser_width_px / 2 - across + 0.5, 0, 1)
            * np.clip(scene.tip_px - dist + 0.5, 0, 1) * np.clip(dist - scene.rim_px + 1.0, 0, 1))


def scene_truth(scene: SecondScene) -> dict:
    """The truth of a scene (also returned by :func:`render_second`)."""
    beta = np.deg2rad(np.arange(-175.0, 180.0, 10.0))
    theta = np.arctan2(scene.direction * np.cos(beta), -np.sin(beta))
    return {"schema": "swtlab.virtual_testbed.second_flow_render/1", "scene": asdict(scene),
            "wheel_center_px": list(scene.axle_px), "wheel_radius_px": scene.rim_px,
            "sled_velocity_mps": [scene.direction * scene.speed_mps, 0.0],
            "omega_radps": scene.omega_radps, "soil_surface_px": scene.surface_px,
            "grouser_tip_px": scene.tip_px,
            # soil velocity at the tip circle (the rim without grousers), bin frame
            "radial_rim_velocity_mps": (scene.speed_mps * np.sin(theta)).tolist(),
            "tangential_rim_velocity_mps": (scene.speed_mps * np.cos(theta) - scene.omega_radps
                                            * scene.tip_px / scene.px_per_m).tolist(),
            "beta_deg": np.rad2deg(beta).tolist(),
            "radial_decay_per_m": radial_rate_per_m(scene, theta).tolist(),
            "tangential_decay_per_m": tangential_rate_per_m(scene, theta).tolist()}


def write_second(scene: SecondScene, rendered: tuple[list[np.ndarray], np.ndarray, dict],
                 folder: str | Path) -> Path:
    """Frames, times and truth of :func:`render_second` written as ``camera_side/<t_ns>.png``
    (the JPEG-damaged frames, stored losslessly) and a ``run.json`` (scale, direction, no wheel
    hints); the truth to ``second_flow_truth.json``."""
    frames, times, truth = rendered
    folder = Path(folder)
    (folder / "camera_side").mkdir(parents=True, exist_ok=True)
    for img, t_s in zip(frames, times):
        cv2.imwrite(str(folder / "camera_side" / f"{int(round(t_s * 1e9))}.png"), img)
    run = {"camera": {"px_per_m": scene.px_per_m,
                      "travel_direction": "+x" if scene.direction > 0 else "-x"}}
    write_atomically(folder / "run.json", json.dumps(run))
    write_atomically(folder / "second_flow_truth.json", json.dumps(truth, indent=1))
    return folder
