"""Ingest throughput: samples/s and MB/s on a 100-run synthetic campaign at 1 kHz.

The campaign is written once by the virtual testbed into ``bench/.cache/`` and
reused. Timed: ``ingest.read_run`` per run (decode, validate, calibrate, common
time base, derived signals), one process, warm file cache.
"""

from __future__ import annotations

import time
from pathlib import Path

import numpy as np

import ingest
from virtual_testbed.campaign import generate_campaign
from virtual_testbed.conditions import RunCondition
from virtual_testbed.sensors import Rates

CACHE = Path(__file__).parent / ".cache"
RATE_HZ = 1000.0
SEED = 1


def _campaign(n_runs: int, form: str) -> list[Path]:
    folder = CACHE / f"ingest_{form}_{n_runs}runs_{int(RATE_HZ)}hz_seed{SEED}"
    marker = folder / "complete"
    if not marker.exists():
        rng = np.random.default_rng(SEED)
        conditions = [RunCondition(run_id=f"bench_{i:03d}", mode="speed_control",
                                   load_n=float(rng.choice([70.0, 180.0, 300.0])),
                                   multipass=int(rng.integers(0, 2)),
                                   slip_setpoint=float(rng.uniform(-0.1, 0.7)))
                      for i in range(n_runs)]
        rates = Rates(*(RATE_HZ,) * 6)
        print(f"writing {n_runs} {form} runs at {RATE_HZ:.0f} Hz into {folder} (once)")
        generate_campaign(folder, conditions, SEED, rates=rates, form=form)
        marker.touch()
    return ingest.find_runs(folder / "campaign")


def _size_bytes(path: Path) -> int:
    return path.stat().st_size if path.is_file() else sum(
        p.stat().st_size for p in path.rglob("*") if p.is_file())


def _measure(paths: list[Path]) -> dict:
    samples = 0
    start = time.perf_counter()
    for path in paths:
        run = ingest.read_run(path)
        samples += sum(len(frame) for frame in run.streams.values())  # time stamps, all fields
    seconds = time.perf_counter() - start
    megabytes = sum(_size_bytes(p) for p in paths) / 1e6
    return {"runs": len(paths), "seconds": seconds, "samples": samples, "megabytes": megabytes,
            "samples_per_s": samples / seconds, "mb_per_s": megabytes / seconds,
            "runs_per_s": len(paths) / seconds}


def main(quick: bool = False) -> dict:
    results = {"mcap": _measure(_campaign(10 if quick else 100, "mcap")),
               "csv": _measure(_campaign(5 if quick else 20, "csv"))}
    print(f"{'form':5} {'runs':>5} {'samples':>11} {'MB':>8} {'s':>7} {'samples/s':>11} "
          f"{'MB/s':>7} {'runs/s':>7}")
    for form, r in results.items():
        print(f"{form:5} {r['runs']:5d} {r['samples']:11d} {r['megabytes']:8.1f} "
              f"{r['seconds']:7.2f} {r['samples_per_s']:11.3g} {r['mb_per_s']:7.2f} "
              f"{r['runs_per_s']:7.2f}")
    return results
