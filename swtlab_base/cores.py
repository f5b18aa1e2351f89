"""The cores this process may run on: the default number of ``process`` jobs, the most
threads softflow's kernels use, and each ``--jobs`` worker's (or dask task's) share of them.
Counts only; a worker applies its share with ``swtlab.pipeline.process.limit_threads``."""

from __future__ import annotations

import os


def available_cores() -> int:
    """Cores this process may run on now (its CPU affinity; all CPUs where there is none)."""
    if hasattr(os, "sched_getaffinity"):
        return max(1, len(os.sched_getaffinity(0)))
    return os.cpu_count() or 1


def threads_per_worker(workers: int) -> int:
    """Threads each of ``workers`` processes sharing this process's cores may run (numba,
    OpenCV, BLAS): the cores split evenly, at least one each."""
    if workers < 1:
        raise ValueError(f"workers {workers} must be >= 1")
    return max(1, available_cores() // workers)

