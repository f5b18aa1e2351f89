"""Driving slip from a photo of the wheel track: the spacing of the grouser marks.

Method of the RUAG single-wheel tests (ESA ExoMars wheel testing): with ``n``
equally spaced grousers the theoretical grouser distance is ``d = 2*pi*r/n``; the
marks in the track lie ``d*(1 - s)`` apart, so ``s = 1 - d_track*n/(2*pi*r)``.
``r`` is the radius WITHOUT grousers, the one that defines the encoder slip (raw-run
spec): the mark spacing is the hub travel per grouser pitch, ``(v/omega)*2*pi/n``,
whatever the grouser height (docs/track-slip.md shows it with the renderer). A braked
wheel (marks farther apart than ``2*pi*r/n``) gets the spec's skid ``(r*omega - v)/v``.
The spacing is measured over the whole visible track with sub-pixel precision.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass
from pathlib import Path

import cv2
import numpy as np

from softflow import track_period, track_profile
from swtlab_base.errors import InputError

MIN_MARKS = 5  # marks needed for a spacing
MIN_FOUND_FRACTION = 0.5  # of the one-period windows along the visible track
ANGLE_REFINEMENTS = 4
MIN_COHERENCE = 0.85  # |sum of row amplitudes| / sum of |row amplitudes| across the band
MAX_RESIDUAL = 0.12  # RMS of mark positions about the line, fraction of the spacing


class NoPeriodicMarksError(InputError, ValueError):
    """The image shows no significant periodic grouser marks: no slip is given."""

    def __init__(self, detail: str = ""):
        super().__init__("no periodic grouser marks found" + (f" ({detail})" if detail else ""))


@dataclass(frozen=True)
class TrackSlipResult:
    """Slip from the track; angles in degrees in the image (x right, y down), in [0, 180)."""

    slip: float
    slip_std: float
    spacing_m: float  # mean mark spacing in the track
    spacing_std_m: float  # regression standard error, scale uncertainty included
    theoretical_spacing_m: float  # 2*pi*r/n
    marks_used: int
    marks_expected: int  # one-period windows along the visible track
    track_angle_deg: float
    length_m: float  # from the first to the last mark used
    spacing_px: float
    px_per_m: float
    prominence: float  # spectral peak over its neighbourhood's median power

    def to_dict(self) -> dict:
        return asdict(self)


def scale_from_points(points_px, distance_m: float,
                      point_std_px: float = 0.5) -> tuple[float, float]:
    """``px_per_m`` from two image points ``distance_m`` apart, and its relative std
    (each point placed to ``point_std_px``)."""
    (x1, y1), (x2, y2) = np.asarray(points_px, float)
    length_px = float(np.hypot(x2 - x1, y2 - y1))
    if length_px <= 0 or distance_m <= 0:
        raise ValueError("scale points must be distinct and their distance > 0")
    return length_px / distance_m, np.sqrt(2) * point_std_px / length_px


def slip_from_spacing(spacing_m: float, theoretical_m: float,
                      spacing_rel_std: float = 0.0) -> tuple[float, float]:
    """Slip and its std from the mark spacing (raw-run spec): driving ``1 - d/d0`` while the
    marks are closer than ``d0 = 2*pi*r/n`` (r*omega > v), skid ``d0/d - 1`` beyond."""
    ratio = spacing_m / theoretical_m
    if ratio <= 1:
        return float(1 - ratio), float(ratio * spacing_rel_std)
    return float(1 / ratio - 1), float(spacing_rel_std / ratio)


def _gray(image) -> np.ndarray:
    if isinstance(image, (str, Path)):
        try:
            data = np.fromfile(image, np.uint8)
        except OSError as exc:
            raise OSError(f"{image}: {exc.strerror or exc}") from None
        img = cv2.imdecode(data, cv2.IMREAD_GRAYSCALE) if data.size else None
        if img is None:
            raise OSError(f"{image}: not an image file OpenCV can read")
        image = img
    image = np.asarray(image)
    if image.ndim == 3:
        image = cv2.cvtColor(image[..., :3].astype(np.float32), cv2.COLOR_BGR2GRAY)
    if image.ndim != 2 or min(image.shape) < 32:
        raise ValueError("expected a grey or colour image of at least 32 x 32 pixels")
    return image.astype(np.float32)


def _measure_direction(gray, angle_rad, freqs_px, min_period_px, max_period_px, reference_px):
    """Mark fit along one candidate direction, refined: (fit, prominence, direction) or the
    reason it failed. ``freqs_px`` are candidate frequencies (cycles/px): the one whose band
    of rows carries its pattern with the best signal-to-noise ratio leads.
    ``reference_px`` is the image point (from the centre) where the scale applies."""
    step = track_profile.STEP_PX
    min_period, max_period = min_period_px / step, max_period_px / step
    strip = track_profile.resample(gray, angle_rad)
    bands = [(*track_profile.find_band(strip, f * step, 4 / (f * step)), f * step)
             for f in freqs_px]
    lo, hi, _, freq = max(bands, key=lambda band: band[2])
    for refinement in range(ANGLE_REFINEMENTS + 1):
        if refinement:
            lo, hi, _ = track_profile.find_band(strip, freq, min_len=4 / freq)
        if hi - lo < 3:
            return "no band of marks"
        slope = track_profile.shear_slope(strip, lo, hi, freq)
        if abs(slope) < 0.005 or refinement == ANGLE_REFINEMENTS:
            break
        angle_rad -= np.arctan(slope)
        strip = track_profile.resample(gray, angle_rad)
    profile, first = track_profile.band_profile(strip, lo, hi)
    if profile.size < 4 * min_period:
        return "no band of marks"
    freq, prominence = track_period.fundamental(profile, min_period, max_period)
    if prominence < track_period.MIN_PROMINENCE:
        return f"spectral peak only {prominence:.0f} x background"
    if profile.size * freq < 4:
        return "fewer than 4 periods visible"
    coherence = track_profile.coherence(strip, lo, hi, freq)
    if coherence < MIN_COHERENCE:
        return f"pattern not aligned across the track (coherence {coherence:.2f})"
    along_px = reference_px @ np.array([np.cos(angle_rad), np.sin(angle_rad)])
    fit = track_period.fit_marks(profile, 1 / freq,
                                 (along_px - strip.along_start_px) / step - first)
    used = fit.indices.size
    if used < MIN_MARKS or used < MIN_FOUND_FRACTION * fit.windows:
        return f"{used} of {fit.windows} marks matched"
    if fit.residual_rms > MAX_RESIDUAL * fit.spacing:
        return "marks not evenly spaced"
    return fit, prominence, angle_rad


def _relative_se(fit: track_period.MarkFit) -> float:
    return fit.spacing_se / fit.spacing


def measure_track_slip(image, radius_m: float, grouser_count: int, px_per_m: float | None = None,
                       scale_points=None, scale_distance_m: float | None = None,
                       point_std_px: float = 0.5, min_period_px: float = 5.0) -> TrackSlipResult:
    """Slip from a top view of the track (array or image file).

    The scale is ``px_per_m`` (taken as the scale at the image centre) or two image points
    ``scale_points`` ``scale_distance_m`` apart (the scale at their midpoint). The spacing
    is measured where that scale applies: a mild perspective changes it along the track.
    Raises :class:`NoPeriodicMarksError` when no significant periodic marks are found.
    """
    if radius_m <= 0 or grouser_count < 1:
        raise ValueError("radius_m must be > 0 and grouser_count >= 1")
    if (px_per_m is None) == (scale_points is None):
        raise ValueError("give either px_per_m or scale_points with scale_distance_m")
    if px_per_m is not None:
        if px_per_m <= 0:
            raise ValueError("px_per_m must be > 0")
        scale_rel_std = 0.0
    else:
        if scale_distance_m is None:
            raise ValueError("scale_points need scale_distance_m")
        px_per_m, scale_rel_std = scale_from_points(scale_points, scale_distance_m, point_std_px)
    gray = _gray(image)
    centre = (np.array(gray.shape[::-1]) - 1) / 2
    reference_px = (np.zeros(2) if scale_points is None
                    else np.asarray(scale_points, float).mean(axis=0) - centre)
    max_period_px = max(gray.shape) / 4
    best, reasons = None, []
    for angle, freqs in track_profile.direction_candidates(gray, min_period_px, max_period_px):
        found = _measure_direction(gray, angle, freqs, min_period_px, max_period_px, reference_px)
        if isinstance(found, str):
            reasons.append(found)
        elif best is None or _relative_se(found[0]) < _relative_se(best[0]):
            best = found  # the most precise spacing among the directions that pass
    if best is None:
        raise NoPeriodicMarksError("; ".join(dict.fromkeys(reasons)))
    fit, prominence, angle = best
    step = track_profile.STEP_PX
    spacing_px = fit.spacing * step
    spacing_m = spacing_px / px_per_m
    spacing_rel_std = float(np.hypot(fit.spacing_se / fit.spacing, scale_rel_std))
    theoretical_m = 2 * np.pi * radius_m / grouser_count
    slip, slip_std = slip_from_spacing(spacing_m, theoretical_m, spacing_rel_std)
    return TrackSlipResult(
        slip=slip, slip_std=slip_std,
        spacing_m=float(spacing_m), spacing_std_m=float(spacing_m * spacing_rel_std),
        theoretical_spacing_m=float(theoretical_m), marks_used=int(fit.indices.size),
        marks_expected=int(fit.windows), track_angle_deg=float(np.degrees(angle) % 180),
        length_m=float(np.ptp(fit.positions) * step / px_per_m), spacing_px=float(spacing_px),
        px_per_m=float(px_per_m), prominence=float(prominence))
