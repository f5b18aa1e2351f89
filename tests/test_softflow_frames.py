"""softflow.frames: /camera/side in MCAP, image folders, video with its times CSV."""

from __future__ import annotations

import base64
import json

import cv2
import numpy as np
import pytest

from softflow.frames import FrameSourceError, load_frames


def _images(n=4, size=64):
    rng = np.random.default_rng(0)
    return [rng.integers(0, 255, (size, size), dtype=np.uint8) for _ in range(n)]


def test_mcap_frames_and_camera_metadata(tmp_path):
    from mcap.writer import Writer

    path = tmp_path / "run.mcap"
    with open(path, "wb") as stream:
        w = Writer(stream)
        w.start()
        schema = w.register_schema("foxglove.CompressedImage", "jsonschema", b"{}")
        channel = w.register_channel("/camera/side", "json", schema)
        for i, img in enumerate(_images()):
            t_ns = 1_000_000_000 + i * 40_000_000
            msg = {"timestamp": {"sec": t_ns // 10**9, "nsec": t_ns % 10**9}, "frame_id": "side",
                   "format": "png",
                   "data": base64.b64encode(cv2.imencode(".png", img)[1].tobytes()).decode()}
            w.add_message(channel, log_time=t_ns, publish_time=t_ns, data=json.dumps(msg).encode())
        w.add_metadata("swt.camera", {"px_per_m": "2000", "travel_direction": "-x",
                                      "wheel_center_px": "30,20", "wheel_radius_px": "15"})
        w.add_metadata("swt.wheel", {"radius_m": "0.1", "width_m": "0.1", "grouser_count": "8",
                                     "grouser_height_m": "0.005"})
        w.finish()
    fs = load_frames(path, (1, 4))
    assert len(fs.frames) == 3 and np.array_equal(fs.frames[0], _images()[1])
    assert fs.t_s == pytest.approx([1.04, 1.08, 1.12])
    assert fs.px_per_m == 2000 and fs.direction == -1
    assert fs.wheel_center_px == (30.0, 20.0) and fs.wheel_radius_px == 15.0
    assert fs.grouser_count == 8 and fs.grouser_height_px == pytest.approx(10.0)


def test_video_with_times_csv(tmp_path):
    video = tmp_path / "camera_side.avi"
    writer = cv2.VideoWriter(str(video), cv2.VideoWriter_fourcc(*"MJPG"), 25, (64, 64), False)
    for img in _images(5):
        writer.write(img)
    writer.release()
    (tmp_path / "camera_side.csv").write_text("frame,t_s\n" + "".join(
        f"{i},{0.5 + i * 0.04}\n" for i in range(5)))
    fs = load_frames(tmp_path, (0, 3), px_per_m=1500)
    assert len(fs.frames) == 3 and fs.frames[0].shape == (64, 64)
    assert fs.t_s == pytest.approx([0.5, 0.54, 0.58])


def test_plain_image_folder_needs_scale_and_times(tmp_path):
    for i, img in enumerate(_images(3)):
        cv2.imwrite(str(tmp_path / f"img{i}.png"), img)
    with pytest.raises(FrameSourceError, match=r"\(fps=FPS\)"):
        load_frames(tmp_path, px_per_m=1000)
    with pytest.raises(FrameSourceError, match="px_per_m"):
        load_frames(tmp_path, fps=50)
    fs = load_frames(tmp_path, px_per_m=1000, fps=50)
    assert fs.t_s == pytest.approx([0, 0.02, 0.04])
