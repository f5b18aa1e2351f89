"""numba as softflow's kernels use it: on the ``workqueue`` threading layer, which survives a
fork. With GNU OpenMP (the layer numba picks first where it is installed) a process that has
measured soil flow aborts when it forks, and ``swtlab process --jobs`` forks its workers
("fork() called from a process already using GNU OpenMP"). workqueue is not for concurrent
calls from several Python threads: run dask workers with one thread each
(docs/scale-out.md). The layer is chosen at the first parallel launch or thread-count
change, so every softflow module that touches numba imports it from here."""

import numba

numba.config.THREADING_LAYER = "workqueue"

__all__ = ["numba"]
