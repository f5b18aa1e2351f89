"""Track slip on the second track renderer (written apart, issue 21): jittered, erased and smeared
marks, uneven light, rotation, keystone, JPEG q80.

Seeds looked at while tuning the period search and the mark fit (issue 21, second pass):
``TUNING_SEEDS``; the accuracy test uses 81 000-81 011, the bench's figures 1000 on."""

from __future__ import annotations

import numpy as np
import pytest

from softflow import track_period
from softflow.track_slip import NoPeriodicMarksError, measure_track_slip
from virtual_testbed.second_track_render import (SecondTrackScene, random_second_track,
                                                 render_second_track, spacing_m)

TUNING_SEEDS = (*range(200, 230), *range(80_000, 80_040), 300, *range(700, 704))


def test_spacing_is_the_rim_circumference_share():
    scene = SecondTrackScene(radius_m=0.125, grousers=12, slip=0.25)
    assert spacing_m(scene) == pytest.approx(2 * np.pi * 0.125 * 0.75 / 12)  # RUAG: d0 (1 - s)


@pytest.mark.slow  # track photos of the second renderer rendered and measured
@pytest.mark.slow_render
def test_slip_within_half_a_point():
    errors = []
    for i, slip in enumerate(np.linspace(0.0, 0.8, 12)):
        assert 81_000 + i not in TUNING_SEEDS
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


def _grooves(period: float, width: float, noise: float, seed: int) -> np.ndarray:
    """14 periods of narrow grooves (a shaded wall then a lit wall, 1 % position jitter, 10 %
    erased) on white noise: their spectrum peaks at a high harmonic, the fundamental is weak."""
    rng = np.random.default_rng(seed)
    a = np.arange(int(period * 14), dtype=float)
    out = rng.normal(0, noise, a.size)
    for i in range(14):
        if rng.uniform() < 0.1:
            continue
        s = (a - (i + 0.5 + 0.01 * rng.standard_normal()) * period) / width
        out += -np.exp(-((s + 0.35) / 0.3) ** 2) + 0.7 * np.exp(-((s - 0.4) / 0.3) ** 2)
    return out


def test_fundamental_of_narrow_grooves_not_a_harmonic():
    """Seeds 203 and 207 of the second renderer were refused: the spectrum of narrow grooves
    peaks at their 4th-6th harmonic; the comb between its multiples finds the marks. Period
    within 3 % (the mark fit refines it) and prominent on 24 of these 30 profiles (12 before)."""
    found = 0
    for period, width, noise in ((78.0, 4.5, 0.1), (78.0, 3.0, 0.05), (65.0, 3.0, 0.05)):
        for seed in range(10):
            freq, prominence = track_period.fundamental(_grooves(period, width, noise, seed),
                                                        10.0, 320.0)
            found += bool(freq and abs(1 / freq / period - 1) < 0.03
                          and prominence >= track_period.MIN_PROMINENCE)
    assert found >= 22


def test_fundamental_of_noise_not_found():
    rng = np.random.default_rng(5)
    for _ in range(20):
        _, prominence = track_period.fundamental(rng.normal(size=900), 10.0, 320.0)
        assert prominence < track_period.MIN_PROMINENCE


def test_stray_mark_at_the_end_rejected():
    """Seed 206: a stray mark 0.3 period off before two erased ones, at one end of 9, was kept
    by a quadratic that bent towards it (1.9 points of slip); a Theil-Sen start rejects it."""
    period = 73.5
    rng = np.random.default_rng(0)
    positions = 100 + period * np.arange(3, 11) + 0.01 * period * rng.standard_normal(8)
    a = np.arange(1000, dtype=float)
    profile = rng.normal(0, 0.02, a.size)
    for x in np.r_[100 + period * 0.71, positions]:
        profile -= np.exp(-((a - x) / 3.0) ** 2)
    fit = track_period.fit_marks(profile, period * 1.01, 500.0)
    assert fit.spacing == pytest.approx(period, rel=0.003)
    assert fit.indices.size == 8
