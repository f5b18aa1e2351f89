"""Slip from the grouser marks in a photo of the track, against renders of known slip.

Ground truth comes from the renderer (virtual_testbed.track_render), never from the
estimator. Accuracy target (issue): |slip error| <= 0.5 percentage points for 95 % of
the renders across slip 0-0.8; an image with no periodic marks is refused.
"""

from __future__ import annotations

import json
from dataclasses import replace

import cv2
import numpy as np
import pytest

from softflow.track_slip import NoPeriodicMarksError, TrackSlipResult, measure_track_slip
from virtual_testbed.track_render import (
    TrackNuisance, mark_spacing_m, random_nuisance, render_track, write_track_render)

RADIUS_M, GROUSERS, HEIGHT_M = 0.125, 12, 0.0092  # BB2-like wheel
SIZE_PX = (800, 600)
RENDERS = 20
MAX_OFF = 1  # renders allowed off by more than 0.5 pp (refusals count as off)


def _random_render(i: int):
    """Render ``i`` of the accuracy set: slips evenly over 0-0.8, seeded random nuisances;
    640 x 480 px at 480-720 px/m keeps 10 or more marks in view at zero slip."""
    rng = np.random.default_rng(10_000 + i)
    slip = 0.8 * i / (RENDERS - 1)
    px_per_m = float(rng.uniform(480, 720))
    return render_track(slip, RADIUS_M, GROUSERS, HEIGHT_M, px_per_m, seed=i,
                        nuisance=random_nuisance(20_000 + i, (640, 480)))


@pytest.mark.slow  # 20 track photos rendered and measured
@pytest.mark.slow_render
def test_accuracy_over_20_random_renders():
    """A regression check of the accuracy target; the accuracy record itself is the bench's
    (``python -m bench track_slip --markdown``, docs/validation/track_slip.md).

    Acceptance rule: at most ``MAX_OFF`` = 1 of the 20 renders off by more than 0.5 pp (a
    refusal counts as off), and the median error below 0.1 pp. With the renders drawn
    independently and a true within-0.5-pp rate p, the number off is Binomial(20, 1 - p):
    P(pass | p = 0.80) = 0.8^20 + 20 * 0.2 * 0.8^19 = 0.069 (93 % power to catch a drop to
    80 %), P(fail | p = 0.99) = 1 - 0.99^20 - 20 * 0.01 * 0.99^19 = 0.017 (the target is 95 %;
    the bench measures 98-100 %). The former 50 renders with 95 % (at most 2 off) had
    P(pass | 0.80) = 0.001 and P(fail | 0.99) = 0.014.
    """
    errors_pp, refused = [], 0
    for i in range(RENDERS):
        image, truth = _random_render(i)
        try:
            result = measure_track_slip(image, RADIUS_M, GROUSERS, px_per_m=truth["px_per_m"])
        except NoPeriodicMarksError:
            refused += 1
            errors_pp.append(np.inf)
            continue
        errors_pp.append(100 * abs(result.slip - truth["slip"]))
    errors_pp = np.array(errors_pp)
    off = int(np.sum(errors_pp > 0.5))
    assert off <= MAX_OFF, (f"{off} of {RENDERS} off by more than 0.5 pp, {refused} refused, "
                            f"errors {np.round(np.sort(errors_pp)[-6:], 2)}")
    assert np.median(errors_pp) < 0.1


def test_result_fields_and_uncertainty_cover_the_error():
    image, truth = render_track(0.42, RADIUS_M, GROUSERS, HEIGHT_M, 900.0, seed=3,
                                size_px=SIZE_PX, track_angle_deg=-33.0, noise_std=3.0)
    result = measure_track_slip(image, RADIUS_M, GROUSERS, px_per_m=900.0)
    assert isinstance(result, TrackSlipResult)
    assert abs(result.slip - 0.42) <= max(4 * result.slip_std, 0.002)
    assert abs(result.spacing_m - truth["spacing_m"]) / truth["spacing_m"] < 0.003
    assert result.theoretical_spacing_m == pytest.approx(2 * np.pi * RADIUS_M / GROUSERS)
    assert result.marks_used >= 15 and result.marks_used <= result.marks_expected
    assert abs((result.track_angle_deg - (-33.0 % 180) + 90) % 180 - 90) < 1.0
    assert result.length_m > 0.6
    assert json.loads(json.dumps(result.to_dict()))["marks_used"] == result.marks_used


def test_two_point_scale_under_perspective():
    """Scale from two image points a known distance apart, with a keystone."""
    image, truth = render_track(0.25, RADIUS_M, GROUSERS, HEIGHT_M, 800.0, seed=5,
                                size_px=SIZE_PX, track_angle_deg=75.0, perspective=0.015,
                                perspective_azimuth_deg=70.0)
    result = measure_track_slip(image, RADIUS_M, GROUSERS, scale_points=truth["scale_points_px"],
                                scale_distance_m=truth["scale_distance_m"])
    assert abs(result.slip - 0.25) < 0.005
    assert result.px_per_m == pytest.approx(800.0, rel=0.01)
    assert result.slip_std > 0.0005  # the placement of the two points counts


def _blobs(seed: int) -> np.ndarray:
    """Plain sand strewn with random blobs (pebbles, footprints): no periodicity."""
    rng = np.random.default_rng(seed)
    image, _ = render_track(0.3, seed=seed, size_px=SIZE_PX, track_width_m=0.0, sinkage_m=0.0,
                            marks=False)
    image = image.astype(np.float32)
    for _ in range(150):
        centre = (int(rng.uniform(0, SIZE_PX[0])), int(rng.uniform(0, SIZE_PX[1])))
        axes = (int(rng.uniform(3, 15)), int(rng.uniform(3, 15)))
        cv2.ellipse(image, centre, axes, rng.uniform(0, 180), 0, 360, rng.uniform(20, 200), -1)
    return np.clip(cv2.GaussianBlur(image, (0, 0), 1.0), 0, 255).astype(np.uint8)


@pytest.mark.parametrize("case", ["plain sand", "track without marks", "random blobs"])
@pytest.mark.parametrize("seed", [1, 2])
def test_refuses_images_without_periodic_marks(case, seed):
    nuisance = random_nuisance(30_000 + seed, SIZE_PX)
    if case == "plain sand":
        image, _ = render_track(0.3, seed=seed, nuisance=nuisance, track_width_m=0.0,
                                sinkage_m=0.0, marks=False)
    elif case == "track without marks":
        image, _ = render_track(0.3, seed=seed, nuisance=nuisance, marks=False)
    else:
        image = _blobs(seed)
    with pytest.raises(NoPeriodicMarksError, match="no periodic grouser marks found"):
        measure_track_slip(image, RADIUS_M, GROUSERS, px_per_m=900.0)


@pytest.mark.parametrize("height_m", [0.0092, 0.03])
def test_mark_spacing_follows_the_rim_radius_not_the_grouser_tip(height_m):
    """The grooves are cut by the tips at r + h (trochoid envelope), yet their spacing is
    the hub travel per grouser pitch, 2*pi*r*(1 - s)/n with r the rim radius."""
    slip = 0.3
    image, truth = render_track(slip, RADIUS_M, GROUSERS, height_m, 900.0, seed=7,
                                size_px=SIZE_PX, track_angle_deg=20.0)
    spacing_m = measure_track_slip(image, RADIUS_M, GROUSERS, px_per_m=900.0).spacing_m
    rim_m = mark_spacing_m(slip, RADIUS_M, GROUSERS)
    tip_m = mark_spacing_m(slip, RADIUS_M + height_m, GROUSERS)
    assert abs(spacing_m / rim_m - 1) < 0.003
    assert abs(spacing_m / tip_m - 1) > 0.06
    # slip with the tip radius as reference would be off by 1 - (1 - s) r/(r + h)
    tip_slip = measure_track_slip(image, RADIUS_M + height_m, GROUSERS, px_per_m=900.0).slip
    assert tip_slip - slip == pytest.approx((1 - slip) * height_m / (RADIUS_M + height_m), abs=2e-3)


def test_renderer_truth_written_apart(tmp_path):
    png, truth_path = write_track_render(tmp_path / "track.png", 0.5, seed=1,
                                         nuisance=TrackNuisance(size_px=(320, 240)))
    image = cv2.imread(str(png), cv2.IMREAD_GRAYSCALE)
    truth = json.loads(truth_path.read_text())
    assert image.shape == (240, 320) and truth_path.name == "track.truth.json"
    assert truth["slip"] == 0.5
    assert truth["spacing_m"] == pytest.approx(2 * np.pi * 0.125 * 0.5 / 12)
    assert truth["nuisance"]["size_px"] == [320, 240]


def test_renderer_is_seeded_and_rejects_skid():
    a, _ = render_track(0.2, seed=4, nuisance=replace(random_nuisance(4), size_px=(200, 150)))
    b, _ = render_track(0.2, seed=4, nuisance=replace(random_nuisance(4), size_px=(200, 150)))
    assert np.array_equal(a, b)
    with pytest.raises(ValueError):
        render_track(-0.1)


def test_bad_arguments():
    image, _ = render_track(0.2, size_px=(320, 240))
    with pytest.raises(ValueError, match="either px_per_m or scale_points"):
        measure_track_slip(image, RADIUS_M, GROUSERS)
    with pytest.raises(ValueError):
        measure_track_slip(image, RADIUS_M, GROUSERS, scale_points=[(0, 0), (0, 0)],
                           scale_distance_m=0.1)
    with pytest.raises(ValueError):
        measure_track_slip(image[:10], RADIUS_M, GROUSERS, px_per_m=900.0)


def test_slip_from_spacing_follows_the_spec_for_drive_and_skid():
    from softflow.track_slip import slip_from_spacing

    assert slip_from_spacing(0.75, 1.0) == (0.25, 0.0)
    slip, std = slip_from_spacing(1.25, 1.0, 0.01)  # braked: (r*omega - v)/v
    assert slip == pytest.approx(-0.2) and std == pytest.approx(0.008)
