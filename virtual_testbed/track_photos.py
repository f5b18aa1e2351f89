"""Photos of the wheel track behind the wheel (``/camera/track``), at the run's true slip.

The RUAG track-slip method reads slip from the grouser marks a wheel leaves in its track
(docs/track-slip.md); the testbed renders such a photo with :func:`render_track` (random
but plausible light, rotation, defects) once the run has ended, and writes it as JPEG.
"""

from __future__ import annotations

from dataclasses import dataclass

import cv2
import numpy as np

from virtual_testbed.rig import Wheel
from virtual_testbed.track_render import random_nuisance, render_track

TRACK_TOPIC = "/camera/track"
JPEG_QUALITY = 92
PHOTO_SIZE_PX = (800, 600)


@dataclass(frozen=True)
class TrackPhoto:
    """One encoded photo and when it was taken (ns since run start)."""

    t_ns: int
    data: bytes
    format: str = "jpeg"


def track_photos(slip: float, wheel: Wheel, count: int, px_per_m: float, t_end_ns: int,
                 seed: int) -> list[TrackPhoto]:
    """``count`` photos of the track laid at ``slip``, one second apart after ``t_end_ns``."""
    photos = []
    for i in range(count):
        image, _ = render_track(slip, wheel.radius_m, wheel.grouser_count, wheel.grouser_height_m,
                                px_per_m, seed=seed + i,
                                nuisance=random_nuisance(seed + i, PHOTO_SIZE_PX))
        ok, encoded = cv2.imencode(".jpg", image, [cv2.IMWRITE_JPEG_QUALITY, JPEG_QUALITY])
        if not ok:
            raise RuntimeError("JPEG encoding of a track photo failed")
        photos.append(TrackPhoto(t_end_ns + (i + 1) * 1_000_000_000, encoded.tobytes()))
    return photos


def photo_seed(rng: np.random.Generator) -> int:
    return int(rng.integers(0, 2**31 - 1))
