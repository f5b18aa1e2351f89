"""libswtwpm, the C WPM (issue 37.2), in one run:

- scalar queries per second in C at random continuous loads (one call per query, a new load
  each time, as a simulator asks every step): forward (DP at a slip), inverse (slip for a
  DP), forward with the 95 % bands; goal >= 5 M/s; beside the Python runtime asked the same
  way in the same run (``band_one``, its cheapest scalar forward call, which also gives the
  half-widths, and ``slip_for_one``, one scalar call per query). Rates per CPU second of
  each process (the ratios from them: on a shared machine wall seconds also count the
  waits for a core) and per wall second;
- 10,000 mutated WPM CSVs (:mod:`bench.wpm_fuzz`) through the reader and every query under
  AddressSanitizer + UBSan: findings (goal 0), files read and refused, and how often the C
  and the Python reader agree on reading or refusing a file.

The curves: the bb2_sand model's at the sample campaign's loads and slips, fitted by swtlab
(:func:`bench.bench_wpm._wpm`).
"""

from __future__ import annotations

import os
import subprocess
import tempfile
import time
from pathlib import Path

import numpy as np

from bench.bench_wpm import _wpm
from bench.wpm_fuzz import C_SOURCES, ROOT, build_driver, run_driver, seed_texts, write_mutants
from wpm_export import WpmFormatError, read_wpm_csv

BENCH = ROOT / "libswtwpm" / "tools" / "bench_queries.c"
GOAL_PER_S = 5e6
COMMAND = "python -m bench wpm_c --markdown"


def _c_rates(path: Path, folder: Path, n: int) -> tuple[dict[str, float], dict[str, float]]:
    """(queries per wall second, per CPU second) of each kind."""
    program = folder / "bench_queries"
    subprocess.run([os.environ.get("CC", "gcc"), "-std=c99", "-O2", "-ffp-contract=off",
                    f"-I{ROOT / 'libswtwpm'}", "-o", str(program), *map(str, C_SOURCES),
                    str(BENCH), "-lm"], check=True)
    out = subprocess.run([str(program), str(path), "0", str(n)], capture_output=True, text=True,
                         check=True).stdout
    rows = [line.split() for line in out.splitlines()]
    return {k: float(w) for k, w, _ in rows}, {k: float(c) for k, _, c in rows}


def _python_rates(path: Path, n: int) -> tuple[dict[str, float], dict[str, float]]:
    """(queries per wall second, per CPU second) of the runtime's scalar calls."""
    from wpm_export import WheelPerformanceModule

    wpm = WheelPerformanceModule.load(path)
    rng = np.random.default_rng(1)
    loads, slips, targets = (a.tolist() for a in (
        rng.uniform(70, 300, n), rng.uniform(-0.1, 0.6, n), rng.uniform(-10, 50, n)))
    wpm.slip_for_one("dp_n", 10.0, 100.0, multipass=0)  # packs the table, loads the kernels
    wpm.band_one("dp_n", 0.1, 100.0, multipass=0)

    def forward():
        for w, s in zip(loads, slips):
            wpm.band_one("dp_n", s, w, multipass=0)

    def inverse():
        for w, t in zip(loads, targets):
            wpm.slip_for_one("dp_n", t, w, multipass=0)

    wall, cpu = {}, {}
    for kind, call in (("forward", forward), ("inverse", inverse)):
        start, start_cpu = time.perf_counter(), time.process_time()
        call()
        wall[kind] = n / (time.perf_counter() - start)
        cpu[kind] = n / max(time.process_time() - start_cpu, 1e-9)
    wall["band"], cpu["band"] = wall["forward"], cpu["forward"]  # band_one gives both
    return wall, cpu


def _fuzz(path: Path, folder: Path, n: int) -> dict:
    paths = write_mutants(seed_texts(path.read_text()), n, seed=37, folder=folder)
    results, exit_code, report = run_driver(build_driver(folder), paths)
    agree = python_gaps = nul = 0
    for p, (code, _) in zip(paths, results):
        try:
            read_wpm_csv(p)
            python_reads = True
        except WpmFormatError:
            python_reads = False
        except Exception:
            python_gaps += 1
            continue
        nul += b"\x00" in p.read_bytes() and python_reads != (code == 0)
        agree += python_reads == (code == 0)
    findings = int(exit_code != 0 or "ERROR: AddressSanitizer" in report
                   or "runtime error" in report or len(results) != len(paths))
    return {"mutants": n, "findings": findings, "read": sum(c == 0 for c, _ in results),
            "refused": sum(c < 0 for c, _ in results),
            "silent": sum(c < 0 and not m for c, m in results),
            "agree_with_python": agree, "python_reader_crashes": python_gaps,
            "disagree_nul_byte": int(nul), "report": report[-2000:] if findings else ""}


def main(quick: bool = False) -> dict:
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        wpm = _wpm(folder)
        path = Path(wpm.source)
        c_wall, c = _c_rates(path, folder, 200_000 if quick else 2_000_000)
        py_wall, py = _python_rates(path, 20_000 if quick else 100_000)
        fuzz_folder = folder / "fuzz"
        fuzz_folder.mkdir()
        fuzz = _fuzz(path, fuzz_folder, 1000 if quick else 10_000)
    print(f"{'scalar queries at random loads':30s} {'C /CPU s':>12s} {'Python /CPU s':>14s} "
          f"{'ratio':>7s} {'C /wall s':>12s} {'Python /wall s':>15s}")
    for kind, label in (("forward", "forward (Python: band_one)"), ("inverse", "inverse"),
                        ("band", "forward with 95 % bands")):
        goal = "" if kind == "band" else \
            f"  (goal >= {GOAL_PER_S:,.0f}/s: {'met' if c[kind] >= GOAL_PER_S else 'NOT met'})"
        print(f"{label:30s} {c[kind]:12,.0f} {py[kind]:14,.0f} {c[kind] / py[kind]:6,.1f}x "
              f"{c_wall[kind]:12,.0f} {py_wall[kind]:15,.0f}{goal}")
    print(f"fuzz: {fuzz['mutants']} mutants under ASan+UBSan, {fuzz['findings']} findings; "
          f"{fuzz['read']} read, {fuzz['refused']} refused ({fuzz['silent']} without a "
          f"message); C and Python readers agree on {fuzz['agree_with_python']} "
          f"(Python reader crashed on {fuzz['python_reader_crashes']}, NUL bytes refused by C "
          f"only: {fuzz['disagree_nul_byte']})")
    if fuzz["report"]:
        print(fuzz["report"])
    return {"c_per_cpu_s": c, "python_per_cpu_s": py, "c_per_wall_s": c_wall,
            "python_per_wall_s": py_wall, "ratio_cpu": {k: c[k] / py[k] for k in py},
            "goal_per_s": GOAL_PER_S, "load_average_1min": os.getloadavg()[0],
            "cores": os.cpu_count(), "quick": quick, "fuzz": fuzz}


def markdown(numbers: dict) -> str:
    """docs/validation/wpm_c.md from a run's numbers."""
    c, py, c_wall, py_wall = (numbers[k] for k in ("c_per_cpu_s", "python_per_cpu_s",
                                                    "c_per_wall_s", "python_per_wall_s"))
    fuzz = numbers["fuzz"]
    other = (fuzz["mutants"] - fuzz["agree_with_python"] - fuzz["python_reader_crashes"]
             - fuzz["disagree_nul_byte"])
    lines = [
        "# libswtwpm (C): queries per second at random loads, and the fuzz run",
        "",
        f"Regenerate with `{COMMAND}` (bench/bench_wpm_c.py; its docstring defines the cases). "
        "One scalar call per query, each at a fresh random load in the tested 70-300 N, as a "
        "simulator asks once per time step; the Python runtime's scalar calls in the same "
        f"run. This run: {numbers['cores']} cores, 1-minute load average "
        f"{numbers['load_average_1min']:.1f} (a shared machine: rates per CPU second of each "
        "process, the ratios from them; per wall second beside them)"
        + (", quick sizes" if numbers["quick"] else "") + ".",
        "",
        f"Goal (issue 37.2): >= {GOAL_PER_S:,.0f} scalar queries per second in C.",
        "",
        "| scalar query | C, per CPU s | Python, per CPU s | ratio | C, per wall s | "
        "Python, per wall s |",
        "|---|---:|---:|---:|---:|---:|",
    ]
    for kind, label in (("forward", "forward: `swtwpm_value` (Python: `band_one`)"),
                        ("inverse", "inverse: `swtwpm_slip_for` (Python: `slip_for_one`)"),
                        ("band", "forward with 95 % bands: `swtwpm_value_band` (Python: "
                                 "`band_one`)")):
        lines.append(f"| {label} | {c[kind]:,.0f} | {py[kind]:,.0f} | "
                     f"{c[kind] / py[kind]:.1f}x | {c_wall[kind]:,.0f} | {py_wall[kind]:,.0f} |")
    lines += [
        "",
        f"Fuzz: {fuzz['mutants']:,} mutated WPM CSVs (bench/wpm_fuzz.py) through the reader "
        f"and every query under AddressSanitizer + UBSan: {fuzz['findings']} findings; "
        f"{fuzz['read']:,} read, {fuzz['refused']:,} refused ({fuzz['silent']} without a "
        f"message); the C and the Python reader agree on {fuzz['agree_with_python']:,} of "
        f"them, disagree on {fuzz['disagree_nul_byte']} holding a NUL byte (refused by C "
        f"only) and on {other} others; the Python reader crashed on "
        f"{fuzz['python_reader_crashes']}.",
        "",
        "Answers: C and the Python runtime agree within 1e-9 (tests/test_wpm_clib.py, "
        "100,000 random queries).",
        "",
    ]
    return "\n".join(lines)


if __name__ == "__main__":
    main()
