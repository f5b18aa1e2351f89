"""Image slip of a run: every ``/camera/track`` photo measured, combined by inverse variance.

The raw-run spec's track photos (top view behind the wheel, scale ``swt.camera_track.px_per_m``)
give slip from the grouser-mark spacing (:func:`measure_track_slip`, RUAG SWT method); the
run's image slip is the inverse-variance mean over its photos, beside the encoder slip.
"""

from __future__ import annotations

from dataclasses import dataclass

import cv2
import numpy as np

from softflow.track_slip import NoPeriodicMarksError, measure_track_slip

TRACK_TOPIC = "/camera/track"


@dataclass(frozen=True)
class RunImageSlip:
    """Combined image slip (None when no photo gave one), its standard error, the spread
    between photos, and why photos were refused."""

    slip: float | None
    slip_se: float | None
    slip_spread: float | None
    photos: int
    used: int
    refusals: tuple[str, ...]


def run_image_slip(run) -> RunImageSlip | None:
    """Image slip of an ``ingest.Run`` with track photos; None when it has none."""
    frames = run.frames.get(TRACK_TOPIC)
    if frames is None or frames.count == 0:
        return None
    if run.metadata.camera_track is None:
        return RunImageSlip(None, None, None, frames.count, 0,
                            ("no swt.camera_track.px_per_m: the photos have no scale",))
    wheel = run.metadata.wheel
    slips, stds, refusals = [], [], []
    for i in range(frames.count):
        image = cv2.imdecode(np.frombuffer(frames.data(i), np.uint8), cv2.IMREAD_GRAYSCALE)
        if image is None:
            refusals.append(f"photo {i}: not a decodable image")
            continue
        try:
            result = measure_track_slip(image, wheel.radius_m, wheel.grouser_count,
                                        px_per_m=run.metadata.camera_track.px_per_m)
        except NoPeriodicMarksError as error:
            refusals.append(f"photo {i}: {error}")
            continue
        slips.append(result.slip)
        stds.append(result.slip_std)
    if not slips:
        return RunImageSlip(None, None, None, frames.count, 0, tuple(refusals))
    weights = 1.0 / np.maximum(np.asarray(stds), 1e-6) ** 2
    slip = float(np.sum(weights * slips) / np.sum(weights))
    return RunImageSlip(slip, float(np.sqrt(1.0 / np.sum(weights))),
                        float(np.std(slips, ddof=1)) if len(slips) > 1 else 0.0,
                        frames.count, len(slips), tuple(refusals))
