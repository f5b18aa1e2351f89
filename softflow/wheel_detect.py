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
from scipy import ndimage, stats

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


class WheelNotFoundError(ValueError):
    """No wheel-like smooth region in the frame."""


def _smooth_pixels(gray: np.ndarray, window_px: int) -> np.ndarray:
    f = gray.astype(np.float32)
    high = f - cv2.GaussianBlur(f, (0, 0), 1.5)
    energy = np.sqrt(cv2.blur(high ** 2, (window_px, window_px)))
    log_e = np.log1p(energy)
    scaled = np.clip(255 * (log_e - log_e.min()) / (np.ptp(log_e) + 1e-9), 0, 255).astype(np.uint8)
    thr, _ = cv2.threshold(scaled, 0, 255, cv2.THRESH_BINARY + cv2.THRESH_OTSU)
    return scaled < thr


def smooth_region(gray: np.ndarray) -> np.ndarray:
    """Boolean mask of the non-textured region (7 px window) that covers most once its
    holes are filled: a painted ring on the wheel can split it into an inner disc and an
    outer annulus, and the annulus, filled, is the whole wheel."""
    smooth = cv2.morphologyEx(_smooth_pixels(gray, 7).astype(np.uint8), cv2.MORPH_OPEN,
                              np.ones((5, 5), np.uint8))
    labels, n = ndimage.label(smooth)
    if n == 0:
        raise WheelNotFoundError("no smooth (non-soil) region in the frame")
    sizes = ndimage.sum(smooth, labels, index=np.arange(1, n + 1))
    best, best_area = None, 0
    for label in 1 + np.flatnonzero(sizes >= 0.1 * sizes.max()):
        filled = ndimage.binary_fill_holes(labels == label)
        if filled.sum() > best_area:
            best, best_area = filled, int(filled.sum())
    return best


def _edge_radii(mask: np.ndarray, center: tuple[float, float], r_max: float,
                direction: int) -> tuple[np.ndarray, np.ndarray]:
    theta = np.linspace(-np.pi, np.pi, N_RAYS, endpoint=False)
    radii = np.arange(1.0, r_max, 0.5)
    x = center[0] + direction * np.sin(theta)[:, None] * radii[None, :]
    y = center[1] + np.cos(theta)[:, None] * radii[None, :]
    inside = cv2.remap(mask.astype(np.float32), x.astype(np.float32), y.astype(np.float32),
                       cv2.INTER_LINEAR, borderValue=0.0) > 0.5
    first_out = np.argmax(~inside, axis=1)
    r_edge = np.where(inside.all(axis=1), np.nan, radii[first_out])
    return theta, r_edge


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


def _refine_rim(gray: np.ndarray, center: tuple[float, float], rough_px: float,
                direction: int) -> float:
    """The rim edge: peak of the median over rays of ``|dI/dr|`` near the smooth region's edge.

    The smooth-region edge lies a few pixels inside the rim (texture window); the
    wheel/soil boundary is the strongest radial step common to all rays.
    """
    radii = rough_px + np.arange(-2.0, 7.0, 0.5)  # the smooth edge lies 3-4 px inside
    _, values = _ray_samples(gray, center, radii, direction)
    step = np.median(np.abs(np.diff(values, axis=1)), axis=0)
    return float(radii[int(np.argmax(step))] + 0.25)  # diff i lies between radii i and i + 1


def _grousers(gray: np.ndarray, center: tuple[float, float], rim_px: float,
              direction: int, count: int | None,
              height_px: float | None = None) -> tuple[int, float, float]:
    """Grouser count, angle and height from rays just outside the rim.

    A grouser is uniform along the ray where the soil is not: the spread of the
    intensity over ``rim + 1.5 .. rim + 4.5`` px (up to the grouser tip when its
    height is known), as a function of ``theta``, dips at
    each grouser; its harmonic at the grouser count (``swt.wheel``, else the strongest
    harmonic when it is four times the median one) gives the phase. The height is the
    median, over the grousers, of the run from the rim over which the intensity
    stays within 12 grey levels of the grouser's.
    """
    radii = rim_px + np.arange(1.5, max(0.3 * rim_px, 10.0), 0.5)
    theta, values = _ray_samples(gray, center, radii, direction)
    depth = 7 if height_px is None else int(np.clip(2 * (height_px - 2.5), 7, values.shape[1]))
    spread = values[:, :depth].std(axis=1)
    dip = np.median(spread) - spread
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
                 radius_px: float | None = None,
                 grouser_height_px: float | None = None) -> WheelPose:
    """Find the wheel in one grey frame (``direction``: +1 travel to the image right)."""
    mask = smooth_region(gray)
    ys, xs = np.nonzero(mask)
    center = (float(xs.mean()), float(ys.mean()))
    r_max = float(np.hypot(*gray.shape))
    for _ in range(2):
        theta, r_edge = _edge_radii(mask, center, r_max, direction)
        ok = np.isfinite(r_edge)
        if ok.sum() < N_RAYS // 4:
            raise WheelNotFoundError("the wheel's edge is not visible")
        rim = np.nanmedian(r_edge)
        near = ok & (np.abs(r_edge - rim) < 2.5)
        px = center[0] + direction * np.sin(theta[near]) * r_edge[near]
        py = center[1] + np.cos(theta[near]) * r_edge[near]
        cx, cy, _ = _kasa_circle(px, py)
        center = (cx, cy)
    theta, r_edge = _edge_radii(mask, center, r_max, direction)
    rim = radius_px or _refine_rim(gray, center, float(np.nanmedian(r_edge)), direction)
    count, angle, height = _grousers(gray, center, rim, direction, grouser_count,
                                     grouser_height_px)
    return WheelPose(center, rim, height, count, angle)


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
    poses = []
    for gray in frames:
        try:
            poses.append(detect_wheel(gray, direction, grouser_count, radius_px,
                                      grouser_height_px))
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
