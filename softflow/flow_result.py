"""What one soil-flow measurement holds: the mean velocity field of the frame pairs
(:class:`MeanField`) and the result of a frame range (:class:`FlowResult`, what the database
stores through ``to_dict()``). Data only, without the flow engine's numba kernels, so that a
reader of stored flows (``softflow.flow_archive``, the campaign report) loads neither numba
nor the engine."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from softflow.decay_fit import DecayFit
from softflow.wheel_detect import WheelPose


@dataclass
class MeanField:
    """Per-pixel mean velocity of the valid vectors of all pairs (camera frame)."""

    velocity_px_per_s: np.ndarray  # (H, W, 2), NaN where no valid vector
    count: np.ndarray  # (H, W) valid pairs per pixel
    outlier_fraction: float
    pair_velocities_px_per_s: list[np.ndarray]  # per pair, NaN where masked or rejected


@dataclass
class FlowResult:
    """Everything measured on one frame range; ``to_dict()`` is what the database stores."""

    px_per_m: float
    t_s: np.ndarray
    frame_range: tuple[int, int]
    poses: list[WheelPose]
    mean: MeanField
    sled_velocity_mps: tuple[float, float]  # (x right, y down), image axes
    beta_rad: np.ndarray
    radial: list[DecayFit | None]
    tangential: list[DecayFit | None]
    profiles_r: list = field(default_factory=list)
    profiles_t: list = field(default_factory=list)
    grouser: dict | None = None
    alpha12: dict | None = None
    engine: str = "deform-lk"
    source: str = ""
    eps_vol_p: np.ndarray | None = None  # per beta bin, compression positive
    eps_source: str | None = None  # "given" or "estimated"
    eps_depth_m: float | None = None  # estimated: taken this far outside the wheel
    eps_bound: np.ndarray | None = None  # estimated: uncertainty bound per beta bin
    eps_reason: list = field(default_factory=list)  # per bin: why eps is not resolved
    alpha12_reason: str | None = None  # why alpha12 is None
    radial_reason: list = field(default_factory=list)  # per bin: why no k (None: fitted)
    tangential_reason: list = field(default_factory=list)

    def to_dict(self) -> dict:
        p0 = self.poses[0]
        nan = np.full(len(self.beta_rad), np.nan)
        eps = nan if self.eps_vol_p is None else self.eps_vol_p
        bound = nan if self.eps_bound is None else self.eps_bound
        return {
            "schema": "swtlab.softflow/1",
            "source": self.source,
            "frame_range": list(self.frame_range),
            "t_s": [float(self.t_s[0]), float(self.t_s[-1])],
            "pairs": len(self.t_s) - 1,
            "engine": self.engine,
            "px_per_m": self.px_per_m,
            "outlier_fraction": self.mean.outlier_fraction,
            "sled_velocity_mps": list(self.sled_velocity_mps),
            "wheel": {"center_px_first": list(p0.center_px),
                      "center_px_last": list(self.poses[-1].center_px),
                      "radius_px": p0.radius_px, "grouser_count": p0.grouser_count,
                      "grouser_height_px": p0.grouser_height_px},
            "angle_convention": "beta: 0 at image right, counter-clockwise; velocities in the "
                                "bin (world) frame about the axle, v_r outwards, v_theta along "
                                "e_theta (theta from the downward vertical towards travel)",
            "per_beta": [
                {"beta_deg": float(np.rad2deg(b)),
                 "k": r.to_dict() if r else None,
                 "k_reason": rr,
                 "alpha3": t.to_dict() if t else None,
                 "alpha3_reason": tr,
                 "eps_vol_p": None if np.isnan(e) else float(e),
                 "eps_vol_p_bound": None if np.isnan(eb) else float(eb),
                 "eps_vol_p_reason": er}
                for b, r, t, e, eb, rr, tr, er in zip(
                    self.beta_rad, self.radial, self.tangential, eps, bound,
                    self._reasons(self.radial_reason), self._reasons(self.tangential_reason),
                    self._reasons(self.eps_reason))],
            "alpha1_alpha2": self.alpha12,
            "alpha1_alpha2_reason": self.alpha12_reason,
            "eps_vol_p_source": self.eps_source,
            "eps_vol_p_depth_m": self.eps_depth_m,
            "grouser_model": self.grouser,
        }


    def _reasons(self, reasons: list) -> list:
        return reasons or [None] * len(self.beta_rad)

    def resolved_eps(self) -> np.ndarray | None:
        """``eps_vol_p`` where it is resolved (``eps_reason`` None), else NaN."""
        if self.eps_vol_p is None:
            return None
        return np.where([r is None for r in self._reasons(self.eps_reason)], self.eps_vol_p,
                        np.nan)
