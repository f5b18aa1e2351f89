"""softflow: not built yet (see the issues)."""

from softflow.track_slip import NoPeriodicMarksError, TrackSlipResult, measure_track_slip

__all__ = ["NoPeriodicMarksError", "TrackSlipResult", "measure_track_slip"]
