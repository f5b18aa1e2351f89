"""A soil-flow result in a compact, storable form, and back as a result the plots take.

:func:`pack_flow` keeps what ``FlowResult.to_dict()`` leaves out and the plots of
:mod:`softflow.flow_plots` need: the mean velocity field and the first frame, both subsampled
to at most ``MAX_SIDE_PX`` on their longer side, and the polar profiles the decay fits were
made on (one compressed npz, about 100 kB whatever the camera). :func:`unpack_flow` rebuilds a
``FlowResult`` on the subsampled pixel grid: scale, wheel, field and profiles in the same
pixels, so every plot is the original one at a lower resolution.
"""

from __future__ import annotations

import io
import math

import cv2
import numpy as np

from softflow.decay_fit import DecayFit
from softflow.flow_result import FlowResult, MeanField
from softflow.wheel_detect import WheelPose

MAX_SIDE_PX = 192
COMPONENTS = (("r", "profiles_r"), ("t", "profiles_t"))


def pack_flow(result: FlowResult, frame: np.ndarray) -> bytes:
    """npz bytes: ``step``, ``velocity_px_per_s`` and ``frame`` subsampled by ``step``, and
    per component the profiles ``profile_<c>_counts``, ``_r_px``, ``_value``, ``_se``."""
    step = max(1, math.ceil(max(frame.shape) / MAX_SIDE_PX))
    h, w = frame.shape[0] // step, frame.shape[1] // step
    arrays = {
        "step": np.array(step),
        "velocity_px_per_s": result.mean.velocity_px_per_s[:h * step:step, :w * step:step]
        .astype(np.float16),
        "frame": cv2.resize(frame[:h * step, :w * step], (w, h), interpolation=cv2.INTER_AREA),
    }
    for c, name in COMPONENTS:
        profiles = getattr(result, name)
        arrays[f"profile_{c}_counts"] = np.array([len(p[0]) for p in profiles])
        for i, key in enumerate(("r_px", "value", "se")):
            arrays[f"profile_{c}_{key}"] = np.concatenate(
                [np.asarray(p[i], np.float32) for p in profiles] or [np.empty(0, np.float32)])
    buffer = io.BytesIO()
    np.savez_compressed(buffer, **arrays)
    return buffer.getvalue()


def _fit(d: dict | None) -> DecayFit | None:
    if d is None:
        return None
    ci = tuple(np.nan if v is None else v for v in d["ci95_per_m"])
    # results stored before the joint fits over neighbouring angles: each bin alone
    return DecayFit(d["amplitude_mps"], d["rate_per_m"], ci,
                    np.nan if d["r2"] is None else d["r2"], d["points"], d.get("ci95_dof"),
                    tuple(d.get("joint_bins_offset_deg", (0.0,))))


def _profiles(z, c: str, step: int) -> list[tuple[np.ndarray, np.ndarray, np.ndarray]]:
    bounds = np.concatenate([[0], np.cumsum(z[f"profile_{c}_counts"])])
    r, v, se = (z[f"profile_{c}_{key}"].astype(float) for key in ("r_px", "value", "se"))
    return [(r[a:b] / step, v[a:b], se[a:b]) for a, b in zip(bounds[:-1], bounds[1:])]


def unpack_flow(data: dict, blob: bytes) -> tuple[FlowResult, np.ndarray]:
    """The result of ``data`` (``FlowResult.to_dict()``, strict JSON) and ``blob``
    (:func:`pack_flow`) on the subsampled grid, and the subsampled first frame."""
    with np.load(io.BytesIO(blob)) as z:
        step = int(z["step"])
        velocity = z["velocity_px_per_s"].astype(float) / step
        frame = z["frame"]
        profiles = {c: _profiles(z, c, step) for c, _ in COMPONENTS}
    wheel = data["wheel"]
    pose = WheelPose(center_px=tuple(v / step for v in wheel["center_px_first"]),
                     radius_px=wheel["radius_px"] / step,
                     grouser_height_px=wheel["grouser_height_px"] / step,
                     grouser_count=wheel["grouser_count"], grouser_angle_rad=0.0)
    per_beta = data["per_beta"]
    result = FlowResult(
        px_per_m=data["px_per_m"] / step, t_s=np.asarray(data["t_s"], float),
        frame_range=tuple(data["frame_range"]), poses=[pose],
        mean=MeanField(velocity, np.zeros(velocity.shape[:2], np.int32),
                       data["outlier_fraction"], []),
        sled_velocity_mps=tuple(data["sled_velocity_mps"]),
        beta_rad=np.deg2rad([row["beta_deg"] for row in per_beta]),
        radial=[_fit(row["k"]) for row in per_beta],
        tangential=[_fit(row["alpha3"]) for row in per_beta],
        profiles_r=profiles["r"], profiles_t=profiles["t"], grouser=data["grouser_model"],
        alpha12=data["alpha1_alpha2"], alpha12_reason=data.get("alpha1_alpha2_reason"),
        engine=data["engine"], source=data["source"])
    return result, frame
