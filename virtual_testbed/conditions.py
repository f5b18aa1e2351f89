"""Test conditions of simulated runs: the domain set point (``swtlab_base.domain.
TestCondition``, the one definition ingest, the results and the database use) with what only
the generator needs (the run's id, the photos and frames it renders)."""

from __future__ import annotations

from dataclasses import dataclass

from swtlab_base.domain import G0_MPS2, TestCondition

#: modes whose slip the testbed imposes through the wheel and sled speeds
SLIP_IMPOSED = ("speed_control", "steered")
#: 40 m/h, the travel velocity of the ESA/ExoMars SWT campaigns.
VELOCITY_40_M_PER_H_MPS = 40.0 / 3600.0


@dataclass(frozen=True, kw_only=True)
class RunCondition(TestCondition):
    """One run: the set point the testbed operator sets (a ``TestCondition``: ``slip_setpoint``
    for speed control and steered runs, ``steer_deg``, the slip angle of the wheel to the
    travel direction, for steered runs), the ``run_id``, and the cameras' share."""

    run_id: str
    #: photos of the track taken after the run (``/camera/track``), driving slip only
    track_photos: int = 0
    #: side-camera frames (``/camera/side``) in the stable phase, soil flow under the wheel
    side_camera_frames: int = 0

    @classmethod
    def of(cls, run_id: str, mode: str, load_set_n: float, multipass: int = 0,
           slip_setpoint: float | None = None,
           velocity_set_mps: float = VELOCITY_40_M_PER_H_MPS, gravity_mps2: float = G0_MPS2,
           steer_deg: float | None = None, track_photos: int = 0,
           side_camera_frames: int = 0) -> RunCondition:
        """The generator's short form: run id first, no passes and 40 m/h by default."""
        return cls(mode=mode, load_set_n=load_set_n, multipass=multipass,
                   velocity_set_mps=velocity_set_mps, slip_setpoint=slip_setpoint,
                   gravity_mps2=gravity_mps2, steer_deg=steer_deg, run_id=run_id,
                   track_photos=track_photos, side_camera_frames=side_camera_frames)

    def __post_init__(self) -> None:
        super().__post_init__()
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

    def to_dict(self) -> dict:
        """The truth file's ``condition`` record (docs/virtual-testbed.md), in its key names."""
        return {"run_id": self.run_id, "mode": self.mode, "load_n": self.load_set_n,
                "multipass": self.multipass, "slip_setpoint": self.slip_setpoint,
                "velocity_mps": self.velocity_set_mps, "gravity_mps2": self.gravity_mps2,
                "steer_deg": self.steer_deg, "track_photos": self.track_photos,
                "side_camera_frames": self.side_camera_frames}
