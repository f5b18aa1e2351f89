"""Side-camera frames of sand flowing under a wheel behind the glass wall, with exact truth.

The soil moves by the SOFT velocity-field wheel/soil model (McGill and Concordia
reduced-gravity single-wheel tests, as quoted in the swtlab issue)::

    v_r(r, th)  = (V . e_r) * exp(-k(beta)  * (r - R_e(th, t)))
    v_th(r, th) = (V . e_th - R*omega) * exp(-alpha3(beta) * (r - R_e(th, t)))

in the bin (world) frame, ``V = (v_x, v_z)`` the wheel's velocity, ``k = alpha1 /
(eps_vol_P + alpha2)`` the radial decay rate. Angles: ``th`` from the downward
vertical, positive towards the travel direction (so ``e_r = (sin th, cos th)`` in
(travel, down) and the issue's formula is recovered for ``v_z = 0``); ``beta`` the
image angle, 0 at the image right, counter-clockwise (image x right, y down, so
``beta = atan2(-dy, dx)``). Grousers enter through the effective radius ``R_e`` of
the issue's models (2), (4), (5), (6), with ``g = cos((th - th1 + omega t) n_G)``.

The camera rides on the sled: in the image the undisturbed soil moves at ``-V``.
Frame ``k`` is ``I_k(x) = T(Q_k(x))``, ``Q_k = Q_{k-1} o phi_{k-1}^-1`` with the one-frame
map ``phi_j(p) = p + u_j(p) dt`` (camera frame, pixels), inverted by fixed-point
iteration (``Q_{k-1}`` is smooth: sampled by cubic spline, errs < 1e-4 px); ``T`` is
a grain texture (Gaussian grains of a few pixels) generated on
a supersampled grid, sampled by cubic spline and box-integrated over each pixel. So the
truth displacement of pair ``(k, k+1)`` at pixel ``x`` of frame ``k`` is exactly
``u_k(x) dt``. Then: the wheel (rim disc with a rotating pattern, grousers) drawn
over with anti-aliased edges, glass-wall smudges (moving with the bin, i.e. at
``-V``), illumination flicker, camera noise. Never imports an estimator.

Self-consistent ``k`` (off by default; ``FlowScene.alpha1_per_m`` and ``alpha2``):
``k(beta) = alpha1 / (eps(beta) + alpha2)`` with ``eps(beta)`` the volumetric strain
(compression positive, logarithmic) that this very field gives to the soil at
``eps_depth_px`` outside the rim: ``d eps / ds = -(div u) / |u|`` integrated (RK4,
closed-form divergence) along the streamline of the steady camera-frame field from
far upstream (``exp(-20)`` of the disturbance left) to the point. ``k`` and ``eps``
depend on each other: solved by Anderson-accelerated fixed-point iteration to 1e-6.
Smooth-wheel, steady scenes only; ``truth`` then holds ``eps_vol_p`` (on
``BETA_GRID``, below the axle), ``alpha1_per_m``, ``alpha2``, ``eps_depth_px``.
"""

from __future__ import annotations

import json
from dataclasses import asdict, dataclass, field, replace
from pathlib import Path

import cv2
import numpy as np
from scipy import ndimage

from swtlab_base.atomic import atomic_file, write_atomically

TRUTH_SCHEMA = "swtlab.virtual_testbed.flow_render/1"
GROUSER_MODELS = ("piecewise", "cosine", "cosine_series", "gear")


def effective_radius_px(theta: np.ndarray, t_s: float, radius_px: float, height_px: float,
                        count: int, model: str | None, theta1: float = 0.0,
                        omega_radps: float = 0.0, gamma: float = 3.0) -> np.ndarray:
    """``R_e(theta, t)`` of the issue's grouser models (2), (4), (5), (6); ``None``: ``R``."""
    if model is None or count == 0 or height_px == 0:
        return np.full_like(theta, radius_px)
    c = np.cos((theta - theta1 + omega_radps * t_s) * count)
    if model == "piecewise":
        return radius_px + height_px * np.maximum(c, 0.0)
    if model == "cosine":
        return radius_px + height_px / 2 * (1 + c)
    if model == "cosine_series":
        return radius_px + height_px / 2 * (1 + 1.5 * c - 0.5 * c ** 3)
    if model == "gear":
        return radius_px + height_px / 2 * (1 + np.tanh(gamma * c))
    raise ValueError(f"unknown grouser model {model!r}; known: {GROUSER_MODELS}")


def default_radial_decay_per_m(beta: np.ndarray) -> np.ndarray:
    """k(beta) = alpha1/(eps+alpha2), 1/m: faster decay ahead of the wheel than behind."""
    return 45.0 * (1 + 0.25 * np.cos(beta + np.pi / 2 - 0.6))


def default_tangential_decay_per_m(beta: np.ndarray) -> np.ndarray:
    """alpha3(beta), 1/m."""
    return 60.0 * (1 + 0.2 * np.sin(2 * beta))


@dataclass(frozen=True)
class FlowScene:
    """Scene, wheel, soil model and nuisances; the defaults give a 512 px smooth-wheel scene."""

    size_px: tuple[int, int] = (512, 512)  # width, height
    px_per_m: float = 1000.0
    fps: float = 25.0
    wheel_center_px: tuple[float, float] = (256.0, 150.0)  # frame 0
    wheel_radius_px: float = 100.0  # rim, without grousers
    sink_px_per_frame: float = 0.0  # the axle moves down in the image as the wheel sinks
    velocity_mps: float = 0.05  # v_x, wheel (and sled) speed
    sink_velocity_mps: float = 0.0  # v_z of the model, positive down
    slip: float = 0.2  # R omega = v_x / (1 - slip)
    travel_direction: int = 1  # +1: travels to the image right
    grouser_count: int = 0
    grouser_height_px: float = 0.0
    grouser_thickness_px: float = 6.0
    grouser_model: str | None = None  # effective radius of the soil model
    grouser_theta1: float = 0.0
    grouser_gamma: float = 3.0
    radial_decay_per_m: tuple[float, ...] = ()  # empty: default_radial_decay_per_m at BETA_GRID
    tangential_decay_per_m: tuple[float, ...] = ()
    grain_px: float = 3.0  # typical grain diameter
    grain_density_per_px2: float = 0.12
    supersample: int = 4
    noise_std: float = 2.0  # grey levels
    flicker: float = 0.02  # relative standard deviation of the illumination, frame to frame
    smudges: int = 6  # blurry glass-wall smudges
    seed: int = 0
    alpha1_per_m: float | None = None  # set both: k(beta) = alpha1 / (eps(beta) + alpha2)
    alpha2: float | None = None
    eps_depth_px: float | None = None  # where eps(beta) is taken, outside the rim; None: R / 5

    @property
    def omega_radps(self) -> float:
        return self.velocity_mps / (1 - self.slip) / (self.wheel_radius_px / self.px_per_m)


BETA_GRID = np.linspace(-np.pi, np.pi, 73)  # where tabulated decays are given


def _decay(table: tuple[float, ...], default, beta: np.ndarray) -> np.ndarray:
    if not table:
        return default(beta)
    values = np.asarray(table, float)
    return np.interp(beta, BETA_GRID, values, period=2 * np.pi)


@dataclass
class FlowRender:
    """Frames (uint8) and their truth: per-pair displacement fields in pixels, camera frame."""

    scene: FlowScene
    frames: list[np.ndarray]
    t_s: np.ndarray
    displacement_px: np.ndarray  # (pairs, H, W, 2): (dx, dy) of pair (k, k+1) at frame-k pixels
    soil_mask: np.ndarray  # (pairs, H, W) bool: soil visible in both frames of the pair
    wheel_center_px: np.ndarray  # (frames, 2)
    grouser_angle_rad: np.ndarray  # (frames,) wheel angle of grouser 0, from the bottom
    truth: dict = field(default_factory=dict)


def _soil_velocity_px_per_frame(x: np.ndarray, y: np.ndarray, scene: FlowScene, t_s: float,
                                center: tuple[float, float]) -> tuple[np.ndarray, np.ndarray]:
    """Camera-frame soil velocity (px/frame) of the model at image points (x, y)."""
    d = scene.travel_direction
    dx, dy = x - center[0], y - center[1]
    r = np.hypot(dx, dy)
    beta = np.arctan2(-dy, dx)
    theta = np.arctan2(d * dx, dy)  # from the downward vertical towards travel
    radius_m = scene.wheel_radius_px / scene.px_per_m
    r_e = effective_radius_px(theta, t_s, scene.wheel_radius_px, scene.grouser_height_px,
                              scene.grouser_count, scene.grouser_model, scene.grouser_theta1,
                              scene.omega_radps, scene.grouser_gamma)
    depth_m = np.maximum(r - r_e, 0.0) / scene.px_per_m  # inside: the rim value continues
    k = _decay(scene.radial_decay_per_m, default_radial_decay_per_m, beta)
    a3 = _decay(scene.tangential_decay_per_m, default_tangential_decay_per_m, beta)
    vx, vz = scene.velocity_mps, scene.sink_velocity_mps
    s, c = np.sin(theta), np.cos(theta)
    v_r = (vx * s + vz * c) * np.exp(-k * depth_m)
    v_t = (vx * c - vz * s - radius_m * scene.omega_radps) * np.exp(-a3 * depth_m)
    # e_r = (s, c), e_th = (c, -s) in (travel, down); image x = d * travel.
    u_travel = v_r * s + v_t * c - vx
    u_down = v_r * c - v_t * s - vz
    scale = scene.px_per_m / scene.fps
    return d * u_travel * scale, u_down * scale


def _soil_divergence_per_frame(x: np.ndarray, y: np.ndarray, scene: FlowScene,
                               center: tuple[float, float]) -> np.ndarray:
    """Closed-form ``div u`` (1/frame) of the smooth-wheel model field (0 inside the rim,
    where the field is the rim's: ``u = -R omega e_th``).

    ``div = (1/r) d(r v_r)/dr + (1/r) d(v_th)/d(th)`` with ``v_r = A exp(-k rho)``,
    ``v_th = B exp(-alpha3 rho)``, ``A = V . e_r``, ``B = V . e_th - R omega``, ``dB/dth = -A``.
    """
    d = scene.travel_direction
    dx, dy = x - center[0], y - center[1]
    r = np.hypot(dx, dy)
    beta = np.arctan2(-dy, dx)
    theta = np.arctan2(d * dx, dy)
    rho = np.maximum(r - scene.wheel_radius_px, 0.0)
    k = _decay(scene.radial_decay_per_m, default_radial_decay_per_m, beta) / scene.px_per_m
    a3 = _decay(scene.tangential_decay_per_m, default_tangential_decay_per_m, beta) / scene.px_per_m
    h = 1e-6  # d alpha3 / d theta = direction * d alpha3 / d beta, central difference
    da3 = d * (_decay(scene.tangential_decay_per_m, default_tangential_decay_per_m, beta + h)
               - _decay(scene.tangential_decay_per_m, default_tangential_decay_per_m, beta - h)
               ) / (2 * h * scene.px_per_m)
    scale = scene.px_per_m / scene.fps
    vx, vz = scene.velocity_mps * scale, scene.sink_velocity_mps * scale
    rim_speed = scene.wheel_radius_px / scene.px_per_m * scene.omega_radps * scale
    s, c = np.sin(theta), np.cos(theta)
    a, b = vx * s + vz * c, vx * c - vz * s - rim_speed
    div = a * np.exp(-k * rho) * (1 / r - k) - (a + b * rho * da3) * np.exp(-a3 * rho) / r
    return np.where(r > scene.wheel_radius_px, div, 0.0)


def volumetric_strain_truth(scene: FlowScene, depth_px: float, beta: np.ndarray,
                            step_px: float = 1.0) -> np.ndarray:
    """``eps`` at ``depth_px`` outside the rim at image angles ``beta`` (steady field, t = 0).

    RK4 upstream along ``-u/|u|`` of ``(x, y, eps)`` with ``d eps/ds = -div u / |u|``,
    steps of ``step_px`` growing as ``rho / 20`` away from the rim (the field varies on
    the scale ``rho`` there; quartering either changes eps by < 1e-4), until the
    disturbance has decayed to ``exp(-20)`` (``rho > 20 / min(k, alpha3)``).
    """
    c = scene.wheel_center_px
    grid = BETA_GRID[:-1]
    rates = np.concatenate([_decay(scene.radial_decay_per_m, default_radial_decay_per_m, grid),
                            _decay(scene.tangential_decay_per_m, default_tangential_decay_per_m,
                                   grid)])
    rho_far = 20 / rates.min() * scene.px_per_m
    r0 = scene.wheel_radius_px + depth_px
    state = np.stack([c[0] + r0 * np.cos(beta), c[1] - r0 * np.sin(beta), np.zeros_like(beta)])

    def slope(p):
        ux, uy = _soil_velocity_px_per_frame(p[0], p[1], scene, 0.0, c)
        speed = np.hypot(ux, uy)
        return np.stack([-ux, -uy, -_soil_divergence_per_frame(p[0], p[1], scene, c)]) / speed

    eps = np.full(len(beta), np.nan)
    active = np.arange(len(beta))
    rho = np.full(len(beta), float(depth_px))
    for _ in range(int(20 * (r0 + rho_far) / step_px)):
        p = state[:, active]
        h = np.maximum(step_px, rho[active] / 20)
        k1 = slope(p)
        k2 = slope(p + h / 2 * k1)
        k3 = slope(p + h / 2 * k2)
        k4 = slope(p + h * k3)
        p = p + h / 6 * (k1 + 2 * k2 + 2 * k3 + k4)
        state[:, active] = p
        rho[active] = np.hypot(p[0] - c[0], p[1] - c[1]) - scene.wheel_radius_px
        far = rho[active] > rho_far
        eps[active[far]] = p[2][far]
        active = active[~far]
        if not len(active):
            break
    return eps


def _self_consistent_scene(scene: FlowScene) -> tuple[FlowScene, dict]:
    """The scene with ``k = alpha1 / (eps + alpha2)`` tabulated, and the strain truth.

    ``eps`` is traced below the axle (``beta <= 0``, where a bin has soil); above it
    (soil only in this scene) ``eps`` is interpolated linearly across ``beta``.
    """
    if scene.alpha2 is None or scene.radial_decay_per_m or scene.grouser_model \
            or scene.sink_px_per_frame:
        raise ValueError("alpha1_per_m needs alpha2, no radial_decay_per_m table, no grouser "
                         "soil model and no sink_px_per_frame (a steady smooth-wheel field)")
    depth = scene.wheel_radius_px / 5 if scene.eps_depth_px is None else scene.eps_depth_px
    a1, a2 = scene.alpha1_per_m, scene.alpha2
    below = BETA_GRID <= 0
    k = default_radial_decay_per_m(BETA_GRID)
    tried, images = [], []  # Anderson acceleration, depth 3 (Walker & Ni 2011, SIAM JNA 49)
    for _ in range(60):
        eps = volumetric_strain_truth(replace(scene, radial_decay_per_m=tuple(k)), depth,
                                      BETA_GRID[below])
        filled = np.interp(BETA_GRID, BETA_GRID[below], eps, period=2 * np.pi)
        if not np.all(filled + a2 > 0):  # also False where a streamline never got far
            raise ValueError(f"eps + alpha2 must be > 0 (eps from {np.nanmin(eps):.3f}): "
                             "choose a larger alpha2")
        g = a1 / (filled + a2)
        residual = float(np.max(np.abs(g - k) / k))
        if residual < 1e-6:
            break
        tried, images = (tried + [k])[-4:], (images + [g])[-4:]
        f = np.array(images) - np.array(tried)
        gamma = np.linalg.lstsq(np.diff(f, axis=0).T, f[-1], rcond=None)[0]
        k = g - np.diff(images, axis=0).T @ gamma
        if np.any(k <= 0):
            k = g
    truth = {"alpha1_per_m": a1, "alpha2": a2, "eps_depth_px": depth,
             "eps_vol_p": [float(e) if b else None for e, b in zip(filled, below)],
             "eps_vol_p_definition": "logarithmic volumetric strain, compression positive, "
                                     "accumulated along the camera-frame streamline from far "
                                     "upstream to eps_depth_px outside the rim, beta <= 0",
             "eps_fixed_point_residual": residual}
    return replace(scene, radial_decay_per_m=tuple(k)), truth


def _texture(scene: FlowScene, rng: np.random.Generator, margin_px: int) -> np.ndarray:
    """Grain texture on the supersampled grid covering the frame plus ``margin_px`` around."""
    w, h = scene.size_px
    s = scene.supersample
    hh, ww = (h + 2 * margin_px) * s, (w + 2 * margin_px) * s
    tex = np.zeros((hh, ww), np.float32)
    n = int(scene.grain_density_per_px2 * (h + 2 * margin_px) * (w + 2 * margin_px))
    for size_factor in (0.7, 1.0, 1.4):  # three grain size classes
        cells = rng.integers(0, hh * ww, n // 3)
        layer = np.bincount(cells, rng.uniform(0.3, 1.0, n // 3), minlength=hh * ww)
        layer = layer.reshape(hh, ww).astype(np.float32)
        sigma = scene.grain_px * size_factor * s / 4
        tex += cv2.GaussianBlur(layer, (0, 0), sigma) * (2 * np.pi * sigma ** 2)
    return tex


def _sample(field_px: np.ndarray, x: np.ndarray, y: np.ndarray) -> np.ndarray:
    """Cubic-spline sample of a smooth per-pixel map, extrapolated linearly beyond the frame.

    scipy, not ``cv2.remap``: OpenCV quantises sample positions to 1/32 pixel (and
    its cubic remap of float64 data is off by ~0.05 px), far too coarse for a truth.
    """
    h, w = field_px.shape
    xc, yc = np.clip(x, 0, w - 1), np.clip(y, 0, h - 1)
    inner = ndimage.map_coordinates(field_px, [yc, xc], order=3, mode="nearest")
    gy, gx = np.gradient(field_px)
    ex = ndimage.map_coordinates(gx, [yc, xc], order=1, mode="nearest")
    ey = ndimage.map_coordinates(gy, [yc, xc], order=1, mode="nearest")
    return inner + ex * (x - xc) + ey * (y - yc)


def _upsample(map_px: np.ndarray, xs: np.ndarray, ys: np.ndarray) -> np.ndarray:
    """Bilinear sample of a smooth map on the grid of supersample points ``xs`` (columns) by
    ``ys`` (rows), all within half a pixel of the frame: rows first, then columns (the grid is
    separable, so this is ``ndimage.map_coordinates(order=1)`` at the grid's points).

    The map is padded by one linearly extrapolated pixel; its curvature is < 1e-3
    px/px^2, so bilinear interpolation errs < 1e-4 px.
    """
    padded = np.pad(map_px, 1, mode="reflect", reflect_type="odd")

    def cell(u: np.ndarray, n: int) -> tuple[np.ndarray, np.ndarray]:
        i = np.clip(np.floor(u + 1).astype(np.intp), 0, n - 2)
        return i, u + 1 - i

    iy, fy = cell(ys, padded.shape[0])
    ix, fx = cell(xs, padded.shape[1])
    rows = padded[iy] * (1 - fy)[:, None] + padded[iy + 1] * fy[:, None]
    return rows[:, ix] * (1 - fx) + rows[:, ix + 1] * fx


def _box_down(img: np.ndarray, s: int) -> np.ndarray:
    h, w = img.shape[0] // s, img.shape[1] // s
    return img.reshape(h, s, w, s).mean(axis=(1, 3))


def _wheel_layer(scene: FlowScene, xs: np.ndarray, ys: np.ndarray, center: tuple[float, float],
                 wheel_angle: float) -> tuple[np.ndarray, np.ndarray]:
    """Coverage (0..1) and grey level of wheel and grousers at supersampled points (the grid
    ``xs``, ``ys`` of a meshgrid). Computed only in the box holding the grouser tips: outside
    it the coverage is 0, so the grey level there (70, the wheel's base) is never seen."""
    reach = scene.wheel_radius_px + max(scene.grouser_height_px, 0.0) + 1.0
    cols = np.flatnonzero(np.abs(xs[0] - center[0]) <= reach)
    rows = np.flatnonzero(np.abs(ys[:, 0] - center[1]) <= reach)
    cover = np.zeros(xs.shape, np.float32)
    grey = np.full(xs.shape, 70.0, np.float32)
    if cols.size == 0 or rows.size == 0:
        return cover, grey
    box = np.s_[rows[0]:rows[-1] + 1, cols[0]:cols[-1] + 1]
    dx, dy = xs[box] - center[0], ys[box] - center[1]
    r = np.hypot(dx, dy)
    theta = np.arctan2(scene.travel_direction * dx, dy)
    rim = r <= scene.wheel_radius_px
    phi = theta + wheel_angle  # material angle of the wheel (theta + omega t)
    grey_box = 70 + 25 * np.cos(6 * phi) * (r < 0.8 * scene.wheel_radius_px) \
        + 40 * (np.abs(r - 0.75 * scene.wheel_radius_px) < 3)
    cover_box = rim.astype(np.float32)
    if scene.grouser_count and scene.grouser_height_px > 0:
        pitch = 2 * np.pi / scene.grouser_count
        local = (phi + pitch / 2) % pitch - pitch / 2  # angle to the nearest grouser
        across = r * np.sin(local)
        g = (np.abs(across) <= scene.grouser_thickness_px / 2) & \
            (r <= scene.wheel_radius_px + scene.grouser_height_px) & (np.cos(local) > 0)
        cover_box = np.maximum(cover_box, g.astype(np.float32))
        grey_box = np.where(g & ~rim, 170.0, grey_box)
    cover[box], grey[box] = cover_box, grey_box
    return cover, grey


def render_flow(scene: FlowScene, n_frames: int = 4) -> FlowRender:
    """Render ``n_frames`` consecutive frames and the exact truth of each of their pairs."""
    strain_truth = {}
    if scene.alpha1_per_m is not None:
        scene, strain_truth = _self_consistent_scene(scene)
    rng = np.random.default_rng(scene.seed)
    w, h = scene.size_px
    s = scene.supersample
    dt = 1.0 / scene.fps
    vmax = scene.velocity_mps * 3 * scene.px_per_m * dt
    margin = int(np.ceil(vmax * n_frames + abs(scene.sink_px_per_frame) * n_frames)) + 8
    tex = _texture(scene, rng, margin)
    tex = 40 + 170 * tex / np.percentile(tex, 99.5)
    coeffs = ndimage.spline_filter(tex.astype(np.float64), order=3, mode="mirror")
    # Supersample centres, in frame pixel coordinates (pixel centres at integers).
    off = (np.arange(s) + 0.5) / s - 0.5
    xs = (np.arange(w)[:, None] + off[None, :]).ravel().astype(np.float64)
    ys = (np.arange(h)[:, None] + off[None, :]).ravel().astype(np.float64)
    XS, YS = np.meshgrid(xs, ys)
    px, py = np.meshgrid(np.arange(w, dtype=np.float64), np.arange(h, dtype=np.float64))
    centers = np.array([(scene.wheel_center_px[0], scene.wheel_center_px[1]
                         + scene.sink_px_per_frame * k) for k in range(n_frames)])
    t_s = np.arange(n_frames) * dt
    wheel_angle = scene.omega_radps * t_s  # grousers rotate with the wheel (th - omega t fixed)
    smudge_pts = rng.uniform([0, 0], [w, h], (scene.smudges, 2))
    smudge_amp = rng.uniform(-25, 25, scene.smudges)
    smudge_sig = rng.uniform(15, 50, scene.smudges)
    frames, disp, masks, covers = [], [], [], []
    qx0, qy0 = px.copy(), py.copy()  # texture position of each frame pixel (frame 0: itself)
    for k in range(n_frames):
        if k:
            # the soil's displacement from frame k-1 to k at the pixels (the truth); then
            # Q_k = Q_{k-1} o phi_{k-1}^-1: invert that map by fixed-point iteration starting
            # at the pixels themselves, and sample the (smooth) previous map there, bicubically
            ux, uy = _soil_velocity_px_per_frame(px, py, scene, t_s[k - 1], centers[k - 1])
            disp.append(np.stack([ux, uy], axis=-1).astype(np.float32))
            for _ in range(5):
                ux, uy = _soil_velocity_px_per_frame(px - ux, py - uy, scene, t_s[k - 1],
                                                     centers[k - 1])
            bx, by = px - ux, py - uy
            qx0 = _sample(qx0, bx, by)
            qy0 = _sample(qy0, bx, by)
        qx, qy = _upsample(qx0, xs, ys), _upsample(qy0, xs, ys)
        soil = ndimage.map_coordinates(coeffs, [(qy + margin) * s + (s - 1) / 2,
                                                (qx + margin) * s + (s - 1) / 2],
                                       order=3, prefilter=False, mode="mirror")
        cover, grey = _wheel_layer(scene, XS, YS, centers[k], wheel_angle[k])
        img = _box_down(soil * (1 - cover) + grey * cover, s)
        cover_px = _box_down(cover, s)
        shift = -scene.velocity_mps * scene.px_per_m * dt * k * scene.travel_direction
        for (cx, cy), a, sg in zip(smudge_pts, smudge_amp, smudge_sig):
            img += a * np.exp(-((px - cx - shift) ** 2 + (py - cy) ** 2) / (2 * sg ** 2))
        img *= 1 + scene.flicker * rng.standard_normal()
        img += scene.noise_std * rng.standard_normal(img.shape)
        frames.append(np.clip(np.rint(img), 0, 255).astype(np.uint8))
        covers.append(cover_px)
    for k in range(n_frames - 1):
        masks.append((covers[k] == 0) & (covers[k + 1] == 0))
    render = FlowRender(scene, frames, t_s, np.array(disp), np.array(masks), centers,
                        wheel_angle)
    render.truth = _truth_dict(scene, render) | strain_truth
    return render


def _truth_dict(scene: FlowScene, render: FlowRender) -> dict:
    beta = BETA_GRID
    return {
        "schema": TRUTH_SCHEMA,
        "scene": asdict(scene),
        "omega_radps": scene.omega_radps,
        "t_s": render.t_s.tolist(),
        "wheel_center_px": render.wheel_center_px.tolist(),
        "beta_rad": beta.tolist(),
        "radial_decay_per_m": _decay(scene.radial_decay_per_m, default_radial_decay_per_m,
                                     beta).tolist(),
        "tangential_decay_per_m": _decay(scene.tangential_decay_per_m,
                                         default_tangential_decay_per_m, beta).tolist(),
        "angle_convention": "beta: image angle, 0 at the right, counter-clockwise "
                            "(atan2(-dy, dx)); theta: from the downward vertical towards travel",
        "velocity_frame": "displacement_px: camera (sled) frame, pixels per frame pair",
    }


def write_flow_render(render: FlowRender, folder: str | Path, fmt: str = "png") -> Path:
    """Write ``camera_side/<t_ns>.<fmt>`` (raw-run CSV form), a ``run.json`` holding only the
    ``camera`` and ``wheel`` records (a frames-only folder, not a full run), and the truth apart.

    The truth goes to ``<folder>/flow_truth.json`` and ``flow_truth.npz``
    (``displacement_px``, ``soil_mask``): keep them out of what an estimator reads.
    """
    folder = Path(folder)
    frames_dir = folder / "camera_side"
    frames_dir.mkdir(parents=True, exist_ok=True)
    for img, t in zip(render.frames, render.t_s):
        cv2.imwrite(str(frames_dir / f"{int(round(t * 1e9))}.{fmt}"), img)
    sc = render.scene
    record = {"camera": {"px_per_m": sc.px_per_m,
                         "travel_direction": "+x" if sc.travel_direction > 0 else "-x"},
              "wheel": {"radius_m": sc.wheel_radius_px / sc.px_per_m,
                        "grouser_count": sc.grouser_count,
                        "grouser_height_m": sc.grouser_height_px / sc.px_per_m}}
    write_atomically(folder / "run.json", json.dumps(record, indent=2))
    write_atomically(folder / "flow_truth.json", json.dumps(render.truth, indent=2))
    with atomic_file(folder / "flow_truth.npz", "wb") as stream:
        np.savez_compressed(stream, displacement_px=render.displacement_px,
                            soil_mask=render.soil_mask)
    return frames_dir
