"""Side-camera frames of a run (``/camera/side``): sand flowing under the wheel in the stable phase.

The camera rides on the sled and looks through the glass wall (raw-run spec, ``swt.camera``).
A burst of frames centred in the run's true stable phase is rendered by
:func:`virtual_testbed.flow_render.render_flow` with the run's own wheel (radius, grousers),
travel velocity and wheel speed (the mean of the noise-free signals over the burst), encoded
as PNG. The render's truth (decay rates ``k(beta)``, ``alpha3(beta)``, scene) goes to the
run's truth file, never to the raw run.
"""

from __future__ import annotations

from dataclasses import dataclass

import cv2
import numpy as np

from virtual_testbed.flow_render import FlowScene, render_flow
from virtual_testbed.rig import Wheel
from virtual_testbed.simulate import TrueRun
from virtual_testbed.track_photos import TrackPhoto

SIDE_TOPIC = "/camera/side"


@dataclass(frozen=True)
class SideCamera:
    """The side camera: image size, scale, frame rate, where the axle is, the soil's grouser model.

    At 40 m/h and 800 px/m, 3 frames/s move the far soil about 3 px per frame, the
    displacement a SOFT analysis needs (softflow pairs consecutive frames: a faster camera's
    video has to be thinned to such a step first, docs/softflow.md).
    """

    size_px: tuple[int, int] = (384, 320)  # width, height
    px_per_m: float = 800.0
    fps: float = 3.0
    wheel_center_px: tuple[float, float] = (192.0, 120.0)
    grouser_model: str = "gear"  # effective radius of the soil model (flow_render)
    supersample: int = 3


def burst_times_s(true_run: TrueRun, count: int, fps: float) -> np.ndarray:
    """``count`` frame times at ``fps``, centred in the true stable phase."""
    tl = true_run.timeline
    middle_s = 0.5 * (tl.window_start_s + tl.decel_start_s)
    return middle_s + (np.arange(count) - 0.5 * (count - 1)) / fps


def side_scene(true_run: TrueRun, wheel: Wheel, camera: SideCamera, t_s: np.ndarray,
               seed: int) -> FlowScene:
    """The flow scene of the run over the burst ``t_s``: its velocity and the slip that gives its
    wheel speed (``R omega = v / (1 - slip)``, whatever the sign of the run's slip)."""
    sig = true_run.signals
    velocity_mps = float(np.mean(np.interp(t_s, sig["t_s"], sig["velocity_mps"])))
    surface_mps = float(np.mean(np.interp(t_s, sig["t_s"], sig["omega_radps"]))) * wheel.radius_m
    return FlowScene(size_px=camera.size_px, px_per_m=camera.px_per_m, fps=camera.fps,
                     wheel_center_px=camera.wheel_center_px,
                     wheel_radius_px=wheel.radius_m * camera.px_per_m,
                     velocity_mps=velocity_mps, slip=1.0 - velocity_mps / surface_mps,
                     grouser_count=wheel.grouser_count,
                     grouser_height_px=wheel.grouser_height_m * camera.px_per_m,
                     grouser_model=camera.grouser_model if wheel.grouser_count else None,
                     supersample=camera.supersample, seed=seed)


def side_frames(true_run: TrueRun, wheel: Wheel, camera: SideCamera, count: int,
                seed: int) -> tuple[list[TrackPhoto], dict]:
    """``count`` PNG frames of the stable phase and their truth (render truth plus ``t_ns``)."""
    t_s = burst_times_s(true_run, count, camera.fps)
    render = render_flow(side_scene(true_run, wheel, camera, t_s, seed), count)
    t_ns = [int(round(t * 1e9)) for t in t_s]
    frames = []
    for image, stamp in zip(render.frames, t_ns):
        ok, encoded = cv2.imencode(".png", image)
        if not ok:
            raise RuntimeError("PNG encoding of a side-camera frame failed")
        frames.append(TrackPhoto(stamp, encoded.tobytes(), "png"))
    return frames, {**render.truth, "t_ns": t_ns}


def camera_record(camera: SideCamera) -> dict[str, float | str]:
    """The spec's ``swt.camera`` record: scale and travel direction (towards the image right)."""
    return {"px_per_m": camera.px_per_m, "travel_direction": "+x"}
