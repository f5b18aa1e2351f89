"""Side-camera frames for SOFT (item 1): an MCAP or CSV run, a folder of images, or a video.

Raw-run spec (``/work/shared/spec/raw-run-format.md``): ``/camera/side`` as
``foxglove.CompressedImage`` JSON in MCAP; in the CSV form ``camera_side/<t_ns>.png|.jpg``
or ``camera_side.<mp4|avi|mkv>`` with ``camera_side.csv`` (``frame, t_s``). Scale and
wheel come from ``swt.camera`` (``px_per_m``, ``travel_direction``, optional
``wheel_center_px``, ``wheel_radius_px``) and ``swt.wheel`` (grousers). A bare folder
of images or a video is accepted too: times from ``<t_ns>`` file names or the
``frame, t_s`` CSV beside the video (else ``fps``), scale from a ``run.json`` beside
them or the caller.
"""

from __future__ import annotations

import base64
import json
from dataclasses import dataclass
from pathlib import Path

import cv2
import numpy as np

from swtlab_base.errors import InputError

VIDEO_SUFFIXES = (".mp4", ".avi", ".mkv")
IMAGE_SUFFIXES = (".png", ".jpg", ".jpeg", ".bmp", ".tif", ".tiff")


class FrameSourceError(InputError, ValueError):
    """The frames or their scale could not be read."""


@dataclass
class FrameSet:
    """Grey frames of one range with their times and what the metadata says of camera and wheel."""

    frames: list[np.ndarray]
    t_s: np.ndarray
    frame_range: tuple[int, int]  # [start, stop) indices in the source
    px_per_m: float | None
    direction: int = 1  # +1: travel towards the image right
    wheel_center_px: tuple[float, float] | None = None
    wheel_radius_px: float | None = None
    grouser_count: int | None = None
    grouser_height_px: float | None = None
    source: str = ""


def _grey(img: np.ndarray | None, what: str) -> np.ndarray:
    if img is None:
        raise FrameSourceError(f"{what}: not a decodable image")
    return img if img.ndim == 2 else cv2.cvtColor(img, cv2.COLOR_BGR2GRAY)


def _decode(data: bytes, what: str) -> np.ndarray:
    return _grey(cv2.imdecode(np.frombuffer(data, np.uint8), cv2.IMREAD_UNCHANGED), what)


def _range(count: int, frames: tuple[int | None, int | None] | None) -> tuple[int, int]:
    start, stop, _ = slice(*(frames or (None, None))).indices(count)
    if stop - start < 2:
        raise FrameSourceError(f"frame range {start}:{stop} of {count} frames holds fewer than 2")
    return start, stop


def _apply_metadata(fs: FrameSet, camera: dict, wheel: dict) -> None:
    if camera.get("px_per_m") is not None and fs.px_per_m is None:
        fs.px_per_m = float(camera["px_per_m"])
    fs.direction = -1 if str(camera.get("travel_direction", "+x")).strip() == "-x" else 1
    centre = camera.get("wheel_center_px")
    if isinstance(centre, str):
        centre = [float(v) for v in centre.split(",")]
    if centre is not None:
        fs.wheel_center_px = (float(centre[0]), float(centre[1]))
    if camera.get("wheel_radius_px") is not None:
        fs.wheel_radius_px = float(camera["wheel_radius_px"])
    if fs.wheel_radius_px is None and fs.px_per_m and wheel.get("radius_m") is not None:
        fs.wheel_radius_px = float(wheel["radius_m"]) * fs.px_per_m
    if wheel.get("grouser_count") is not None:
        fs.grouser_count = int(wheel["grouser_count"])
        if fs.px_per_m and wheel.get("grouser_height_m") is not None:
            fs.grouser_height_px = float(wheel["grouser_height_m"]) * fs.px_per_m


def _image_folder(folder: Path, frames, fps: float | None) -> FrameSet:
    files = sorted((p for p in folder.iterdir() if p.suffix.lower() in IMAGE_SUFFIXES),
                   key=lambda p: (not p.stem.isdigit(), int(p.stem) if p.stem.isdigit() else 0,
                                  p.name))
    if len(files) < 2:
        raise FrameSourceError(f"{folder}: fewer than two images")
    if all(p.stem.isdigit() for p in files):
        t_s = np.array([int(p.stem) for p in files]) * 1e-9
    elif fps:
        t_s = np.arange(len(files)) / fps
    else:
        raise FrameSourceError(f"{folder}: image names are not <t_ns>; give the frame rate "
                               "(fps=FPS)")
    a, b = _range(len(files), frames)
    imgs = [_grey(cv2.imread(str(p), cv2.IMREAD_UNCHANGED), str(p)) for p in files[a:b]]
    return FrameSet(imgs, t_s[a:b], (a, b), None, source=str(folder))


def _video(path: Path, frames, fps: float | None) -> FrameSet:
    cap = cv2.VideoCapture(str(path))
    if not cap.isOpened():
        raise FrameSourceError(f"{path}: cannot open the video")
    count = int(cap.get(cv2.CAP_PROP_FRAME_COUNT))
    times_csv = path.with_suffix(".csv")
    if times_csv.exists():
        table = np.atleast_2d(np.loadtxt(times_csv, delimiter=",", skiprows=1))
        t_all = np.full(max(count, int(table[:, 0].max()) + 1), np.nan)
        t_all[table[:, 0].astype(int)] = table[:, 1]
    else:
        rate = fps or cap.get(cv2.CAP_PROP_FPS)
        if not rate:
            raise FrameSourceError(f"{path}: no {times_csv.name} and no frame rate")
        t_all = np.arange(count) / rate
    a, b = _range(count, frames)
    cap.set(cv2.CAP_PROP_POS_FRAMES, a)
    imgs = []
    for i in range(a, b):
        ok, img = cap.read()
        if not ok:
            raise FrameSourceError(f"{path}: frame {i} could not be decoded")
        imgs.append(_grey(img, f"{path} frame {i}"))
    cap.release()
    return FrameSet(imgs, t_all[a:b], (a, b), None, source=str(path))


def _mcap(path: Path, frames) -> FrameSet:
    from mcap.reader import make_reader

    with open(path, "rb") as stream:
        reader = make_reader(stream)
        messages = [(m.log_time, m.data) for _, _, m in
                    reader.iter_messages(topics=["/camera/side"], log_time_order=True)]
        metadata = {rec.name: dict(rec.metadata) for rec in reader.iter_metadata()}
    if len(messages) < 2:
        raise FrameSourceError(f"{path}: fewer than two /camera/side frames")
    a, b = _range(len(messages), frames)
    imgs, t_s = [], []
    for i in range(a, b):
        msg = json.loads(messages[i][1])
        imgs.append(_decode(base64.b64decode(msg["data"]), f"{path} /camera/side #{i}"))
        stamp = msg.get("timestamp", {})
        t_s.append(stamp.get("sec", 0) + stamp.get("nsec", 0) * 1e-9 if stamp
                   else messages[i][0] * 1e-9)
    fs = FrameSet(imgs, np.array(t_s), (a, b), None, source=str(path))
    _apply_metadata(fs, metadata.get("swt.camera", {}), metadata.get("swt.wheel", {}))
    return fs


def load_frames(path: str | Path, frames: tuple[int | None, int | None] | None = None,
                px_per_m: float | None = None, fps: float | None = None) -> FrameSet:
    """Frames ``[start, stop)`` of a run (MCAP file or CSV folder), image folder or video."""
    path = Path(path)
    if not path.exists():
        raise FrameSourceError(f"{path}: no such file or folder")
    if path.suffix.lower() == ".mcap":
        fs = _mcap(path, frames)
    elif path.suffix.lower() in VIDEO_SUFFIXES:
        fs = _video(path, frames, fps)
    elif path.is_dir() and (path / "camera_side").is_dir():
        fs = _image_folder(path / "camera_side", frames, fps)
    elif path.is_dir() and any((path / f"camera_side{s}").exists() for s in VIDEO_SUFFIXES):
        video = next(path / f"camera_side{s}" for s in VIDEO_SUFFIXES
                     if (path / f"camera_side{s}").exists())
        fs = _video(video, frames, fps)
    elif path.is_dir():
        fs = _image_folder(path, frames, fps)
    else:
        raise FrameSourceError(f"{path}: not an MCAP run, run folder, image folder or video")
    if px_per_m is not None:
        fs.px_per_m = px_per_m
    meta = next((d / "run.json" for d in (path, path.parent) if (d / "run.json").exists()), None)
    if meta is not None and path.suffix.lower() != ".mcap":
        record = json.loads(meta.read_text())
        _apply_metadata(fs, record.get("camera", {}), record.get("wheel", {}))
    if fs.px_per_m is None:
        raise FrameSourceError(f"{path}: no scale: swt.camera px_per_m is missing; give "
                               "px_per_m=PX_PER_M")
    return fs
