"""softflow: measurements from camera images (slip from the wheel track; docs/track-slip.md;
soil velocity field under the wheel, SOFT; docs/softflow.md).

The names below are loaded on first use (PEP 562), so that a reader of stored flows (the
campaign report) does not load the flow engine and numba (``softflow.numba_layer`` sets
numba's threading layer for every module that uses it).
"""

import importlib

#: each public name -> the module that defines it
_HOMES = {"FlowResult": "softflow.flow_result", "analyse_frames": "softflow.field_analysis",
          "FrameSet": "softflow.frames", "FrameSourceError": "softflow.frames",
          "load_frames": "softflow.frames", "RunImageSlip": "softflow.track_run",
          "run_image_slip": "softflow.track_run", "NoPeriodicMarksError": "softflow.track_slip",
          "TrackSlipResult": "softflow.track_slip", "measure_track_slip": "softflow.track_slip"}

__all__ = sorted(_HOMES)


def __getattr__(name: str):
    if name in _HOMES:
        return getattr(importlib.import_module(_HOMES[name]), name)
    raise AttributeError(f"module 'softflow' has no attribute {name!r}")


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(_HOMES))
