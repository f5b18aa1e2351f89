"""Track slip on the second track renderer (written apart, issue 21): jittered, erased and smeared
marks, uneven light, rotation, keystone, JPEG q80. Nothing was tuned on this renderer; the
seeds 81 000-81 011 are not those of the bench (80 000 on)."""

from __future__ import annotations

import numpy as np
import pytest

from softflow.track_slip import NoPeriodicMarksError, measure_track_slip
from virtual_testbed.second_track_render import (SecondTrackScene, random_second_track,
                                                 render_second_track, spacing_m)


def test_spacing_is_the_rim_circumference_share():
    scene = SecondTrackScene(radius_m=0.125, grousers=12, slip=0.25)
    assert spacing_m(scene) == pytest.approx(2 * np.pi * 0.125 * 0.75 / 12)  # RUAG: d0 (1 - s)


def test_slip_within_half_a_point():
    errors = []
    for i, slip in enumerate(np.linspace(0.0, 0.8, 12)):
        scene = random_second_track(81_000 + i, float(slip))
        image, truth = render_second_track(scene)
        try:
            r = measure_track_slip(image, scene.radius_m, scene.grousers, px_per_m=scene.px_per_m)
            errors.append(abs(r.slip - truth["slip"]))
        except NoPeriodicMarksError:
            errors.append(np.inf)
    errors = np.array(errors)
    assert np.mean(errors <= 0.005) >= 11 / 12, errors  # goal 95 %: at most 1 of 12 off
    assert np.median(errors) < 0.002, errors


@pytest.mark.parametrize("seed", [91_000, 91_001, 91_002])
def test_mark_free_photo_refused(seed):
    image, _ = render_second_track(SecondTrackScene(marks=False, seed=seed,
                                                    track_angle_deg=37.0 * (seed % 5)))
    with pytest.raises(NoPeriodicMarksError):
        measure_track_slip(image, 0.125, 12, px_per_m=700.0)
