"""WPM runtime queries per second, each beside its baseline in the same run (issue 19.1):

- scalar slip for a required DP in a Python loop at one load (``slip_for_one``, and
  ``slip_for`` with its array wrapping) vs ``np.polyval`` on a 2001-point grid plus
  ``np.interp`` per query, and vs ``np.interp`` on that grid precomputed; goal >= 100 k/s;
- one call with 1e5 targets at one load vs ``np.interp`` on the precomputed grid (goal >=
  0.5x);
- one call with 1e5 targets at 1e5 random loads vs PCHIP rows: the tested curves' values on
  the 2001-point grid (the issue's baseline) interpolated across load by
  ``PchipInterpolator`` for every query, the first crossing by linear interpolation (goal
  >= 3x); also on a 257-point grid (coarser: slip to about 1e-4), printed for comparison;
- values of every quantity at 1e5 slips (no baseline).

The baselines answer less (no braked-branch jump, no turning points, grid accuracy): they
bound the cost of a table look-up, they are not alternatives.
"""

from __future__ import annotations

import tempfile
import time
import warnings
from pathlib import Path

import numpy as np
import pandas as pd
from scipy.interpolate import PchipInterpolator

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


def _polyval_interp(curve, grid: np.ndarray):
    """Baseline: per query, the curve on the grid by ``np.polyval``, then ``np.interp`` on
    its rising part."""
    a = np.array(curve.coefficients)[::-1]

    def one(t: float) -> float:
        values = np.polyval(a, grid)
        return float(np.interp(t, values, grid))
    return one


def _pchip_rows(curves: dict, grid: np.ndarray, targets: np.ndarray, loads: np.ndarray,
                chunk: int = 4096) -> np.ndarray:
    """Baseline: tested values on the grid, PCHIP across load per query, first crossing."""
    tested = np.array(sorted(curves))
    values = np.array([curves[w].evaluate(grid) for w in tested])
    pchip = PchipInterpolator(tested, values, axis=0)
    out = np.empty(targets.size)
    for i in range(0, targets.size, chunk):
        rows = pchip(loads[i:i + chunk])
        t = targets[i:i + chunk, None]
        first = np.argmax(rows >= t, axis=1)
        k = np.clip(first, 1, grid.size - 1)
        pick = np.arange(k.size)
        f0, f1 = rows[pick, k - 1], rows[pick, k]
        out[i:i + chunk] = grid[k - 1] + (t[:, 0] - f0) / (f1 - f0) * (grid[k] - grid[k - 1])
    return out


def main(quick: bool = False) -> dict:
    rng = np.random.default_rng(1)
    n_single, n_vector = (5_000, 10_000) if quick else (50_000, 100_000)
    with tempfile.TemporaryDirectory() as folder:
        wpm = _wpm(Path(folder))
    curve = wpm.curve("dp_n", 120.0)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        tested = {w: c for w, c in wpm._by_load("dp_n", {"soil": None, "wheel": None,
                                                         "multipass": None}).items()}
    grid = np.linspace(0.0, curve.slip_max, 2001)
    rising = np.polyval(np.array(curve.coefficients)[::-1], grid)
    top = int(np.argmax(rising))
    grid_rise, values_rise = grid[:top + 1], rising[:top + 1]
    targets = rng.uniform(0.0, float(values_rise[-1]), n_vector)
    loads = rng.uniform(70.0, 300.0, n_vector)
    slips = rng.uniform(-0.1, 0.6, n_vector)
    one = _polyval_interp(curve, grid_rise)
    n_polyval = n_single // 10
    wpm.slip_for_one("dp_n", 20.0, 120.0)
    wpm.slip_for_one("dp_n", 20.0, 120.0)  # the second time the table is built
    row_grid = np.linspace(0.0, curve.slip_max, 257)
    small = targets[:n_single].tolist()
    cases = {
        "scalar: slip_for_one in a loop, 120 N": (
            lambda: [wpm.slip_for_one("dp_n", t, 120.0) for t in small], n_single),
        "scalar: slip_for in a loop, 120 N": (
            lambda: [wpm.slip_for("dp_n", t, 120.0) for t in small], n_single),
        "  baseline: np.polyval on 2001 slips + np.interp per query": (
            lambda: [one(t) for t in small[:n_polyval]], n_polyval),
        "  baseline: np.interp per query on the precomputed grid": (
            lambda: [float(np.interp(t, values_rise, grid_rise)) for t in small], n_single),
        f"vector: slip_for, {n_vector} targets, 120 N": (
            lambda: wpm.slip_for("dp_n", targets, 120.0), n_vector),
        "  baseline: np.interp on the precomputed grid": (
            lambda: np.interp(targets, values_rise, grid_rise), n_vector),
        f"vector: slip_for, {n_vector} targets, random loads": (
            lambda: wpm.slip_for("dp_n", targets, loads), n_vector),
        "  baseline: PCHIP rows (2001 slips) + first crossing": (
            lambda: _pchip_rows(tested, grid, targets, loads), n_vector),
        "  baseline: PCHIP rows (257 slips) + first crossing": (
            lambda: _pchip_rows(tested, row_grid, targets, loads), n_vector),
        f"at_slip (5 quantities), {n_vector} slips, 120 N": (
            lambda: wpm.at_slip(slips, 120.0), n_vector),
    }
    rates = {name: _rate(call, n) for name, (call, n) in cases.items()}
    print(f"{'case':<64}{'queries/s':>14}")
    for name, rate in rates.items():
        print(f"{name:<64}{rate:>14,.0f}")
    r = list(rates.values())
    ratios = {"scalar_qps": r[0], "scalar_slip_for_qps": r[1],
              "scalar_vs_polyval_interp": r[0] / r[2], "scalar_vs_precomputed_interp": r[0] / r[3],
              "vector_one_load_vs_interp": r[4] / r[5], "vector_random_loads_vs_pchip_rows":
              r[6] / r[7], "vector_random_loads_vs_pchip_rows_257": r[6] / r[8]}
    print("ratios (goal: scalar >= 100,000/s; one load >= 0.5x np.interp; random loads >= 3x "
          "PCHIP rows):")
    for name, value in ratios.items():
        print(f"  {name:<40}{value:>12,.3g}")
    keys = ("scalar_one_qps", "scalar_slip_for_qps", "baseline_polyval_interp_qps",
            "baseline_interp_scalar_qps", "vector_one_load_qps", "baseline_interp_vector_qps",
            "vector_random_loads_qps", "baseline_pchip_rows_qps", "baseline_pchip_rows_257_qps",
            "at_slip_vector_qps")
    return {**dict(zip(keys, r)), **ratios, "n_single": n_single, "n_vector": n_vector}
