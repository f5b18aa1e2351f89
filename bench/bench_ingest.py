"""Ingest throughput: samples/s and MB/s on a 100-run synthetic campaign at 1 kHz, against
the MCAP + orjson decode limit measured in the same run.

The campaign is written once by the virtual testbed into ``bench/.cache/`` and
reused. Timed: ``ingest.read_run`` per run (decode, validate, calibrate, common
time base, derived signals), one process, warm file cache. The decode limit: every message
of the same files read with the ``mcap`` reader (CRCs checked, as ingest does), each JSON
block parsed by ``orjson`` and each of its fields made one numpy array; nothing checked,
sorted, calibrated or derived. It is the limit of reading through orjson's Python objects;
ingest parses blocks of short numbers without them (``ingest.json_blocks``), so it can go
below 1x. Wall and CPU seconds, the fastest of :data:`REPEATS`
interleaved passes of each (CPU: on a shared machine, where wall time includes waiting).
Issue 19 item 4: ingest within 1.3x the limit.
"""

from __future__ import annotations

import time
from pathlib import Path

import numpy as np
import orjson
from mcap.reader import make_reader

import ingest
from virtual_testbed.campaign import generate_campaign
from virtual_testbed.conditions import RunCondition
from virtual_testbed.sensors import Rates

CACHE = Path(__file__).parent / ".cache"
RATE_HZ = 1000.0
SEED = 1
REPEATS = 2


def _campaign(n_runs: int, form: str) -> list[Path]:
    folder = CACHE / f"ingest_{form}_{n_runs}runs_{int(RATE_HZ)}hz_seed{SEED}"
    marker = folder / "complete"
    if not marker.exists():
        rng = np.random.default_rng(SEED)
        conditions = [RunCondition.of(run_id=f"bench_{i:03d}", mode="speed_control",
                                      load_set_n=float(rng.choice([70.0, 180.0, 300.0])),
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


def _read_all(paths: list[Path]) -> int:
    """``ingest.read_run`` of every run; the samples read (time stamps, all fields)."""
    return sum(sum(len(frame) for frame in ingest.read_run(path).streams.values())
               for path in paths)


def _decode_limit(paths: list[Path]) -> int:
    """Every JSON block of every run decoded and made arrays, nothing else; the values."""
    values = 0
    for path in paths:
        with open(path, "rb") as stream:
            for _, channel, message in make_reader(stream, validate_crcs=True).iter_messages(
                    log_time_order=False):
                if channel.message_encoding == "json":
                    block = orjson.loads(message.data)
                    if isinstance(block, dict) and "t_ns" in block:
                        for name, samples in block.items():
                            values += np.array(samples, np.int64 if name == "t_ns"
                                               else np.float64).size
    return values


def _timed(work, paths: list[Path]) -> tuple[float, float, int]:
    wall, cpu = time.perf_counter(), time.process_time()
    count = work(paths)
    return time.perf_counter() - wall, time.process_time() - cpu, count


def _measure(paths: list[Path], limit: bool = False) -> dict:
    passes = [(_timed(_read_all, paths), _timed(_decode_limit, paths) if limit else None)
              for _ in range(REPEATS)]  # interleaved: both see the same load
    seconds, cpu_s = (min(p[0][i] for p in passes) for i in (0, 1))
    samples = passes[0][0][2]
    megabytes = sum(_size_bytes(p) for p in paths) / 1e6
    out = {"runs": len(paths), "seconds": seconds, "cpu_s": cpu_s, "samples": samples,
           "megabytes": megabytes, "samples_per_s": samples / seconds,
           "mb_per_s": megabytes / seconds, "runs_per_s": len(paths) / seconds}
    if limit:
        out["limit_seconds"], out["limit_cpu_s"] = (min(p[1][i] for p in passes)
                                                    for i in (0, 1))
        out["limit_values"] = passes[0][1][2]
        out["ratio_wall"] = seconds / out["limit_seconds"]
        out["ratio_cpu"] = cpu_s / out["limit_cpu_s"]
    return out


def main(quick: bool = False) -> dict:
    results = {"mcap": _measure(_campaign(10 if quick else 100, "mcap"), limit=True),
               "csv": _measure(_campaign(5 if quick else 20, "csv"))}
    print(f"{'form':5} {'runs':>5} {'samples':>11} {'MB':>8} {'s':>7} {'CPU s':>7} "
          f"{'samples/s':>11} {'MB/s':>7} {'runs/s':>7}")
    for form, r in results.items():
        print(f"{form:5} {r['runs']:5d} {r['samples']:11d} {r['megabytes']:8.1f} "
              f"{r['seconds']:7.2f} {r['cpu_s']:7.2f} {r['samples_per_s']:11.3g} "
              f"{r['mb_per_s']:7.2f} {r['runs_per_s']:7.2f}")
    m = results["mcap"]
    print(f"MCAP + orjson decode limit ({m['limit_values']} values): {m['limit_seconds']:.2f} s "
          f"wall, {m['limit_cpu_s']:.2f} s CPU ({m['limit_values'] / m['limit_cpu_s']:.3g} "
          "values/s of CPU)")
    print(f"ingest / decode limit: {m['ratio_wall']:.2f} wall, {m['ratio_cpu']:.2f} CPU "
          "(issue 19.4: <= 1.3)")
    return results
