"""softflow: measurements from camera images (slip from the wheel track; docs/track-slip.md;
soil velocity field under the wheel, SOFT; docs/softflow.md).

The numba kernels run on numba's ``workqueue`` threading layer, which survives a fork: with
GNU OpenMP (the layer numba picks first where it is installed) a process that has measured
soil flow aborts when it forks, and ``swtlab process --jobs`` forks its workers ("fork()
called from a process already using GNU OpenMP"). workqueue is not for concurrent calls
from several Python threads: run dask workers with one thread each (docs/scale-out.md).
"""

import numba

from softflow.field_analysis import FlowResult, analyse_frames
from softflow.frames import FrameSet, FrameSourceError, load_frames
from softflow.track_run import RunImageSlip, run_image_slip
from softflow.track_slip import NoPeriodicMarksError, TrackSlipResult, measure_track_slip

numba.config.THREADING_LAYER = "workqueue"  # chosen at the first parallel launch, not import

__all__ = ["FlowResult", "FrameSet", "FrameSourceError", "analyse_frames", "load_frames",
           "NoPeriodicMarksError", "RunImageSlip", "TrackSlipResult", "measure_track_slip",
           "run_image_slip"]
