"""Threads of the soil-flow kernels capped to the cores this process may run on.

numba sizes its thread pool once, from the CPU affinity at import, and OpenCV from the
machine's CPUs; a process pinned later (``taskset``, ``os.sched_setaffinity``, a cluster
worker given fewer cores) would run more threads than it has cores, and a parallel loop is
only as fast as its slowest thread (issue 19 item 6: on a busy 2-core machine, 2 threads
took 2.4x the time of one). :func:`capped` runs a function with numba's and OpenCV's
threads at most ``swtlab_base.cores.available_cores()`` (never more than the caller set),
and restores them after; :func:`limit` sets them, and the loaded BLAS/OpenMP libraries',
for the rest of the process (a ``swtlab process --jobs`` worker's or a dask task's share of
the cores). The results do not depend on the thread count (every parallel loop writes its
own rows).
"""

from __future__ import annotations

import contextlib
import functools

import cv2
from threadpoolctl import threadpool_limits

from softflow.numba_layer import numba
from swtlab_base.cores import available_cores


def limit(threads: int, opencv: bool = True) -> None:
    """numba, OpenCV and the BLAS/OpenMP libraries loaded so far (threadpoolctl limits only
    those) on at most ``threads`` threads in this process from now on (numba's count is per
    calling thread: call it from the thread that runs the kernels). softflow's import has
    chosen numba's fork-safe workqueue layer before this starts its threads. OpenCV's count
    is left as it is when it is ``threads`` already (inherited, see
    :func:`opencv_threads`), or when ``opencv`` is false (a process that will fork after
    using OpenCV's pool must keep the pool it has)."""
    numba.set_num_threads(max(1, min(threads, numba.config.NUMBA_NUM_THREADS)))
    if opencv and cv2.getNumThreads() != max(1, threads):
        cv2.setNumThreads(max(1, threads))
    threadpool_limits(limits=threads)


@contextlib.contextmanager
def opencv_threads(threads: int):
    """OpenCV on ``threads`` threads in this process for the block, and in the processes it
    forks meanwhile. Set it before the fork: a child forked after its parent used OpenCV's
    thread pool hangs when it resizes the pool it inherited (``cv2.setNumThreads``)."""
    before = cv2.getNumThreads()
    cv2.setNumThreads(max(1, threads))
    try:
        yield
    finally:
        cv2.setNumThreads(before)


def capped(fn):
    """``fn`` run with numba and OpenCV on at most ``available_cores()`` threads."""

    @functools.wraps(fn)
    def run(*args, **kwargs):
        cores = available_cores()
        numba_before, cv_before = numba.get_num_threads(), cv2.getNumThreads()
        numba_n, cv_n = min(numba_before, cores), min(max(cv_before, 1), cores)
        if numba_n != numba_before:
            numba.set_num_threads(numba_n)
        if cv_n != cv_before:
            cv2.setNumThreads(cv_n)
        try:
            return fn(*args, **kwargs)
        finally:
            if numba_n != numba_before:
                numba.set_num_threads(numba_before)
            if cv_n != cv_before:
                cv2.setNumThreads(cv_before)

    return run
