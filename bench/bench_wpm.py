"""WPM runtime queries per second as a rover simulator asks them (issue 37.1): each query at
a fresh random continuous load (uniform over the tested loads, never repeated), each beside
a plain NumPy version of the documented method measured in the same run, in alternation.

The baseline (:class:`PlainNumpy`): the tested curves on the documented slip grid (101
Chebyshev-Lobatto points), PCHIP across load precomputed as pieces (one cubic per grid
slip), per query the row at the load (one NumPy expression), ``np.interp`` on its rising
part to invert, ``np.interp`` of the value and of the half-widths (tested bands on the grid,
PCHIP across load too) at a slip. It answers less than the runtime (grid accuracy, no jump
at zero slip, no turning points after the peak, bands interpolated, not propagated): it
bounds the cost of the documented method in NumPy; it is not an alternative.

Cases (goals: scalar >= 200,000/s and >= 5x the baseline's scalar query; arrays >= 2 M/s;
ratios of CPU seconds of the process, wall-clock ratios printed beside them):

- scalar inverse: ``slip_for("dp_n", dp, load, multipass=0)`` with two floats (the
  simulator's call; ``slip_for_one``, its 0.14.0 name, is the same call) vs the baseline's
  inverse;
- scalar forward with bands: ``band("dp_n", slip, load, multipass=0)`` with two floats
  (value, 95 % confidence and prediction half-widths; ``band_one`` the same call) vs the
  baseline's three interpolations;
- scalar inverse with the slip's bands: ``slip_for`` then ``slip_band`` at the slip found
  vs the baseline's inverse and band;
- arrays: ``slip_for`` and ``band`` over 1e5 (target or slip, load) pairs at random loads, and
  ``at_slip`` (all five quantities) vs the baseline on chunks of rows.
"""

from __future__ import annotations

import bisect
import os
import platform
import tempfile
import time
from pathlib import Path

import numpy as np
import pandas as pd
from scipy.interpolate import PchipInterpolator

from fitting import band, fit_results
from fitting.polynomial import lobatto_grid
from terramechanics import shipped_model
from wpm_export import WheelPerformanceModule, inputs_sha256, write_wpm_csv

SLIPS = (-0.10, 0.0, 0.05, 0.10, 0.20, 0.35, 0.60)
LOADS_N = (70.0, 180.0, 300.0)
GRID_POINTS = 101  # the documented slip grid of the interpolation across load
COMMAND = "python -m bench wpm --markdown"


def _wpm(folder: Path) -> WheelPerformanceModule:
    """WPM of the bb2_sand model's curves at the sample campaign's loads and slips."""
    model = shipped_model("bb2_sand")
    rows = []
    for load in LOADS_N:
        curves = model.curves(load, np.array(SLIPS), 0)
        for i, slip in enumerate(SLIPS):
            rows.append({"wheel": "bb2", "soil": "bb2_sand", "multipass": 0, "load_n": load,
                         "slip": slip, "slip_se": 1e-3, "wheel_load_n": load,
                         **{q: float(curves[q][i]) for q in
                            ("dp_n", "torque_nm", "sinkage_m", "resistance_n")},
                         **{f"{q}_se": se for q, se in
                            (("dp_n", 0.5), ("torque_nm", 0.05), ("sinkage_m", 2e-4),
                             ("resistance_n", 0.5))}})
    table = pd.DataFrame(rows)
    path = folder / "wpm.csv"
    write_wpm_csv(fit_results(table), path, inputs_sha256(table), "bench")
    return WheelPerformanceModule.load(path)


class PlainNumpy:
    """The documented method in plain NumPy (module text): value and bands of the tested
    curves on the grid, PCHIP pieces across load, per query one row and ``np.interp``."""

    def __init__(self, curves: dict) -> None:
        self.loads = sorted(curves)
        lo = max(c.slip_min for c in curves.values())
        hi = min(c.slip_max for c in curves.values())
        self.grid = lobatto_grid(lo, hi, GRID_POINTS)
        rows = np.array([np.concatenate(band(curves[w], self.grid)) for w in self.loads])
        self.pieces = PchipInterpolator(np.array(self.loads), rows, axis=0).c  # 4 x L-1 x 3G

    def _row(self, load: float) -> np.ndarray:
        k = min(max(bisect.bisect_right(self.loads, load) - 1, 0), len(self.loads) - 2)
        dx = load - self.loads[k]
        c = self.pieces[:, k]
        return ((c[0] * dx + c[1]) * dx + c[2]) * dx + c[3]

    def slip_for(self, target: float, load: float) -> float:
        row = self._row(load)[:GRID_POINTS]
        top = int(row.argmax())
        return float(np.interp(target, row[:top + 1], self.grid[:top + 1]))

    def band(self, slip: float, load: float) -> tuple[float, float, float]:
        row = self._row(load).reshape(3, GRID_POINTS)
        return tuple(float(np.interp(slip, self.grid, r)) for r in row)

    def slip_and_band(self, target: float, load: float) -> tuple[float, float, float]:
        slip = self.slip_for(target, load)
        return slip, *self.band(slip, load)[1:]

    def slip_for_rows(self, targets: np.ndarray, loads: np.ndarray,
                      chunk: int = 4096) -> np.ndarray:
        """Arrays: rows at ``loads`` by chunks, the first crossing of each target."""
        out = np.empty(targets.size)
        tested = np.array(self.loads)
        for i in range(0, targets.size, chunk):
            w = loads[i:i + chunk]
            k = np.clip(np.searchsorted(tested, w, side="right") - 1, 0, tested.size - 2)
            dx = (w - tested[k])[:, None]
            c = self.pieces[:, k, :GRID_POINTS]
            rows = ((c[0] * dx + c[1]) * dx + c[2]) * dx + c[3]
            t = targets[i:i + chunk, None]
            j = np.clip(np.argmax(rows >= t, axis=1), 1, GRID_POINTS - 1)
            pick = np.arange(j.size)
            f0, f1 = rows[pick, j - 1], rows[pick, j]
            out[i:i + chunk] = self.grid[j - 1] + (t[:, 0] - f0) / (f1 - f0) * (
                self.grid[j] - self.grid[j - 1])
        return out


def _timed(call) -> tuple[float, float]:
    """(wall, CPU) seconds of one call."""
    wall, cpu = time.perf_counter(), time.process_time()
    call()
    return time.perf_counter() - wall, time.process_time() - cpu


def _rates(pairs: dict, repeats: int) -> tuple[dict, dict]:
    """Best queries per wall second and per CPU second of each case over ``repeats``
    rounds, the cases alternating within a round (a shared machine's load falls on all of
    them alike; CPU seconds count only the time the process ran)."""
    wall = {name: np.inf for name in pairs}
    cpu = dict(wall)
    for _ in range(repeats):
        for name, (call, _) in pairs.items():
            w, c = _timed(call)
            wall[name], cpu[name] = min(wall[name], w), min(cpu[name], c)
    return ({name: pairs[name][1] / wall[name] for name in pairs},
            {name: pairs[name][1] / max(cpu[name], 1e-9) for name in pairs})


def main(quick: bool = False) -> dict:
    rng = np.random.default_rng(1)
    n_scalar, n_vector = (5_000, 20_000) if quick else (40_000, 100_000)
    with tempfile.TemporaryDirectory() as folder:
        wpm = _wpm(Path(folder))
    plain = PlainNumpy(wpm._by_load("dp_n", {"soil": None, "wheel": None, "multipass": None}))
    loads = rng.uniform(LOADS_N[0], LOADS_N[-1], n_vector)  # continuous: never repeated
    targets = rng.uniform(0.0, 20.0, n_vector)  # DP below the smallest maximum (70 N)
    slips = rng.uniform(-0.1, 0.6, n_vector)
    w, t, s = (a[:n_scalar].tolist() for a in (loads, targets, slips))
    wpm.slip_for("dp_n", 10.0, 100.0, multipass=0)  # packs the table, loads the kernels
    wpm.band("dp_n", 0.1, 100.0, multipass=0)

    # each case a plain loop that drops its answers, as a simulator's time steps do
    def slip_for():
        for target, load in zip(t, w):
            wpm.slip_for("dp_n", target, load, multipass=0)

    def baseline_slip_for():
        for target, load in zip(t, w):
            plain.slip_for(target, load)

    def band():
        for slip, load in zip(s, w):
            wpm.band("dp_n", slip, load, multipass=0)

    def baseline_band():
        for slip, load in zip(s, w):
            plain.band(slip, load)

    def inverse_with_bands():
        for target, load in zip(t, w):
            slip, _, _ = wpm.slip_for("dp_n", target, load, multipass=0)
            wpm.slip_band("dp_n", slip, load, multipass=0)

    def baseline_slip_and_band():
        for target, load in zip(t, w):
            plain.slip_and_band(target, load)

    scalar = {name: (call, n_scalar) for name, call in (
        ("slip_for", slip_for), ("baseline_slip_for", baseline_slip_for), ("band", band),
        ("baseline_band", baseline_band), ("slip_for_with_slip_band", inverse_with_bands),
        ("baseline_slip_and_band", baseline_slip_and_band))}
    vector = {
        "vector_slip_for": (lambda: wpm.slip_for("dp_n", targets, loads, multipass=0),
                            n_vector),
        "vector_band": (lambda: wpm.band("dp_n", slips, loads, multipass=0), n_vector),
        "vector_at_slip_5_quantities": (lambda: wpm.at_slip(slips, loads, multipass=0),
                                        n_vector),
        "baseline_vector_slip_for": (lambda: plain.slip_for_rows(targets, loads), n_vector),
    }
    repeats = 3 if quick else 5
    (scalar_wall, scalar_cpu), (vector_wall, vector_cpu) = (_rates(scalar, repeats),
                                                            _rates(vector, repeats))
    rates, cpu = {**scalar_wall, **vector_wall}, {**scalar_cpu, **vector_cpu}
    pairs = {"slip_for": "baseline_slip_for", "band": "baseline_band",
             "slip_for_with_slip_band": "baseline_slip_and_band",
             "vector_slip_for": "baseline_vector_slip_for"}
    # ratios of CPU seconds: on a shared machine the wall clock also counts the time the
    # process waited for a core, which falls on one case more than on its neighbour
    ratios = {f"{ours}_vs_baseline": cpu[ours] / cpu[base] for ours, base in pairs.items()}
    ratios.update({f"{ours}_vs_baseline_wall": rates[ours] / rates[base]
                   for ours, base in pairs.items()})
    print(f"{'case (one query = one fresh random load)':<48}{'queries/s':>14}"
          f"{'per CPU s':>14}")
    for name, rate in rates.items():
        print(f"{name:<48}{rate:>14,.0f}{cpu[name]:>14,.0f}")
    print("ratios, per CPU second and (_wall) per wall second (goals: scalar >= 200,000/s "
          "and >= 5x the baseline; arrays >= 2 M/s):")
    for name, value in ratios.items():
        print(f"  {name:<46}{value:>10.2f}")
    return {**{f"{k}_qps": v for k, v in rates.items()},
            **{f"{k}_per_cpu_second": v for k, v in cpu.items()}, **ratios, "n_scalar": n_scalar,
            "n_vector": n_vector, "load_average_1min": os.getloadavg()[0],
            "cores": os.cpu_count(), "python": platform.python_version(), "quick": quick}


def markdown(numbers: dict) -> str:
    """docs/validation/wpm.md from a run's numbers."""
    def rate(name: str) -> str:
        return f"{numbers[name + '_qps']:,.0f}"

    def cpu(name: str) -> str:
        return f"{numbers[name + '_per_cpu_second']:,.0f}"

    rows = [
        ("inverse, `slip_for`", "slip_for", "baseline_slip_for", "slip_for_vs_baseline"),
        ("forward with bands, `band`", "band", "baseline_band", "band_vs_baseline"),
        ("inverse + slip bands, `slip_for` + `slip_band`", "slip_for_with_slip_band",
         "baseline_slip_and_band", "slip_for_with_slip_band_vs_baseline"),
    ]
    lines = [
        "# WPM runtime: queries per second at random loads",
        "",
        f"Regenerate with `{COMMAND}` (bench/bench_wpm.py; its docstring defines the "
        "cases and the plain NumPy baseline). Each query is at a fresh random load, uniform "
        "over the tested 70-300 N, as a rover simulator asks once per time step; the "
        "baseline runs in the same process, alternating with the runtime (best of 5 rounds). "
        f"This run: {numbers['cores']} cores, 1-minute load average "
        f"{numbers['load_average_1min']:.1f} (a shared machine: rates per wall second "
        "vary with its load, the ratios and the rates per CPU second of the process much "
        f"less), Python {numbers['python']}" + (", quick sizes" if numbers["quick"] else "")
        + ".",
        "",
        "Goals (issue 37.1): one scalar query >= 200,000/s and >= 5x the baseline; arrays "
        ">= 2,000,000 queries/s.",
        "",
        "| scalar query | runtime, per CPU s | plain NumPy, per CPU s | ratio | runtime, "
        "per wall s | plain NumPy, per wall s | ratio, wall |",
        "|---|---:|---:|---:|---:|---:|---:|",
    ]
    for label, ours, base, ratio in rows:
        lines.append(f"| {label} | {cpu(ours)} | {cpu(base)} | {numbers[ratio]:.1f}x | "
                     f"{rate(ours)} | {rate(base)} | {numbers[ratio + '_wall']:.1f}x |")
    lines += [
        "",
        f"| arrays of {numbers['n_vector']:,} queries at random loads | per wall s | "
        "per CPU s |",
        "|---|---:|---:|",
    ]
    for label, name in (("inverse, `slip_for`", "vector_slip_for"),
                        ("forward with bands, `band`", "vector_band"),
                        ("every quantity's value, `at_slip` (5 quantities)",
                         "vector_at_slip_5_quantities"),
                        ("baseline inverse on PCHIP rows (chunks of 4,096)",
                         "baseline_vector_slip_for")):
        lines.append(f"| {label} | {rate(name)} | {cpu(name)} |")
    lines += [
        "",
        "Ratios are of CPU seconds of the process (wall seconds on a loaded machine also "
        "count the waits for a core, unevenly between neighbouring cases); both are shown. "
        "The scalar calls are the public ones with two Python floats, as a simulator makes "
        "them (`slip_for(\"dp_n\", dp, load_n, multipass=0)`; `slip_for_one` and `band_one`, "
        "their 0.14.0 names, are the same calls); they answer floats and the status text.",
        "",
        "Answers: the runtime's equal today's within 1e-9 relative (tests/test_wpm_kernel.py); "
        "the baseline answers to its grid only (about 1e-3 in slip).",
        "",
    ]
    return "\n".join(lines)
