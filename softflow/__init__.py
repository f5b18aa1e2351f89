"""softflow: measurements from camera images (slip from the wheel track; docs/track-slip.md)."""

from softflow.track_run import RunImageSlip, run_image_slip
from softflow.track_slip import NoPeriodicMarksError, TrackSlipResult, measure_track_slip

__all__ = ["NoPeriodicMarksError", "RunImageSlip", "TrackSlipResult", "measure_track_slip",
           "run_image_slip"]
