"""Processing time: the sample campaign and a 100-run synthetic 1 kHz campaign, against a
naive per-sample baseline, in one table; ``swtlab process --jobs 2`` against ``--jobs 1``;
``swtlab --help`` against ``python -c pass``.

swtlab: ``swtlab.pipeline.process.process_file`` per run (read, stable phase, results; no
soil flow), wall and CPU seconds, and the whole ``swtlab process`` into a fresh SQLite
database with one worker and with two (wall: the throughput a user waits for). Baseline:
what a first script does -- decode every MCAP message into one Python dict per sample,
finite-difference rates, a fixed window (second half of the run), means and naive standard
errors in Python loops; no calibration, tare, gap handling, window detection or
autocorrelation. It reads only MCAP runs.
"""

from __future__ import annotations

import contextlib
import io
import json
import math
import os
import resource
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from mcap.reader import make_reader

import ingest
from bench.bench_ingest import _campaign
from swtlab_base.cores import threads_per_worker
from swtlab.pipeline.process import ProcessSettings, process_file
from swtlab_cli.main import main as swtlab

SAMPLE = Path(__file__).resolve().parents[1] / "sample_data" / "campaign"


def _timed(work) -> tuple[float, float]:
    """(wall, CPU of this process) seconds of ``work()``."""
    wall, cpu = time.perf_counter(), time.process_time()
    work()
    return time.perf_counter() - wall, time.process_time() - cpu


def _swtlab_runs(paths: list[Path]) -> tuple[float, float]:
    settings = ProcessSettings(max_frames=0)
    return _timed(lambda: [process_file(path, settings) for path in paths])


def _children_cpu_s() -> float:
    usage = resource.getrusage(resource.RUSAGE_CHILDREN)
    return usage.ru_utime + usage.ru_stime


def _swtlab_process_db(campaign: Path, jobs: int = 1) -> tuple[float, float, float]:
    """Wall, CPU of this process (the writer) and CPU of its worker processes, seconds, of
    ``swtlab process --jobs``."""
    children = _children_cpu_s()
    with tempfile.TemporaryDirectory() as folder, contextlib.redirect_stdout(io.StringIO()):
        wall, cpu = _timed(lambda: swtlab(["process", str(campaign), "--db",
                                           f"sqlite:///{folder}/db.sqlite", "--quiet",
                                           "--jobs", str(jobs)]))
    return wall, cpu, _children_cpu_s() - children


def _start_up(argv: list[str], repeats: int = 7) -> float:
    """Best wall seconds of ``python argv`` (a fresh interpreter each time)."""
    best = math.inf
    for _ in range(repeats):
        start = time.perf_counter()
        subprocess.run([sys.executable, *argv], check=True, stdout=subprocess.DEVNULL,
                       cwd=Path(__file__).resolve().parents[1])
        best = min(best, time.perf_counter() - start)
    return best


def _naive_run(path: Path) -> dict[str, tuple[float, float]]:
    """Per-sample Python: every sample a dict, finite differences, fixed second-half window."""
    samples: dict[str, list[dict]] = {}
    metadata = {}
    with path.open("rb") as handle:
        reader = make_reader(handle)
        for record in reader.iter_metadata():
            metadata[record.name] = record.metadata
        for _schema, channel, message in reader.iter_messages():
            if channel.topic.startswith("/camera/"):
                continue
            block = json.loads(message.data)
            for i in range(len(block["t_ns"])):
                samples.setdefault(channel.topic, []).append(
                    {k: (v[i] * 1e-9 if k == "t_ns" else float(v[i])) for k, v in block.items()})
    radius_m = float(metadata["swt.wheel"]["radius_m"])
    half = samples["/tether/force"][-1]["t_ns"] / 2.0

    def window_mean(topic: str, field: str, transform=lambda x: x) -> tuple[float, float]:
        values = [transform(s[field]) for s in samples[topic] if s["t_ns"] >= half]
        mean = sum(values) / len(values)
        var = sum((v - mean) ** 2 for v in values) / (len(values) - 1)
        return mean, math.sqrt(var / len(values))

    def rate(topic: str, field: str) -> list[tuple[float, float]]:
        rows = [s for s in samples[topic] if s["t_ns"] >= half]
        return [((a["t_ns"] + b["t_ns"]) / 2, (b[field] - a[field]) / (b["t_ns"] - a["t_ns"]))
                for a, b in zip(rows, rows[1:])]

    omega = sum(r for _, r in rate("/wheel/encoder", "angle")) / len(rate("/wheel/encoder",
                                                                          "angle"))
    velocity = sum(r for _, r in rate("/sled/encoder", "position")) / len(
        rate("/sled/encoder", "position"))
    surface = radius_m * omega
    out = {"slip": ((surface - velocity) / max(surface, velocity), 0.0),
           "dp_n": window_mean("/tether/force", "dp"),
           "torque_nm": window_mean("/hub/wrench", "ty"),
           "wheel_load_n": window_mean("/hub/wrench", "fz"),
           "hub_angle_rad": window_mean("/suspension/angle", "angle")}
    out["resistance_n"] = (out["torque_nm"][0] / radius_m - out["dp_n"][0], 0.0)
    return out


def _naive(paths: list[Path]) -> tuple[float, float]:
    return _timed(lambda: [_naive_run(path) for path in paths])


def main(quick: bool = False) -> dict:
    sample = ingest.find_runs(SAMPLE)
    synthetic = _campaign(10 if quick else 100, "mcap")
    sample_mcap = [p for p in sample if p.suffix == ".mcap"]
    process_file(synthetic[0], ProcessSettings(max_frames=0))   # imports, caches: not timed
    rows = {
        "sample: swtlab process_file": (len(sample), _swtlab_runs(sample)),
        "sample: swtlab process -> SQLite, --jobs 1":
            (len(sample), _swtlab_process_db(SAMPLE, 1)[:2]),
        "sample: naive per-sample (MCAP runs)": (len(sample_mcap), _naive(sample_mcap)),
        "1 kHz synthetic: swtlab process_file": (len(synthetic), _swtlab_runs(synthetic)),
        "1 kHz synthetic: naive per-sample": (len(synthetic), _naive(synthetic)),
    }
    jobs1 = _swtlab_process_db(synthetic[0].parent, 1)
    jobs2 = _swtlab_process_db(synthetic[0].parent, 2)
    rows["1 kHz synthetic: swtlab process -> SQLite, --jobs 1"] = (len(synthetic), jobs1[:2])
    rows["1 kHz synthetic: swtlab process -> SQLite, --jobs 2"] = (len(synthetic), jobs2[:2])
    rows["  --jobs 2: CPU of its 2 worker processes"] = (len(synthetic), (math.nan, jobs2[2]))
    print(f"{'case':52} {'runs':>5} {'wall s':>8} {'CPU s':>8} {'wall s/run':>10} "
          f"{'CPU s/run':>9}")
    for case, (runs, (wall, cpu)) in rows.items():
        print(f"{case:52} {runs:5d} {wall:8.2f} {cpu:8.2f} {wall / runs:10.3f} "
              f"{cpu / runs:9.3f}")
    out = {case: {"runs": runs, "seconds": wall, "cpu_seconds": cpu,
                  "seconds_per_run": wall / runs, "cpu_seconds_per_run": cpu / runs}
           for case, (runs, (wall, cpu)) in rows.items()}
    cpu_ratio = (rows["1 kHz synthetic: swtlab process_file"][1][1]
                 / rows["1 kHz synthetic: naive per-sample"][1][1])
    speedup = jobs1[0] / jobs2[0]
    # on 2 idle cores --jobs 2 takes about (writer + workers CPU) / 2, --jobs 1 its CPU
    idle_speedup = (jobs1[1] + jobs1[2]) / ((jobs2[1] + jobs2[2]) / 2.0)
    help_s, pass_s = _start_up(["-m", "swtlab_cli.main", "--help"]), _start_up(["-c", "pass"])
    print(f"per-run CPU, swtlab / naive (1 kHz synthetic): {cpu_ratio:.2f} (goal <= 0.5)")
    print(f"throughput --jobs 2 / --jobs 1 (1 kHz synthetic): {speedup:.2f} measured (wall, "
          f"on a machine with load {os.getloadavg()[0]:.1f}), {idle_speedup:.2f} on 2 idle "
          "cores from the CPU seconds (goal >= 1.7 on 2 idle cores); numba, OpenCV and BLAS "
          f"threads per worker: {threads_per_worker(1)} with --jobs 1, "
          f"{threads_per_worker(2)} with --jobs 2")
    print(f"swtlab --help {help_s:.3f} s, python -c pass {pass_s:.3f} s: "
          f"{help_s / pass_s:.1f}x (goal: <= 0.3 s)")
    out["summary"] = {"cpu_ratio_vs_naive": cpu_ratio, "jobs2_over_jobs1_throughput": speedup,
                      "jobs2_over_jobs1_idle_cores_from_cpu": idle_speedup,
                      "threads_per_worker_jobs1": threads_per_worker(1),
                      "threads_per_worker_jobs2": threads_per_worker(2),
                      "load_average": os.getloadavg()[0],
                      "help_s": help_s, "python_pass_s": pass_s,
                      "help_over_pass": help_s / pass_s}
    return out
