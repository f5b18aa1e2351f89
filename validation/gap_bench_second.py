"""The blind gap-bench on a second signal model: the same hidden truths, conditions and work
folder as ``validation.gap_bench``, the raw runs written by the second rig
(validation/second_rig: underdamped transients, shark-fin grouser load, coloured noise, drift
since zeroing, gain errors, spikes, other rates; docs/second-rig.md) instead of the virtual
testbed. The diagnosis and the scoring are gap_bench's own.

Each run's steady values are the hidden-truth model's curves at the set point
(validation.model_truth); the wheel metadata are the virtual testbed's (BB2-like, 30 N/mm),
so a campaign differs from a gap_bench one only in its signals.
"""

from __future__ import annotations

import shutil
import time
from concurrent.futures import ProcessPoolExecutor, ThreadPoolExecutor
from pathlib import Path

import numpy as np

import terramechanics as tm
from validation.gap_bench import (Design, base_model, conditions, diagnose_campaign, draw_truth,
                                  score)
from validation.model_truth import ModelTruth
from validation.second_rig import Rig, RunCondition, Timeline, WheelGeometry, write_campaign
from validation.second_rig.writers import write_json

DEFAULT_DESIGN = Design()


def rig_conditions(conds, campaign: str) -> list[RunCondition]:
    """Speed-control conditions of the virtual testbed (gap_bench's ``conditions``) as
    second-rig conditions, on the virtual testbed's wheel."""
    from virtual_testbed.rig import BB2_WHEEL

    w = BB2_WHEEL
    wheel = WheelGeometry(name=w.name, radius_m=w.radius_m, width_m=w.width_m,
                          grouser_count=w.grouser_count, grouser_height_m=w.grouser_height_m,
                          stiffness_n_per_mm=w.stiffness_n_per_mm)
    return [RunCondition(c.run_id, c.mode, c.load_n, c.slip_setpoint, multipass=c.multipass,
                         gravity_mps2=c.gravity_mps2, velocity_mps=c.velocity_mps, soil="sand",
                         campaign=campaign, wheel=wheel)
            for c in conds]


def write_second_campaign(out: Path, conds, truth: tm.WheelModel, seed: int, name: str,
                          duration_s: float) -> None:
    """One campaign's raw runs from the second rig under ``out/campaign``, the truth of
    ``truth``'s curves under ``out/truth`` (as the testbed's ``generate_campaign``)."""
    rig = Rig(timeline=Timeline(duration_s=duration_s))
    write_campaign(out, rig_conditions(conds, name), ModelTruth(truth), seed, rig=rig)


def _generate(job) -> None:
    """One campaign; its truth folder is moved out of it."""
    workdir, name, truth, seed, design = job
    out = workdir / name
    write_second_campaign(out, conditions(design), truth, seed, name, design.duration_s)
    (workdir / "labels" / name).mkdir(parents=True, exist_ok=True)
    shutil.move(str(out / "truth"), str(workdir / "labels" / name / "truth"))


def make_campaigns_second(n: int, seed: int, workdir: Path, design: Design = DEFAULT_DESIGN,
                          jobs: int = 2) -> Path:
    """Write ``n`` second-rig campaigns and the labels file (gap_bench's layout, truths and
    per-campaign seeds); return the labels path."""
    workdir.mkdir(parents=True, exist_ok=True)
    tm.save_model(base_model(), workdir / "sim.toml")
    rng = np.random.default_rng(seed)
    truths = [draw_truth(rng) for _ in range(n)]
    work = [(workdir, f"c{i:03d}", truth, seed * 1000 + i, design)
            for i, (truth, _) in enumerate(truths)]
    with ProcessPoolExecutor(jobs) as pool:
        list(pool.map(_generate, work))
    labels = {f"c{i:03d}": label for i, (_, label) in enumerate(truths)}
    return write_json(workdir / "labels" / "labels.json", labels, workdir / "labels")


def run_bench_second(n: int, seed: int, workdir: Path, design: Design = DEFAULT_DESIGN,
                     jobs: int = 2, boot: int = 50) -> dict:
    """Generate on the second rig, diagnose (gap_bench's separate processes), score."""
    t0 = time.perf_counter()
    labels = make_campaigns_second(n, seed, workdir, design, jobs)
    t1 = time.perf_counter()
    names = [f"c{i:03d}" for i in range(n)]
    with ThreadPoolExecutor(jobs) as pool:
        seconds = list(pool.map(lambda name: diagnose_campaign(workdir, name, boot), names))
    t2 = time.perf_counter()
    out = score(labels, workdir)
    out["timing_s"] = {"generate": t1 - t0, "process_and_diagnose": t2 - t1,
                       "per_campaign_mean": float(np.mean(seconds)), "jobs": jobs}
    out["signal_model"] = "second_rig"
    write_json(workdir / "score.json", out, workdir)
    return out
