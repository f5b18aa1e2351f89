"""The cores this process may run on: the default number of ``process`` jobs and the most
threads softflow's kernels use."""

from __future__ import annotations

import os


def available_cores() -> int:
    """Cores this process may run on now (its CPU affinity; all CPUs where there is none)."""
    if hasattr(os, "sched_getaffinity"):
        return max(1, len(os.sched_getaffinity(0)))
    return os.cpu_count() or 1
