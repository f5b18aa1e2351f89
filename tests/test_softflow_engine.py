"""softflow.flow_engine against the renderer's truth (sub-pixel accuracy, outliers, averaging)."""

from __future__ import annotations

import cv2
import numpy as np
import pytest

from softflow.flow_engine import (BORDER_PX, average_flow, normalised_median_outliers,
                                  pair_displacement_px)
from virtual_testbed.flow_render import BETA_GRID, FlowScene, render_flow


@pytest.fixture(scope="module")
def render():
    scene = FlowScene(size_px=(320, 320), wheel_center_px=(160, 100), wheel_radius_px=64,
                      grouser_count=10, grouser_height_px=6, grouser_model="cosine", seed=7)
    return render_flow(scene, 3)


def _inner(mask):
    m = cv2.erode(mask.astype(np.uint8), np.ones((17, 17), np.uint8)).astype(bool)
    m[:10], m[-10:], m[:, :10], m[:, -10:] = False, False, False, False
    return m


@pytest.mark.parametrize("engine, rms_px, bias_px", [("deform-lk", 0.02, 0.006),
                                                      ("farneback", 0.05, 0.02),
                                                      ("dis", 0.05, 0.02)])
def test_pair_accuracy(render, engine, rms_px, bias_px):
    """The default engine meets the issue's 0.05 px / 0.01 px with margin; the plain engines
    (no deformation) are kept for comparison and are biased (module docstring)."""
    m = _inner(render.soil_mask[0])
    err = (pair_displacement_px(render.frames[0], render.frames[1], engine)
           - render.displacement_px[0])[m]
    assert np.sqrt(np.mean(err ** 2)) <= rms_px
    assert np.all(np.abs(err.mean(axis=0)) <= bias_px)
    assert np.mean(np.hypot(err[:, 0], err[:, 1]) > 0.5) < 0.01


@pytest.mark.parametrize("shift_px", [0.25, 0.75, 1.25])
def test_deformation_removes_subpixel_bias(shift_px):
    """Uniform fractional shifts: Farneback's peak-locking bias, gone after deformation
    (quintic spline and its gradient: <= 0.0016 px measured; cubic spline 0.011 px)."""
    uniform = tuple([5000.0] * len(BETA_GRID))
    scene = FlowScene(size_px=(192, 192), wheel_center_px=(96, -200),
                      velocity_mps=shift_px * 25 / 1000, radial_decay_per_m=uniform,
                      tangential_decay_per_m=uniform, smudges=0, seed=3)
    r = render_flow(scene, 2)
    m = _inner(r.soil_mask[0])
    bias = [np.mean((pair_displacement_px(*r.frames, engine=e) - r.displacement_px[0])[m][:, 0])
            for e in ("deform-lk", "farneback")]
    assert abs(bias[0]) < 0.0025
    if shift_px == 0.25:
        assert 0.004 < abs(bias[1])


def test_odd_frame_size(render):
    """Frames of odd size are padded to whole solve blocks and cropped back."""
    a, b = (f[:317, :291] for f in render.frames[:2])
    flow = pair_displacement_px(a, b)
    m = _inner(render.soil_mask[0][:317, :291])
    assert flow.shape == (317, 291, 2)
    assert np.sqrt(np.mean((flow - render.displacement_px[0][:317, :291])[m] ** 2)) < 0.02


def test_normalised_median_test_flags_spikes():
    rng = np.random.default_rng(0)
    flow = np.dstack([np.full((64, 64), 2.0), np.zeros((64, 64))])
    flow += rng.normal(0, 0.02, (64, 64, 2))
    flow[20, 30] = (6.0, -3.0)
    flow[40, 10] = (2.0, 1.5)
    bad = normalised_median_outliers(flow, np.ones((64, 64), bool))
    assert bad[20, 30] and bad[40, 10]
    assert bad.sum() <= 2 + 64 * 64 * 0.01


def test_average_in_velocity_units(render):
    masks = [render.soil_mask[k] for k in range(2)]
    mean = average_flow(render.frames, render.t_s, masks)
    m = _inner(render.soil_mask[0] & render.soil_mask[1])
    truth = render.displacement_px.mean(axis=0) * render.scene.fps
    err = (mean.velocity_px_per_s - truth)[m] / render.scene.fps
    valid = np.isfinite(err[:, 0])  # a pixel flagged in both pairs has no vector (1 of 71175)
    assert valid.mean() > 0.999
    assert np.sqrt(np.mean(err[valid] ** 2)) < 0.04  # 0.0189 px (0.0177 without presmoothing)
    assert mean.outlier_fraction < 0.02  # small-window field: ~1.4 % flagged at eps 0.1 px
    assert np.isnan(mean.velocity_px_per_s[100, 160]).all()  # inside the wheel
    # vectors at the image border are rejected (biased low there: the warp leaves the image)
    b = BORDER_PX
    v = mean.velocity_px_per_s
    assert np.isnan(v[:b]).all() and np.isnan(v[-b:]).all()
    assert np.isnan(v[:, :b]).all() and np.isnan(v[:, -b:]).all()
    assert np.isfinite(v[-b - 1, 2 * b:-2 * b, 0]).mean() > 0.9  # just inside: kept


def test_cli_engine_choices_match_the_engines():
    """``swtlab flow --engine`` lists its choices without importing the engine (fast start)."""
    from softflow.flow_engine import ENGINES
    from swtlab_cli.cmd_flow import ENGINE_CHOICES
    assert ENGINE_CHOICES == ENGINES


def test_a_process_that_measured_flow_can_fork_workers():
    """``swtlab process --jobs`` forks; after a numba parallel kernel under GNU OpenMP the
    fork aborts ("fork() called from a process already using GNU OpenMP"). softflow runs
    its kernels on the fork-safe workqueue layer: a child forked after a kernel runs one."""
    import subprocess
    import sys

    script = (
        "import numpy as np, numba\n"
        "from concurrent.futures import ProcessPoolExecutor\n"
        "from softflow.flow_engine import normalise_frames\n"
        "def run(_):\n"
        "    f = np.random.default_rng(0).random((64, 64), dtype=np.float32)\n"
        "    return float(normalise_frames((f,), np.ones((64, 64), np.float32))[0].sum())\n"
        "run(0)\n"
        "assert numba.threading_layer() == 'workqueue', numba.threading_layer()\n"
        "with ProcessPoolExecutor(2) as pool:\n"
        "    print(list(pool.map(run, range(2))) == [run(0)] * 2)\n")
    done = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True,
                          timeout=300)
    assert done.returncode == 0, done.stderr[-500:]
    assert done.stdout.strip() == "True"


def test_static_step_at_the_soil_edge(monkeypatch):
    """Textured soil shifted by (1.3, 0.6) px under a static smooth band (sky, sled frame) with
    the soil mask 4 px below the step, as ``analyse_frames`` masks it: off the soil the
    normalised frames are 0, a static step that pulls the flow of the pixels whose spline
    support reaches it towards zero motion. With the LK sums kept ``EDGE_PX`` inside the mask
    the vertical bias 0-3 px inside the mask is 0.010 px, without 0.017 px; far from the edge
    0.0000 px either way."""
    import softflow.flow_engine as fe
    from scipy import ndimage

    rng = np.random.default_rng(3)
    tex = ndimage.gaussian_filter(rng.random((200, 240)), 1.2)
    tex = (tex - tex.mean()) / tex.std() * 40 + 120
    shift = np.array([1.3, 0.6])
    moved = ndimage.shift(tex, shift[::-1], order=5, mode="reflect")
    edge = 80.0 + 3 * np.sin(np.arange(240) / 17.0)  # soil below, static and smooth above
    depth = np.arange(200)[:, None] - edge[None, :]
    a, b = (np.where(depth > 0, t, 200.0).astype(np.float32) for t in (tex, moved))
    mask = depth > 4
    inner = np.zeros(mask.shape, bool)
    inner[10:-10, 10:-10] = True
    band, far = inner & (depth > 4) & (depth < 7), inner & (depth >= 20)

    def bias(edge_px):
        monkeypatch.setattr(fe, "EDGE_PX", edge_px)
        err = fe.pair_displacement_px(a, b, soil=mask, windows=fe.RATE_KERNELS_PX,
                                      presmooth_px=fe.RATE_PRESMOOTH_PX) - shift
        return err[band].mean(axis=0), err[far].mean(axis=0)

    (band_now, far_now), (band_before, far_before) = bias(2), bias(0)
    assert abs(band_now[1]) < 0.012 < 0.015 < abs(band_before[1])
    assert np.all(np.abs(far_now) < 0.001) and np.all(np.abs(far_before) < 0.001)
