"""softflow.wheel_detect: centre, radius, grousers, tracking of a sinking wheel."""

from __future__ import annotations

import numpy as np
import pytest

from softflow.wheel_detect import soil_mask, track_wheel
from virtual_testbed.flow_render import FlowScene, render_flow


@pytest.fixture(scope="module")
def sinking():
    scene = FlowScene(size_px=(320, 320), wheel_center_px=(150, 110), wheel_radius_px=70,
                      grouser_count=12, grouser_height_px=7, grouser_model="cosine",
                      sink_px_per_frame=1.0, seed=4)
    return render_flow(scene, 3)


def test_centre_radius_and_sinking(sinking):
    poses = track_wheel(sinking.frames, grouser_count=12)
    for pose, truth in zip(poses, sinking.wheel_center_px):
        assert np.hypot(*(np.array(pose.center_px) - truth)) < 1.0
        assert pose.radius_px == pytest.approx(70, abs=5)  # edge 3-4 px inside: docstring
    assert poses[2].center_px[1] - poses[0].center_px[1] == pytest.approx(2.0, abs=0.75)
    assert poses[0].grouser_count == 12


def test_grouser_phase(sinking):
    pose = track_wheel(sinking.frames[:1], grouser_count=12)[0]
    pitch = 2 * np.pi / 12
    assert abs(np.angle(np.exp(1j * 12 * pose.grouser_angle_rad))) / 12 < 0.1 * pitch


def test_metadata_overrides(sinking):
    poses = track_wheel(sinking.frames, center_px=(151.0, 111.0), radius_px=70.0,
                        grouser_count=12, grouser_height_px=7.0)
    assert poses[0].center_px == pytest.approx((151.0, 111.0))
    assert poses[0].radius_px == 70.0 and poses[0].grouser_height_px == 7.0
    mask = soil_mask((320, 320), poses[0])
    assert not mask[111, 151 + 80] and mask[111, 151 + 90]


@pytest.mark.slow  # wheel detection on supersampled renders
@pytest.mark.parametrize("noise_std", [0.0, 2.0])
def test_painted_ring_is_not_the_rim(noise_std):
    """The rendered wheel carries a bright ring at 0.75 R. Noise-free, the ring's edges are
    the only texture on the wheel and split its smooth region into a disc and an annulus;
    the larger one alone was the disc inside the ring (radius 72 px for a 100 px rim), so
    the soil mask took in the wheel and the decay rates went 5-13 % off."""
    scene = FlowScene(noise_std=noise_std, seed=6)
    pose = track_wheel(render_flow(scene, 1).frames)[0]
    assert pose.radius_px == pytest.approx(scene.wheel_radius_px, abs=1.0)
    assert np.hypot(*(np.array(pose.center_px) - scene.wheel_center_px)) < 1.0
