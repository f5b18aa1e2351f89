"""Soil velocity about the axle: world frame, radial/tangential components, profiles per beta.

The camera rides on the sled, so the image shows the soil at ``u_cam = u_world - V``
(``V`` the sled/wheel velocity). The SOFT model (McGill and Concordia) is written in
the bin (world) frame about the axle: the soil far from the wheel is at rest. So
``V`` is estimated as minus the median camera-frame velocity of the soil farthest
from the wheel (the outer 15 % of soil radii), refined by the caller with the fitted
model, and ``u_world = u_cam + V`` is resolved on ``e_r`` (outwards) and ``e_theta``
(``theta`` from the downward vertical towards travel, as in the model).
``beta``: image angle, 0 at the image right, counter-clockwise (``atan2(-dy, dx)``).
"""

from __future__ import annotations

import numpy as np

from softflow.flow_checks import FlowMeasurementError

MIN_WEDGE_FILL = 0.8
MAX_WEDGE_OFFSET = 0.1


def polar_coordinates(shape: tuple[int, int], center_px: tuple[float, float],
                      direction: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Radius (px), beta and theta (rad) of every pixel."""
    h, w = shape
    y, x = np.mgrid[0:h, 0:w].astype(np.float64)
    dx, dy = x - center_px[0], y - center_px[1]
    return np.hypot(dx, dy), np.arctan2(-dy, dx), np.arctan2(direction * dx, dy)


def resolve(velocity_xy: np.ndarray, theta: np.ndarray,
            direction: int) -> tuple[np.ndarray, np.ndarray]:
    """Image-frame (x right, y down) vectors to (radial, tangential) about the axle.

    ``e_r = (sin th, cos th)``, ``e_th = (cos th, -sin th)`` in (travel, down).
    """
    travel, down = direction * velocity_xy[..., 0], velocity_xy[..., 1]
    s, c = np.sin(theta), np.cos(theta)
    return travel * s + down * c, travel * c - down * s


def far_field_velocity(velocity_xy: np.ndarray, radius_px: np.ndarray,
                       usable: np.ndarray) -> tuple[np.ndarray, float]:
    """Median camera-frame velocity of the outer 15 % (by radius) of the valid ``usable``
    pixels, and the spread of its x part (IQR / 1.349)."""
    ok = np.isfinite(velocity_xy[..., 0]) & usable
    if ok.sum() < 50:
        raise FlowMeasurementError("no far-field soil: fewer than 50 valid flow vectors")
    cut = np.quantile(radius_px[ok], 0.85)
    far = velocity_xy[ok & (radius_px >= cut)]
    q1, q3 = np.percentile(far[:, 0], [25, 75])
    return np.median(far, axis=0), float((q3 - q1) / 1.349)


def beta_bins(width_deg: float = 10.0) -> np.ndarray:
    """Bin centres (rad) covering the circle."""
    return np.deg2rad(np.arange(-180 + width_deg / 2, 180, width_deg))


def group_value_order(values: np.ndarray, groups: np.ndarray) -> np.ndarray:
    """``np.lexsort((values, groups))`` for values without NaN and non-negative integer groups:
    by group, then value, then position. The same permutation in a third of the time
    (lexsort's two stable indirect sorts of 200 000 flow vectors take about 150 ms, and
    :func:`profiles` runs some 40 times per analysis): the values' dense ranks from one
    quicksort, then one quicksort of the distinct int64 keys ``(group, rank, position)``;
    lexsort itself where those keys would not fit in int64."""
    n = values.size
    if n < 2:
        return np.arange(n)
    by_value = np.argsort(values)
    ranked = values[by_value]
    dense = np.r_[0, np.cumsum(ranked[1:] != ranked[:-1])]
    distinct = int(dense[-1]) + 1
    if (int(groups.max()) + 1) * distinct * n >= 2 ** 63:
        return np.lexsort((values, groups))
    rank = np.empty(n, np.int64)
    rank[by_value] = dense
    return np.argsort((groups.astype(np.int64) * distinct + rank) * n + np.arange(n))


def profiles(component: np.ndarray, radius_px: np.ndarray, beta: np.ndarray,
             beta_centres: np.ndarray, width_rad: float, r_min_px: float,
             step_px: float = 2.0) -> list[tuple[np.ndarray, np.ndarray, np.ndarray]]:
    """Per beta bin: (r centres px, median value, standard error) over r bins of ``step_px``.

    Standard error: 1.4826 MAD / sqrt(n / 25), ``n/25`` the number of independent
    vectors (neighbours within a ~5 px flow window are correlated). An r bin is kept only
    where its valid pixels fill the wedge evenly (at least ``MIN_WEDGE_FILL`` of the area
    ``r * step * width``, their mean angle within ``MAX_WEDGE_OFFSET`` of the width from the
    centre): a wedge cut by the image edge, the soil surface or a mask holds one side only,
    and its median is the velocity off the bin centre (on the second renderer's exact field,
    ``k`` 5 % low where the image bottom cut the ray).
    """
    n_bins = len(beta_centres)
    if not np.isclose(n_bins * width_rad, 2 * np.pi):
        raise ValueError(f"{n_bins} beta bins of {np.rad2deg(width_rad):g} deg do not cover "
                         "the circle")
    ok = np.isfinite(component) & (radius_px >= r_min_px)
    r, v, angle = radius_px[ok], component[ok], beta[ok]
    b = np.rint((angle - beta_centres[0]) / width_rad).astype(int) % n_bins
    off = np.angle(np.exp(1j * (angle - beta_centres[b])))
    idx = ((r - r_min_px) // step_px).astype(int)
    rows = int(idx.max()) + 1 if len(idx) else 1
    key = b * rows + idx  # one group per (beta bin, r bin), sorted by value within it
    order = group_value_order(v, key)
    key, v, off = key[order], v[order], off[order]
    starts = np.flatnonzero(np.r_[True, key[1:] != key[:-1]]) if len(key) else np.empty(0, int)
    n = np.diff(np.r_[starts, len(key)])
    lo, hi = starts + (n - 1) // 2, starts + n // 2  # the middle one or two of each group
    med = (v[lo] + v[hi]) / 2
    dev = np.abs(v - np.repeat(med, n))
    dev = dev[group_value_order(dev, key)]
    mad = (dev[lo] + dev[hi]) / 2
    mean_off = np.add.reduceat(off, starts) / n if len(starts) else np.empty(0)
    group_bin, group_r = np.divmod(key[starts], rows)
    rc = r_min_px + (group_r + 0.5) * step_px
    keep = (n >= 10) & (n >= MIN_WEDGE_FILL * rc * step_px * width_rad) \
        & (np.abs(mean_off) <= MAX_WEDGE_OFFSET * width_rad)
    se = 1.4826 * mad / np.sqrt(np.maximum(n / 25, 1)) + 1e-9
    enough = np.bincount(b, minlength=n_bins) >= 50
    out = []
    for j in range(n_bins):
        sel = keep & (group_bin == j) if enough[j] else np.zeros(len(keep), bool)
        out.append((rc[sel], med[sel], se[sel]))
    return out
