"""Test conditions of simulated runs."""

from __future__ import annotations

from dataclasses import dataclass

from swtlab_base.domain import G0_MPS2, MODES
#: modes whose slip the testbed imposes through the wheel and sled speeds
SLIP_IMPOSED = ("speed_control", "steered")
#: 40 m/h, the travel velocity of the ESA/ExoMars SWT campaigns.
VELOCITY_40_M_PER_H_MPS = 40.0 / 3600.0


@dataclass(frozen=True)
class RunCondition:
    """One run: what the testbed operator sets (``slip_setpoint`` for speed control and steered
    runs, ``steer_deg``, the slip angle of the wheel to the travel direction, for steered runs)."""

    run_id: str
    mode: str
    load_n: float
    multipass: int = 0
    slip_setpoint: float | None = None
    velocity_mps: float = VELOCITY_40_M_PER_H_MPS
    gravity_mps2: float = G0_MPS2
    steer_deg: float | None = None
    #: photos of the track taken after the run (``/camera/track``), driving slip only
    track_photos: int = 0
    #: side-camera frames (``/camera/side``) in the stable phase, soil flow under the wheel
    side_camera_frames: int = 0

    def __post_init__(self) -> None:
        if self.mode not in MODES:
            raise ValueError(f"mode {self.mode!r} not in {MODES}")
        if (self.mode in SLIP_IMPOSED) != (self.slip_setpoint is not None):
            raise ValueError("slip_setpoint is required for speed_control and steered, and only "
                             "there")
        if (self.mode == "steered") != (self.steer_deg is not None):
            raise ValueError("steer_deg is required for steered runs and only there")
        if self.track_photos and not (self.mode in SLIP_IMPOSED and self.slip_setpoint >= 0):
            raise ValueError("track photos are rendered for a driving slip set point >= 0")
        if self.side_camera_frames < 0 or self.side_camera_frames == 1:
            raise ValueError("side_camera_frames is 0 or at least 2 (a flow needs a frame pair)")
        if self.slip_setpoint is not None and not -1.0 < self.slip_setpoint < 1.0:
            raise ValueError(f"slip_setpoint {self.slip_setpoint} outside (-1, 1)")
