"""softflow: measurements from camera images (slip from the wheel track; docs/track-slip.md;
soil velocity field under the wheel, SOFT; docs/softflow.md)."""

from softflow.field_analysis import FlowResult, analyse_frames
from softflow.frames import FrameSet, FrameSourceError, load_frames
from softflow.track_run import RunImageSlip, run_image_slip
from softflow.track_slip import NoPeriodicMarksError, TrackSlipResult, measure_track_slip

__all__ = ["FlowResult", "FrameSet", "FrameSourceError", "analyse_frames", "load_frames",
           "NoPeriodicMarksError", "RunImageSlip", "TrackSlipResult", "measure_track_slip",
           "run_image_slip"]
