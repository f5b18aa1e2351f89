"""Derived signals on the common time base (docs/channels.md "Derived columns", spec slip/sinkage).

Rates come from positions by Savitzky-Golay (local quadratic) differentiation
with a window chosen from the encoder's quantisation step and noise.
"""

from __future__ import annotations

import math

import numpy as np

from swtlab_base.order_stats import median

#: relative error aimed at for a derivative at the stream's typical speed
TARGET_REL_ERROR = 0.01
WINDOW_MIN_S = 0.02
WINDOW_MAX_S = 1.0
POLYORDER = 2
#: slip is NaN where max(r*omega, v) is below this fraction of the reference speed
SLIP_EPS_FRACTION = 0.02


def quantisation_step(x: np.ndarray) -> float:
    """Encoder resolution: the largest q with every recorded level on a lattice of step q.

    Tries q = (smallest level spacing)/k for k = 1..1000; 0.0 when the levels are not
    on a lattice (a continuous signal, or steps far finer than the motion per sample).
    """
    if len(x) < 2:
        return 0.0
    levels = np.sort(x, kind="stable")  # np.unique's levels; an encoder's rising counts are
    levels = levels[np.r_[True, levels[1:] != levels[:-1]]]  # one run for the stable sort
    spacing = np.diff(levels)
    spacing = spacing[spacing > 1e-12 * max(1.0, float(np.abs(levels).max(initial=0.0)))]
    if len(spacing) == 0:
        return 0.0
    spacing = np.unique(np.round(spacing / spacing.min(), 6)) * spacing.min()
    candidates = spacing.min() / np.arange(1, 1001)
    multiples = spacing[:, None] / candidates[None, :]
    on_lattice = np.all(np.abs(multiples - np.round(multiples)) < 1e-4, axis=0)
    return float(candidates[np.argmax(on_lattice)]) if on_lattice.any() else 0.0


def encoder_noise(t_s: np.ndarray, x: np.ndarray) -> dict:
    """Quantisation step, white-noise level and typical speed of a position/angle signal.

    The noise is the robust spread of each sample about the straight line through
    its two neighbours (valid on uneven time stamps).
    """
    noise = 0.0
    if len(x) > 2:
        w = (t_s[1:-1] - t_s[:-2]) / (t_s[2:] - t_s[:-2])
        residual = x[1:-1] - ((1 - w) * x[:-2] + w * x[2:])
        noise = float(1.4826 * median(np.abs(residual - median(residual))) / math.sqrt(1.5))
    duration = float(t_s[-1] - t_s[0]) if len(t_s) > 1 else 0.0
    speed = abs(float(x[-1] - x[0])) / duration if duration > 0 else 0.0
    rate = (len(t_s) - 1) / duration if duration > 0 else None
    return {"quantisation_step": quantisation_step(x), "noise_std": noise,
            "typical_speed": speed, "native_rate_hz": rate}


def choose_window_s(stats: dict) -> float:
    """Window (s) for a slope error of about TARGET_REL_ERROR of the typical speed.

    Noise: a least-squares slope over W seconds of N = W*fs samples with white noise
    sigma has std sqrt(12)*sigma/(W*sqrt(N)); quantisation counts as sigma >= q/sqrt(12).
    Staircase: the quantisation error is not white when the wheel moves about a step
    per sample; it is bounded by q, so the slope error by about q/W, hence W >= q/(eps*v).
    """
    speed, rate = stats["typical_speed"], stats["native_rate_hz"]
    if not speed > 0 or rate is None:
        return WINDOW_MAX_S
    step = stats["quantisation_step"]
    sigma = max(stats["noise_std"], step / math.sqrt(12))
    w_noise = (math.sqrt(12) * sigma / (TARGET_REL_ERROR * speed * math.sqrt(rate))) ** (2 / 3)
    w_steps = step / (TARGET_REL_ERROR * speed)
    w_min = max(WINDOW_MIN_S, 5.0 / rate)
    return float(min(max(w_noise, w_steps, w_min), WINDOW_MAX_S))


def savgol_slopes(y: np.ndarray, window: int, delta: float) -> np.ndarray:
    """First derivative by a local quadratic least-squares fit over ``window`` samples
    (Savitzky & Golay 1964, Anal. Chem. 36:1627); ``len(y) >= window``, window odd.

    Inside, the slope of the quadratic at the centre equals the straight-line slope
    sum(k*y_k)/sum(k^2); the first and last half-windows take the derivative of the
    quadratic fitted to the first or last window at their own positions (scipy's
    ``savgol_filter(..., mode="interp")``).
    """
    half = window // 2
    k = np.arange(-half, half + 1, dtype=float)
    out = np.empty(len(y))
    out[half:len(y) - half] = np.correlate(y, k / np.dot(k, k), mode="valid")
    x = np.arange(window, dtype=float) - half
    basis = np.vander(x, POLYORDER + 1, increasing=True)
    coef = np.linalg.lstsq(basis, np.stack([y[:window], y[-window:]], axis=1), rcond=None)[0]
    slope_at = coef[1][None, :] + 2.0 * coef[2][None, :] * x[:, None]
    out[:half] = slope_at[:half, 0]
    out[len(y) - half:] = slope_at[half + 1:, 1]
    return out / delta


def savgol_derivative(y: np.ndarray, rate_hz: float, window_s: float) -> tuple[np.ndarray, int]:
    """d/dt of a uniformly sampled signal, segment by segment between NaN gaps.

    Segments shorter than the window stay NaN. Returns (derivative, window in samples).
    """
    window = max(int(round(window_s * rate_hz)) | 1, POLYORDER + 3)
    out = np.full(len(y), np.nan)
    finite = np.isfinite(y)
    edges = np.flatnonzero(np.diff(np.r_[0, finite.astype(np.int8), 0]))
    for start, stop in zip(edges[::2], edges[1::2]):
        if stop - start >= window:
            out[start:stop] = savgol_slopes(y[start:stop], window, 1.0 / rate_hz)
    return out, window


def slip(surface_speed_mps: np.ndarray, velocity_mps: np.ndarray, eps_mps: float) -> np.ndarray:
    """Spec slip: (rw - v)/rw driving, (rw - v)/v skid; NaN where both speeds are ~0."""
    denominator = np.fmax(surface_speed_mps, velocity_mps)
    valid = denominator > eps_mps
    out = np.full(len(denominator), np.nan)
    out[valid] = (surface_speed_mps[valid] - velocity_mps[valid]) / denominator[valid]
    return out


def slip_eps(velocity_setpoint_mps: float, surface_speed_mps: np.ndarray,
             velocity_mps: np.ndarray) -> float:
    """Speed below which slip is undefined: a fraction of the set or typical travel speed."""
    reference = velocity_setpoint_mps
    if not reference > 0:
        both = np.fmax(np.abs(surface_speed_mps), np.abs(velocity_mps))
        reference = float(np.nanpercentile(both, 95)) if np.isfinite(both).any() else 0.0
    return SLIP_EPS_FRACTION * reference if reference > 0 else 1e-6


def hub_height_m(angle_rad: np.ndarray, arm_length_m: float, angle_zero_rad: float) -> np.ndarray:
    """Spec: h = arm_length_m * (sin(angle) - sin(angle_zero_rad))."""
    return arm_length_m * (np.sin(angle_rad) - math.sin(angle_zero_rad))


def sinkage_m(hub_height: np.ndarray, fz_n: np.ndarray | None,
              stiffness_n_per_mm: float | None) -> np.ndarray:
    """Spec: z = -h rigid; z = -h - fz/(1000*k) for a flexible wheel (k in N/mm)."""
    if stiffness_n_per_mm is None:
        return -hub_height
    if fz_n is None:
        return np.full(len(hub_height), np.nan)
    return -hub_height - fz_n / (1000.0 * stiffness_n_per_mm)
