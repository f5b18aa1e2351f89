"""Processing time: the sample campaign and a 100-run synthetic 1 kHz campaign, against a
naive per-sample baseline, in one table.

swtlab: ``ingest.read_run`` + ``run_results.process_run`` per run (vectorised), and the whole
``swtlab process`` into a fresh SQLite database. Baseline: what a first script does -- decode
every MCAP message into one Python dict per sample, finite-difference rates, a fixed window
(second half of the run), means and naive standard errors in Python loops; no calibration,
tare, gap handling, window detection or autocorrelation. It reads only MCAP runs.
"""

from __future__ import annotations

import contextlib
import io
import json
import math
import tempfile
import time
from pathlib import Path

from mcap.reader import make_reader

import ingest
from bench.bench_ingest import _campaign
from run_results import process_run
from swtlab_cli.main import main as swtlab

SAMPLE = Path(__file__).resolve().parents[1] / "sample_data" / "campaign"


def _swtlab_runs(paths: list[Path]) -> float:
    start = time.perf_counter()
    for path in paths:
        process_run(ingest.read_run(path))
    return time.perf_counter() - start


def _swtlab_process_db(campaign: Path) -> float:
    with tempfile.TemporaryDirectory() as folder, contextlib.redirect_stdout(io.StringIO()):
        start = time.perf_counter()
        swtlab(["process", str(campaign), "--db", f"sqlite:///{folder}/db.sqlite", "--quiet"])
        return time.perf_counter() - start


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


def _naive(paths: list[Path]) -> float:
    start = time.perf_counter()
    for path in paths:
        _naive_run(path)
    return time.perf_counter() - start


def main(quick: bool = False) -> dict:
    sample = ingest.find_runs(SAMPLE)
    synthetic = _campaign(10 if quick else 100, "mcap")
    sample_mcap = [p for p in sample if p.suffix == ".mcap"]
    rows = {
        "sample: swtlab read+process": (len(sample), _swtlab_runs(sample)),
        "sample: swtlab process -> SQLite": (len(sample), _swtlab_process_db(SAMPLE)),
        "sample: naive per-sample (MCAP runs)": (len(sample_mcap), _naive(sample_mcap)),
        "1 kHz synthetic: swtlab read+process": (len(synthetic), _swtlab_runs(synthetic)),
        "1 kHz synthetic: swtlab process -> SQLite":
            (len(synthetic), _swtlab_process_db(synthetic[0].parent)),
        "1 kHz synthetic: naive per-sample": (len(synthetic), _naive(synthetic)),
    }
    print(f"{'case':44} {'runs':>5} {'total s':>9} {'s/run':>8}")
    for case, (runs, seconds) in rows.items():
        print(f"{case:44} {runs:5d} {seconds:9.2f} {seconds / runs:8.3f}")
    return {case: {"runs": runs, "seconds": s, "seconds_per_run": s / runs}
            for case, (runs, s) in rows.items()}
