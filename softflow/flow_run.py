"""Soil flow of a run: its side-camera frames (``/camera/side``) in the stable window, analysed.

The frames whose times lie inside the run's stable window (the middle ``max_frames`` of them
when there are more) go through :func:`softflow.field_analysis.analyse_frames` with the scale
and wheel of the run's metadata (``swt.camera``, ``swt.wheel``, as ingest read them).
Frame indices count the run's frames in time order, as ``swtlab flow RUN --frames A:B`` does,
so a stored range can be analysed again by hand.
"""

from __future__ import annotations

import base64
import json
from dataclasses import dataclass

import numpy as np

from softflow.field_analysis import FlowResult, analyse_frames
from softflow.frames import _decode, load_frames
from swtlab_base.errors import InputError

SIDE_TOPIC = "/camera/side"
#: most frames analysed per run (memory: one velocity field per pair is kept)
MAX_FRAMES = 32


class FlowRunError(InputError, ValueError):
    """Side-camera frames of a run that cannot be analysed: where, which channel, the problem."""

    def __init__(self, source, problem: str) -> None:
        self.source, self.channel, self.problem = str(source), SIDE_TOPIC, problem
        super().__init__(f"{source}: {SIDE_TOPIC}: {problem}")


@dataclass
class RunFlow:
    """The flow measured on a run and the first frame analysed (the background of its plots)."""

    result: FlowResult
    first_frame: np.ndarray


def window_frames(t_s: np.ndarray, start_s: float, end_s: float,
                  max_frames: int = MAX_FRAMES) -> tuple[int, int]:
    """``[first, stop)`` of the frames (times sorted) inside ``[start_s, end_s]``, the middle
    ``max_frames`` of them; ValueError when fewer than two lie inside."""
    inside = np.flatnonzero((t_s >= start_s) & (t_s <= end_s))
    if len(inside) < 2:
        raise ValueError(f"{len(inside)} of {len(t_s)} frames lie inside the stable window "
                         f"{start_s:.2f}-{end_s:.2f} s; a flow needs at least 2")
    first = int(inside[0]) + max(0, (len(inside) - max_frames) // 2)
    return first, first + min(len(inside), max_frames)


def _encoded(frames, order: np.ndarray) -> list[bytes]:
    """Encoded bytes of frames ``order`` (positions in the frame index), one pass over the file."""
    if frames.files:
        return [frames.files[i].read_bytes() for i in order]
    from mcap.reader import make_reader

    wanted, found = set(order.tolist()), {}
    with open(frames.source, "rb") as stream:
        messages = make_reader(stream).iter_messages(topics=[frames.topic], log_time_order=False)
        for i, (_, _, message) in enumerate(messages):
            if i in wanted:
                try:
                    found[i] = base64.b64decode(json.loads(message.data)["data"])
                except (KeyError, TypeError, ValueError) as exc:
                    raise ValueError(f"frame message {i} holds no base64 image ({exc})") from None
    return [found[i] for i in order]


def _grey_frames(run, order: np.ndarray, first: int, stop: int,
                 t_s: np.ndarray) -> list[np.ndarray]:
    """Frames ``first..stop-1`` (time order) decoded to grey."""
    frames = run.frames[SIDE_TOPIC]
    if frames.video is not None:  # decoded by the video reader; the scale is not used here
        return load_frames(run.source, (first, stop), px_per_m=1.0).frames
    data = _encoded(frames, order[first:stop])
    return [_decode(d, f"frame {first + k} (t = {t_s[first + k]:.3f} s)")
            for k, d in enumerate(data)]


def run_flow(run, start_s: float, end_s: float, max_frames: int = MAX_FRAMES) -> RunFlow | None:
    """The soil flow of an ``ingest.Run`` over ``[start_s, end_s]``; None without side-camera
    frames. Raises :class:`FlowRunError` (file, channel, problem) when they cannot be analysed."""
    frames = run.frames.get(SIDE_TOPIC)
    if frames is None or frames.count == 0:
        return None
    camera, wheel = run.metadata.camera, run.metadata.wheel
    if camera is None:
        raise FlowRunError(run.source, "no swt.camera record: without px_per_m the soil "
                                       "velocity has no scale")
    order = np.argsort(frames.t_s, kind="stable")
    t_s = frames.t_s[order]
    scale = camera.px_per_m
    try:
        first, stop = window_frames(t_s, start_s, end_s, max_frames)
        grey = _grey_frames(run, order, first, stop, t_s)
        result = analyse_frames(
            grey, t_s[first:stop], scale, -1 if camera.travel_direction == "-x" else 1,
            camera.wheel_center_px, camera.wheel_radius_px or wheel.radius_m * scale,
            wheel.grouser_count, wheel.grouser_height_m * scale, frame_range=(first, stop),
            source=str(run.source))
    except ValueError as exc:  # FrameSourceError and WheelNotFoundError are ValueErrors
        raise FlowRunError(run.source, str(exc)) from None
    return RunFlow(result, grey[0])
