"""Soil-flow threads: one frame pair of 1 megapixel (``pair_displacement_px``, deform-lk) on
one thread against the threads :mod:`softflow.threads` allows (the cores available), idle
and under load, and on a process pinned to one core after numba sized its pool.

Cases, each the median wall time of :data:`REPEATS` interleaved calls per setting:

- ``idle``: nothing else started by the bench;
- ``loaded``: one busy-loop process per available core running beside it;
- ``pinned``: this process pinned to one core (``os.sched_setaffinity``) with numba's pool
  at every core: the uncapped call (numba at the pool size) against the capped one.

Issue 19 item 6: more threads never slower (ratio threads / one thread <= 1).
"""

from __future__ import annotations

import os
import subprocess
import sys
import time

import numba
import numpy as np

from softflow.flow_engine import pair_displacement_px
from swtlab_base.cores import available_cores
from virtual_testbed.flow_render import FlowScene, render_flow

REPEATS = 5
BUSY = "while True: pass"


def _pair():
    scene = FlowScene(size_px=(1024, 1024), px_per_m=2000, fps=50, wheel_center_px=(512, 300),
                      wheel_radius_px=200, grouser_count=16, grouser_height_px=16,
                      grouser_model="cosine", seed=21)
    frames = render_flow(scene, 2).frames
    return frames[0], frames[1]


def _median_s(settings: dict, pair) -> dict[str, float]:
    """Median seconds per setting (name -> (function, numba threads)), calls interleaved."""
    seconds = {name: [] for name in settings}
    for _ in range(REPEATS):
        for name, (fn, threads) in settings.items():
            numba.set_num_threads(threads)
            start = time.perf_counter()
            fn(*pair)
            seconds[name].append(time.perf_counter() - start)
    numba.set_num_threads(numba.config.NUMBA_NUM_THREADS)
    return {name: float(np.median(s)) for name, s in seconds.items()}


def main(quick: bool = False) -> dict:
    pair = _pair()
    pair_displacement_px(*pair)  # load the compiled kernels
    cores, pool = available_cores(), numba.config.NUMBA_NUM_THREADS
    both = {"one thread": (pair_displacement_px, 1), "capped": (pair_displacement_px, pool)}
    out = {"cores": cores, "numba_pool": pool, "idle": _median_s(both, pair)}
    busy = [subprocess.Popen([sys.executable, "-c", BUSY]) for _ in range(cores)]
    try:
        out["loaded"] = _median_s(both, pair)
    finally:
        for process in busy:
            process.kill()
            process.wait()
    affinity = os.sched_getaffinity(0)
    os.sched_setaffinity(0, {min(affinity)})
    try:
        out["pinned"] = _median_s({"one thread": (pair_displacement_px, 1),
                                   "uncapped": (pair_displacement_px.__wrapped__, pool),
                                   "capped": (pair_displacement_px, pool)}, pair)
    finally:
        os.sched_setaffinity(0, affinity)
    print(f"1-megapixel pair, deform-lk; {cores} cores available, numba pool {pool} threads")
    for case in ("idle", "loaded", "pinned"):
        s = out[case]
        line = ", ".join(f"{name} {v:.3f} s" for name, v in s.items())
        out[case]["capped_over_one"] = s["capped"] / s["one thread"]
        print(f"{case:7s}: {line}; capped / one thread {out[case]['capped_over_one']:.2f}"
              + (f", uncapped / one thread {s['uncapped'] / s['one thread']:.2f}"
                 if "uncapped" in s else "") + " (issue 19.6: <= 1)")
    return out
