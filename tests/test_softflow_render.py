"""virtual_testbed.flow_render: the frames carry exactly the displacement the truth says."""

from __future__ import annotations

import json

import numpy as np
import pytest
from scipy.ndimage import fourier_shift

from virtual_testbed.flow_render import (BETA_GRID, FlowScene, effective_radius_px, render_flow,
                                         write_flow_render)

UNIFORM = tuple([5000.0] * len(BETA_GRID))  # decays within a pixel: pure sled motion


@pytest.mark.parametrize("shift_px", [0.25, 0.6])
def test_uniform_shift_is_rendered_exactly(shift_px):
    scene = FlowScene(size_px=(192, 192), wheel_center_px=(96, -200), wheel_radius_px=100,
                      velocity_mps=shift_px * 25 / 1000, radial_decay_per_m=UNIFORM,
                      tangential_decay_per_m=UNIFORM, noise_std=0, flicker=0, smudges=0, seed=1)
    r = render_flow(scene, 2)
    assert np.allclose(r.displacement_px[0][..., 0], -shift_px)
    a, b = (f.astype(float) for f in r.frames)

    def residual(s):  # frame 1 against frame 0 moved left by s (Fourier shift)
        moved = np.fft.ifft2(fourier_shift(np.fft.fft2(a), (0, -s))).real
        return np.sqrt(np.mean((moved - b)[40:150, 30:160] ** 2))

    best = min(np.arange(shift_px - 0.1, shift_px + 0.101, 0.02), key=residual)
    assert best == pytest.approx(shift_px, abs=0.011)


def test_effective_radius_models():
    theta = np.linspace(-np.pi, np.pi, 721)
    args = (0.0, 100.0, 10.0, 12)
    for model in ("piecewise", "cosine", "cosine_series", "gear"):
        r_e = effective_radius_px(theta, *args, model=model)
        assert r_e.min() >= 100 - 1e-9 and r_e.max() <= 110 + 1e-9
        assert r_e[360] == pytest.approx(110, abs=0.05)  # g = 1 at theta = theta1
    assert effective_radius_px(theta, *args, model=None) == pytest.approx(100)


def test_grousered_scene_and_files(tmp_path):
    scene = FlowScene(size_px=(256, 256), wheel_center_px=(128, 80), wheel_radius_px=50,
                      grouser_count=10, grouser_height_px=6, grouser_model="gear", seed=2)
    r = render_flow(scene, 3)
    assert len(r.frames) == 3 and r.displacement_px.shape == (2, 256, 256, 2)
    assert r.frames[0].dtype == np.uint8
    assert not r.soil_mask[0][80, 128] and r.soil_mask[0][250, 10]
    assert not np.array_equal(r.displacement_px[0], r.displacement_px[1])  # grousers turn
    folder = write_flow_render(r, tmp_path / "run")
    assert len(list(folder.glob("*.png"))) == 3
    record = json.loads((tmp_path / "run" / "run.json").read_text())
    assert record["camera"]["px_per_m"] == scene.px_per_m
    assert record["wheel"]["grouser_count"] == 10
    truth = np.load(tmp_path / "run" / "flow_truth.npz")
    assert truth["displacement_px"].shape == (2, 256, 256, 2)
