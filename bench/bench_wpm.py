"""WPM runtime queries per second: the slip for a required DP, scalar calls in a Python loop
and one vectorised call (1e5 targets), at one load and at random loads; values at a slip."""

from __future__ import annotations

import tempfile
import time
from pathlib import Path

import numpy as np
import pandas as pd

from fitting import fit_results
from terramechanics import shipped_model
from wpm_export import WheelPerformanceModule, inputs_sha256, write_wpm_csv

SLIPS = (-0.10, 0.0, 0.05, 0.10, 0.20, 0.35, 0.60)
LOADS_N = (70.0, 180.0, 300.0)


def _wpm(folder: Path) -> WheelPerformanceModule:
    """WPM of the bb2_sand model's curves at the sample campaign's loads and slips."""
    model = shipped_model("bb2_sand")
    rows = []
    for load in LOADS_N:
        curves = model.curves(load, np.array(SLIPS), 0)
        for i, slip in enumerate(SLIPS):
            rows.append({"wheel": "bb2", "soil": "bb2_sand", "multipass": 0, "load_n": load,
                         "slip": slip, "wheel_load_n": load,
                         **{q: float(curves[q][i]) for q in
                            ("dp_n", "torque_nm", "sinkage_m", "resistance_n")}})
    table = pd.DataFrame(rows)
    path = folder / "wpm.csv"
    write_wpm_csv(fit_results(table), path, inputs_sha256(table), "bench")
    return WheelPerformanceModule.load(path)


def _rate(call, n: int, repeats: int = 3) -> float:
    best = min(_timed(call) for _ in range(repeats))
    return n / best


def _timed(call) -> float:
    start = time.perf_counter()
    call()
    return time.perf_counter() - start


def main(quick: bool = False) -> dict:
    rng = np.random.default_rng(1)
    n_single, n_vector = (200, 10_000) if quick else (2_000, 100_000)
    with tempfile.TemporaryDirectory() as folder:
        wpm = _wpm(Path(folder))
    targets = rng.uniform(-20.0, 45.0, n_vector)
    loads = rng.uniform(70.0, 300.0, n_vector)
    slips = rng.uniform(-0.1, 0.6, n_vector)
    cases = {
        "slip_for dp, scalar loop, 120 N": (lambda: [wpm.slip_for("dp_n", t, 120.0)
                                                     for t in targets[:n_single]], n_single),
        "slip_for dp, scalar loop, random load": (
            lambda: [wpm.slip_for("dp_n", t, w) for t, w in zip(targets[:n_single],
                                                                loads[:n_single])], n_single),
        f"slip_for dp, one call, {n_vector} targets, 120 N": (
            lambda: wpm.slip_for("dp_n", targets, 120.0), n_vector),
        f"slip_for dp, one call, {n_vector} targets, random loads": (
            lambda: wpm.slip_for("dp_n", targets, loads), n_vector),
        f"at_slip (5 quantities), one call, {n_vector} slips, 120 N": (
            lambda: wpm.at_slip(slips, 120.0), n_vector),
    }
    rates = {name: _rate(call, n) for name, (call, n) in cases.items()}
    print(f"{'case':<62}{'queries/s':>14}")
    for name, rate in rates.items():
        print(f"{name:<62}{rate:>14,.0f}")
    keys = ("single_fixed_load_qps", "single_random_load_qps", "vector_fixed_load_qps",
            "vector_random_load_qps", "at_slip_vector_qps")
    return {**dict(zip(keys, rates.values())), "n_single": n_single, "n_vector": n_vector}
