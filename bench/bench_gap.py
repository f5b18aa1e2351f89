"""Time of one gap diagnosis (sim_gap.diagnose) of a 100-run campaign with all six candidate
effects under every law of each (20 singles, 80 pairs on the one-law-at-a-time design;
0.11-0.12, without Bekker's lugs with slip-sinkage, 19 and 75; 0.10, without the
depth-varying bulldozing laws, 17 and 65; until 0.10.0, without the load-varying laws, 13
and 45):
5 loads x 5 slips x multipass {0, 1} x gravity {g0, Mars}, measured values from the model
with a hidden slip-sinkage + bulldozing pair and 0.5 %-of-load noise. Goal: under 60 s on
two cores (``jobs=2``); the CPU seconds of the fits are printed too (wall time on a shared
machine depends on the other load)."""

from __future__ import annotations

import resource
import time

import numpy as np
import pandas as pd

import terramechanics as tm
from sim_gap.diagnose import Settings, diagnose
from sim_gap.simulated import Simulated
from swtlab_base.domain.gravity import G0_MPS2, MARS_GRAVITY_MPS2

LOADS_N = (80.0, 140.0, 200.0, 260.0, 320.0)
SLIPS = (0.1, 0.25, 0.4, 0.55, 0.7)
GOAL_S = 60.0
JOBS = 2


def _cpu_s() -> float:
    """CPU seconds of this process and its finished workers."""
    own, kids = (resource.getrusage(w) for w in (resource.RUSAGE_SELF,
                                                 resource.RUSAGE_CHILDREN))
    return own.ru_utime + own.ru_stime + kids.ru_utime + kids.ru_stime


def campaign(truth: tm.WheelModel, loads=LOADS_N, slips=SLIPS, seed: int = 1) -> pd.DataFrame:
    rng = np.random.default_rng(seed)
    grid = np.meshgrid(loads, slips, (0, 1), (G0_MPS2, MARS_GRAVITY_MPS2), indexing="ij")
    load, slip, mp, g = (a.ravel() for a in grid)
    c = truth.curves(load, slip, mp, g)
    points = pd.DataFrame({"run_id": [f"r{i:03d}" for i in range(load.size)],
                           "load_set_n": load, "wheel_load_n": load, "multipass": mp.astype(int),
                           "gravity_mps2": g, "slip": slip})
    sd = {"dp_n": 0.005 * load, "torque_nm": 0.005 * load * truth.wheel.radius_m,
          "sinkage_m": np.full(load.size, 1e-4), "resistance_n": 0.005 * load}
    for q, s in sd.items():
        points[q] = c[q] + rng.normal(0, 1, load.size) * s
        points[f"{q}_se"] = 0.2 * s
    points.attrs.update(source="bench", sinkage_relative=False)
    return points


def main(quick: bool = False) -> dict:
    base = tm.shipped_model("bb2_sand").with_effects(**{n: False for n in tm.EFFECTS})
    truth = base.with_soil(kphi=2.2e7).with_effects(slip_sinkage={"n1": 0.5},
                                                    bulldozing={"coefficient": 0.3})
    points = campaign(truth, LOADS_N[::2] if quick else LOADS_N)
    start, cpu0 = time.perf_counter(), _cpu_s()
    report = diagnose(points, Simulated(base), None, Settings(n_boot=200, jobs=JOBS))
    seconds, cpu = time.perf_counter() - start, _cpu_s() - cpu0
    out = {"runs": len(points), "candidates": len(report["hypotheses"]) - 1,
           "effects_tested": 6 - len(report["untestable_effects"]),
           "verdict": report["verdict"], "seconds": seconds, "cpu_seconds": cpu, "jobs": JOBS,
           "goal_s": GOAL_S, "within_goal": seconds < GOAL_S}
    print(f"{out['runs']} runs, {out['effects_tested']} effects, {out['candidates']} candidates:"
          f" {seconds:.1f} s wall on {JOBS} workers, {cpu:.1f} CPU s (goal < {GOAL_S:.0f} s),"
          f" verdict {report['verdict']} (p = {report['decision']['probability']:.2f})")
    return out


if __name__ == "__main__":
    main()
