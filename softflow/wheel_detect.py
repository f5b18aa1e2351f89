"""The wheel in side-camera frames: axle centre, rim radius, grousers, rotation, mask (item 2).

The soil seen through the glass is a fine grain texture; the wheel is not. A pixel
is "smooth" where the local standard deviation of the high-passed frame is below an
Otsu threshold (on its logarithm); the smooth region that is largest with its holes
filled is the wheel. Its edge along 720 rays gives the centre (algebraic Kasa circle fit
to the edge points near the median radius, i.e. between grousers); that edge lies
3-4 px inside the rim (half the texture window), so the rim radius is the
strongest radial intensity step common to all rays just outside it. Grousers are
found by their uniformity just outside the rim (:func:`_grousers`). Done on every
frame, so a sinking axle is tracked.

Metadata overrides: ``swt.camera`` ``wheel_center_px`` (first frame, then shifted
with the detected motion) and ``wheel_radius_px`` (or ``swt.wheel`` ``radius_m``
times ``px_per_m``), ``swt.wheel`` grouser count and height. An error in ``R``
only scales the fitted amplitudes, not the decay rates.

Angles: ``theta`` from the downward vertical towards the travel direction, the
convention of the SOFT model (:mod:`softflow.grouser_models`).
"""

from __future__ import annotations

from dataclasses import dataclass

import cv2
import numpy as np

from swtlab_base.errors import InputError

N_RAYS = 720
MASK_MARGIN_PX = 8.0  # soil kept this far from the grouser tips (texture window, blur)


@dataclass
class WheelPose:
    """The wheel in one frame, pixels."""

    center_px: tuple[float, float]
    radius_px: float  # rim, without grousers
    grouser_height_px: float  # 0 when no grousers were seen
    grouser_count: int
    grouser_angle_rad: float  # theta of grouser 0 is -grouser_angle_rad (mod pitch)
    soil_angles_rad: np.ndarray | None = None  # image angles of the rays facing the soil


class WheelNotFoundError(InputError, ValueError):
    """No wheel-like smooth region in the frame."""


def _smooth_pixels(gray: np.ndarray, window_px: int) -> np.ndarray:
    f = gray.astype(np.float32)
    high = f - cv2.GaussianBlur(f, (0, 0), 1.5)
    energy = np.sqrt(cv2.blur(high ** 2, (window_px, window_px)))
    log_e = np.log1p(energy)
    scaled = np.clip(255 * (log_e - log_e.min()) / (np.ptp(log_e) + 1e-9), 0, 255).astype(np.uint8)
    thr, _ = cv2.threshold(scaled, 0, 255, cv2.THRESH_BINARY + cv2.THRESH_OTSU)
    return scaled < thr


def smooth_pixels(gray: np.ndarray) -> np.ndarray:
    """Non-textured pixels (7 px window, Otsu), opened by 5 px: wheel, smooth background."""
    return cv2.morphologyEx(_smooth_pixels(gray, 7).astype(np.uint8), cv2.MORPH_OPEN,
                            np.ones((5, 5), np.uint8)).astype(bool)


def _soil_boundary_points(smooth: np.ndarray) -> np.ndarray:
    """(x, y) of smooth pixels with a textured 4-neighbour and soil beyond: textured 6, 12 and
    20 px out along the boundary's normal (so not the edge of a painted ring or tyre band,
    nor where the wheel meets a smooth background)."""
    inner = cv2.erode(smooth.astype(np.uint8), np.array([[0, 1, 0], [1, 1, 1], [0, 1, 0]],
                                                        np.uint8))
    ys, xs = np.nonzero(smooth & ~inner.astype(bool))
    level = cv2.GaussianBlur(smooth.astype(np.float32), (0, 0), 2.0)
    gy, gx = np.gradient(level)
    nx, ny = -gx[ys, xs], -gy[ys, xs]  # towards the textured side
    norm = np.hypot(nx, ny) + 1e-9
    nx, ny = nx / norm, ny / norm
    h, w = smooth.shape
    soil = np.ones(len(xs), bool)
    for d in (6.0, 12.0, 20.0):
        qx = np.clip(np.rint(xs + d * nx).astype(int), 0, w - 1)
        qy = np.clip(np.rint(ys + d * ny).astype(int), 0, h - 1)
        soil &= ~smooth[qy, qx]
    return np.column_stack([xs[soil], ys[soil]]).astype(np.float64)


def _circle_through(p: np.ndarray) -> tuple[float, float, float] | None:
    (x1, y1), (x2, y2), (x3, y3) = p
    d = 2 * (x1 * (y2 - y3) + x2 * (y3 - y1) + x3 * (y1 - y2))
    if abs(d) < 1e-9:
        return None
    s1, s2, s3 = x1 * x1 + y1 * y1, x2 * x2 + y2 * y2, x3 * x3 + y3 * y3
    cx = (s1 * (y2 - y3) + s2 * (y3 - y1) + s3 * (y1 - y2)) / d
    cy = (s1 * (x3 - x2) + s2 * (x1 - x3) + s3 * (x2 - x1)) / d
    return cx, cy, float(np.hypot(x1 - cx, y1 - cy))


def rough_circle(gray: np.ndarray, seed: int = 0) -> tuple[float, float, float, np.ndarray]:
    """Centre, radius and inlier boundary points of the wheel's edge against the soil.

    RANSAC (Fischler & Bolles 1981, Comm. ACM 24) over the boundary of the smooth pixels
    (5 px opening): the circle of radius 8-60 % of the shorter image side, interior at
    least 80 % smooth, that the most boundary points lie within 1.5 px of. The boundary
    also holds the soil surface and whatever smooth lies above it (sky, bin wall, sled
    frame): they are no circle, so they do not take the centre away from the axle. The
    points lie a few pixels inside the rim (texture window): the radius is rough.
    """
    smooth = smooth_pixels(gray)
    pts = _soil_boundary_points(smooth)
    if len(pts) < 30:
        raise WheelNotFoundError("no smooth (non-soil) region in the frame")
    rng = np.random.default_rng(seed)
    if len(pts) > 3000:
        pts = pts[rng.choice(len(pts), 3000, replace=False)]
    h, w = gray.shape
    r_lo, r_hi = 0.08 * min(h, w), 0.6 * min(h, w)
    best, best_n = None, 0
    for _ in range(1500):
        c = _circle_through(pts[rng.choice(len(pts), 3, replace=False)])
        if c is None or not r_lo < c[2] < r_hi:
            continue
        n = int(np.sum(np.abs(np.hypot(pts[:, 0] - c[0], pts[:, 1] - c[1]) - c[2]) < 1.5))
        if n > best_n and _smooth_inside(smooth, c) > 0.8:
            best, best_n = c, n
    if best is None or best_n < 0.15 * 2 * np.pi * best[2]:
        raise WheelNotFoundError("no circular smooth region (wheel) found in the frame")
    near = np.abs(np.hypot(pts[:, 0] - best[0], pts[:, 1] - best[1]) - best[2]) < 2.5
    cx, cy, r = _kasa_circle(pts[near, 0], pts[near, 1])
    return cx, cy, r, pts[near]


def _smooth_inside(smooth: np.ndarray, c: tuple[float, float, float]) -> float:
    """Fraction of smooth pixels on 3 rings inside the circle (those in the frame)."""
    ang = np.linspace(0, 2 * np.pi, 90, endpoint=False)
    x = np.concatenate([c[0] + f * c[2] * np.cos(ang) for f in (0.4, 0.7, 0.9)])
    y = np.concatenate([c[1] + f * c[2] * np.sin(ang) for f in (0.4, 0.7, 0.9)])
    h, w = smooth.shape
    ok = (x >= 0) & (x < w - 1) & (y >= 0) & (y < h - 1)
    if ok.sum() < 90:
        return 0.0
    return float(smooth[np.rint(y[ok]).astype(int), np.rint(x[ok]).astype(int)].mean())


def _kasa_circle(x: np.ndarray, y: np.ndarray) -> tuple[float, float, float]:
    a = np.column_stack([x, y, np.ones_like(x)])
    sol, *_ = np.linalg.lstsq(a, x ** 2 + y ** 2, rcond=None)
    cx, cy = sol[0] / 2, sol[1] / 2
    return float(cx), float(cy), float(np.sqrt(sol[2] + cx ** 2 + cy ** 2))


def _ray_samples(gray: np.ndarray, center: tuple[float, float], radii: np.ndarray,
                 direction: int) -> tuple[np.ndarray, np.ndarray]:
    theta = np.linspace(-np.pi, np.pi, N_RAYS, endpoint=False)
    x = center[0] + direction * np.sin(theta)[:, None] * radii[None, :]
    y = center[1] + np.cos(theta)[:, None] * radii[None, :]
    values = cv2.remap(gray.astype(np.float32), x.astype(np.float32), y.astype(np.float32),
                       cv2.INTER_LINEAR, borderMode=cv2.BORDER_REPLICATE)
    return theta, values


def _profiles_at(image: np.ndarray, center: tuple[float, float], angles: np.ndarray,
                 radii: np.ndarray) -> np.ndarray:
    """Bilinear samples of ``image`` on rays at image angles ``angles`` (atan2(dy, dx))."""
    x = center[0] + np.cos(angles)[:, None] * radii[None, :]
    y = center[1] + np.sin(angles)[:, None] * radii[None, :]
    return cv2.remap(image, x.astype(np.float32), y.astype(np.float32), cv2.INTER_LINEAR,
                     borderMode=cv2.BORDER_REPLICATE)


def _soil_onset(energy: np.ndarray, center, angles, rough_px: float) -> float:
    """Radius where the soil texture starts for good on the soil-facing rays.

    Median over rays of the local texture energy against the radius: just past the last
    radius (before the soil 24 px out) where it is below the midpoint (in log) of the
    wheel's and the soil's levels. A painted ring or tyre band inside the rim is a burst
    followed by quiet again, not the onset.
    """
    radii = np.arange(max(rough_px - 6.0, 2.0), rough_px + 24.0, 0.5)
    prof = np.log(np.median(_profiles_at(energy, center, angles, radii), axis=0) + 1e-3)
    low, high = np.percentile(prof[:8], 50), np.median(prof[-16:])
    below = np.flatnonzero(prof[:-16] <= 0.5 * (low + high))
    return float(radii[below[-1] + 1]) if len(below) else rough_px


def _rim_edges(gray_blur: np.ndarray, center, angles, onset_px: float) -> np.ndarray:
    """Per ray, the innermost intensity step from 1.5 px inside ``onset_px`` to 4.5 px outside:
    the first local peak of ``|dI/dr|`` reaching half the ray's largest there (the edges of
    soil grains beyond the rim can be stronger than the rim's own step), sub-pixel by a
    parabola through it."""
    radii = onset_px + np.arange(-1.5, 4.75, 0.25)
    d = np.abs(np.gradient(_profiles_at(gray_blur, center, angles, radii), axis=1))
    peak = np.zeros_like(d, bool)
    peak[:, 1:-1] = (d[:, 1:-1] >= d[:, :-2]) & (d[:, 1:-1] >= d[:, 2:])
    peak &= d >= 0.5 * d.max(axis=1, keepdims=True)
    i = np.clip(np.argmax(peak, axis=1), 1, len(radii) - 2)
    rows = np.arange(len(angles))
    a, b, c = d[rows, i - 1], d[rows, i], d[rows, i + 1]
    den = a - 2 * b + c
    off = np.where(np.abs(den) > 1e-9, 0.5 * (a - c) / np.where(den == 0, 1, den), 0.0)
    return radii[i] + 0.25 * np.clip(off, -1, 1)


def _fit_rim(gray: np.ndarray, rough: tuple[float, float, float],
             angles: np.ndarray) -> tuple[tuple[float, float], float]:
    """Centre and rim radius from the intensity step on the soil-facing rays ``angles``.

    Coarse radius: :func:`_soil_onset`; then per ray the sub-pixel step near it and a
    circle through those edges, 1.5 px outliers (rays through grousers, soil grains of
    the wheel's grey) rejected; twice, each time about the new centre.
    """
    f = gray.astype(np.float32)
    energy = cv2.blur((f - cv2.GaussianBlur(f, (0, 0), 1.0)) ** 2, (3, 3))
    blur = cv2.GaussianBlur(f, (0, 0), 0.7)
    center, r = (rough[0], rough[1]), rough[2]
    for _ in range(2):
        edge = _rim_edges(blur, center, angles, _soil_onset(energy, center, angles, r))
        x, y = center[0] + np.cos(angles) * edge, center[1] + np.sin(angles) * edge
        keep = np.ones(len(x), bool)
        for _ in range(3):
            cx, cy, rr = _kasa_circle(x[keep], y[keep])
            keep = np.abs(np.hypot(x - cx, y - cy) - rr) < 1.5
            if keep.sum() < 10:
                raise WheelNotFoundError("the wheel's rim is not visible against the soil")
        center, r = (cx, cy), rr
    return center, r


def _facing_soil(theta: np.ndarray, direction: int, soil_angles: np.ndarray | None) -> np.ndarray:
    """Rays (model angle ``theta``) within 1 degree of a soil-facing image angle."""
    if soil_angles is None or not len(soil_angles):
        return np.ones(len(theta), bool)
    bins = 360
    hist = np.zeros(bins, bool)
    hist[np.floor((soil_angles % (2 * np.pi)) / (2 * np.pi) * bins).astype(int) % bins] = True
    hist = hist | np.roll(hist, 1) | np.roll(hist, -1)
    image_angle = np.arctan2(np.cos(theta), direction * np.sin(theta)) % (2 * np.pi)
    return hist[np.floor(image_angle / (2 * np.pi) * bins).astype(int) % bins]


def _grousers(gray: np.ndarray, center: tuple[float, float], rim_px: float,
              direction: int, count: int | None,
              height_px: float | None = None,
              soil_angles: np.ndarray | None = None) -> tuple[int, float, float]:
    """Grouser count, angle and height from rays just outside the rim.

    A grouser is uniform along the ray where the soil is not: the spread of the
    intensity over ``rim + 1.5 .. rim + 4.5`` px (up to the grouser tip when its
    height is known), as a function of ``theta``, dips at
    each grouser; its harmonic at the grouser count (``swt.wheel``, else the strongest
    harmonic when it is four times the median one) gives the phase; only the rays facing
    soil count (above the soil surface a smooth background would dip too). The height is the
    median, over the grousers, of the run from the rim over which the intensity
    stays within 12 grey levels of the grouser's.
    """
    radii = rim_px + np.arange(1.5, max(0.3 * rim_px, 10.0), 0.5)
    theta, values = _ray_samples(gray, center, radii, direction)
    depth = 7 if height_px is None else int(np.clip(2 * (height_px - 2.5), 7, values.shape[1]))
    spread = values[:, :depth].std(axis=1)
    facing = _facing_soil(theta, direction, soil_angles)
    dip = np.where(facing, np.median(spread[facing]) - spread, 0.0)
    spectrum = np.fft.rfft(dip)
    harmonics = np.arange(len(spectrum))
    band = (harmonics >= 3) & (harmonics <= 80)
    if count is None:  # unknown: the strongest harmonic, if clearly above the others
        count = int(harmonics[band][np.argmax(np.abs(spectrum[band]))])
        if np.abs(spectrum[count]) < 4.0 * np.median(np.abs(spectrum[band])):
            return 0, 0.0, 0.0
    if count == 0:
        return 0, 0.0, 0.0
    # dip ~ cos(n (theta - theta_g0)); theta starts at -pi.
    theta_g0 = -np.angle(spectrum[count] * np.exp(-1j * count * np.pi)) / count
    at = np.round((theta_g0 + 2 * np.pi * np.arange(count) / count + np.pi) % (2 * np.pi)
                  / (2 * np.pi) * N_RAYS).astype(int) % N_RAYS
    prof = values[at]
    close = np.abs(prof - np.median(prof[:, :3], axis=1, keepdims=True)) < 12
    run = np.argmin(np.concatenate([close, np.zeros((count, 1), bool)], axis=1), axis=1)
    height = float(np.median(radii[np.maximum(run - 1, 0)]) - rim_px + 0.5)
    return count, float((-theta_g0) % (2 * np.pi / count)), height


def detect_wheel(gray: np.ndarray, direction: int = 1, grouser_count: int | None = None,
                 radius_px: float | None = None, grouser_height_px: float | None = None,
                 prior: WheelPose | None = None) -> WheelPose:
    """Find the wheel in one grey frame (``direction``: +1 travel to the image right).

    ``prior`` (the previous frame's pose) replaces the RANSAC search: the rim is refit
    on the rays that faced the soil there.
    """
    if prior is None:
        cx, cy, r, pts = rough_circle(gray)
        angles = np.arctan2(pts[:, 1] - cy, pts[:, 0] - cx)
    else:
        (cx, cy), r, angles = prior.center_px, prior.radius_px, prior.soil_angles_rad
    center, rim = _fit_rim(gray, (cx, cy, r), np.sort(angles))
    rim = radius_px or rim
    count, angle, height = _grousers(gray, center, rim, direction, grouser_count,
                                     grouser_height_px, angles)
    return WheelPose(center, rim, height, count, angle, np.sort(angles))


def track_wheel(frames: list[np.ndarray], direction: int = 1,
                center_px: tuple[float, float] | None = None,
                radius_px: float | None = None, grouser_count: int | None = None,
                grouser_height_px: float | None = None) -> list[WheelPose]:
    """Wheel pose in every frame; metadata (centre, radius, grousers), when given, override.

    The grouser angle is unwrapped across frames (a grouser moves less than half a
    pitch between frames) and, from three frames on, replaced by a Theil-Sen line
    through the frames (the wheel turns steadily in the stable phase; one frame's
    bad phase does not count).
    """
    from scipy import stats  # here: reading a stored pose does not need scipy.stats

    poses = []
    for gray in frames:
        try:
            poses.append(detect_wheel(gray, direction, grouser_count, radius_px,
                                      grouser_height_px, poses[-1] if poses else None))
        except WheelNotFoundError:
            if center_px is None or radius_px is None:
                raise
            poses.append(WheelPose(center_px, radius_px, 0.0, 0, 0.0))
    if center_px is not None:
        c0 = np.array(poses[0].center_px)
        for p in poses:
            p.center_px = tuple(np.array(center_px) + np.array(p.center_px) - c0)
    if radius_px is not None:
        for p in poses:
            p.radius_px = float(radius_px)
    counts = [p.grouser_count for p in poses if p.grouser_count]
    if counts:
        n = int(np.bincount(counts).argmax())
        angles = np.array([p.grouser_angle_rad if p.grouser_count == n else np.nan for p in poses])
        angles = np.interp(np.arange(len(poses)), np.flatnonzero(np.isfinite(angles)),
                           angles[np.isfinite(angles)])
        unwrapped = np.unwrap(angles * n) / n
        if len(poses) >= 3:  # steady rotation in the stable phase: robust (Theil-Sen) line
            slope, intercept, _, _ = stats.theilslopes(unwrapped)
            unwrapped = intercept + slope * np.arange(len(poses))
        height = grouser_height_px if grouser_height_px is not None else \
            float(np.median([p.grouser_height_px for p in poses if p.grouser_count == n]))
        for p, a in zip(poses, unwrapped):
            p.grouser_count, p.grouser_angle_rad, p.grouser_height_px = n, float(a), height
    return poses


def soil_mask(shape: tuple[int, int], pose: WheelPose,
              margin_px: float = MASK_MARGIN_PX) -> np.ndarray:
    """True on soil: outside the rim plus grouser ring plus ``margin_px``."""
    h, w = shape
    y, x = np.mgrid[0:h, 0:w]
    r = np.hypot(x - pose.center_px[0], y - pose.center_px[1])
    return r > pose.radius_px + pose.grouser_height_px + margin_px
