"""Report speed: ``swtlab report`` on the sample campaign, on one core, against a minimal
matplotlib loop measured in the same run.

The sample campaign (``sample_data/campaign``, 60 runs) is processed into a SQLite database
(or ``--db URL`` names one already processed); then, each in a fresh process pinned to one
core (``os.sched_setaffinity``):

- ``report``: ``swtlab report --db URL -o page.html --quiet``, start-up included;
- ``baseline``: ``import matplotlib``, then per run one ``Figure`` with four axes, one line
  of 2,000 points each, ``savefig`` to PNG: the least a page of 60 time-series figures costs
  when each figure is drawn anew.

Both children run with bytecode caching on (``PYTHONDONTWRITEBYTECODE`` dropped from their
environment: an installed swtlab starts from cached bytecode; the first run writes it).
Printed: both in seconds (wall and CPU of the child; the fastest of :data:`REPEATS`
interleaved runs of each), their ratio, the page's size, and the
report's phases measured in this process (gathering from the database, the time-series
figures, the other sections, the HTML). Issue 19 item 5: the report in 8 s or less.
"""

from __future__ import annotations

import argparse
import contextlib
import io
import os
import resource
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
SAMPLE = ROOT / "sample_data" / "campaign"
QUICK_RUNS = 12
REPEATS = 2

BASELINE = """
import io, sys
import numpy as np
import matplotlib
matplotlib.use("Agg")
from matplotlib.figure import Figure
t = np.linspace(0.0, 20.0, 2000)
for i in range({runs}):
    fig = Figure(figsize=(8.0, 6.4))
    for ax in fig.subplots(4, 1, sharex=True):
        ax.plot(t, np.sin(t + i) + 0.01 * i)
    fig.savefig(io.BytesIO(), format="png", dpi=100)
"""


def _one_core() -> None:
    os.sched_setaffinity(0, {min(os.sched_getaffinity(0))})


def _child_once(argv: list[str]) -> tuple[float, float]:
    """(wall s, CPU s) of a child process pinned to one core, with bytecode caching on (as
    an installed swtlab runs, even where the environment turns it off: compiling the
    project's modules anew at every start cost the report about 0.4 s)."""
    env = {k: v for k, v in os.environ.items() if k != "PYTHONDONTWRITEBYTECODE"}
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    start = time.perf_counter()
    subprocess.run(argv, check=True, cwd=ROOT, preexec_fn=_one_core,
                   env={**env, "PYTHONPATH": str(ROOT)}, stdout=subprocess.DEVNULL)
    wall = time.perf_counter() - start
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    return wall, (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)


def _process(folder: Path, quick: bool) -> str:
    """A SQLite URL of the sample campaign processed (``quick``: its first runs)."""
    from swtlab_cli.main import main as swtlab

    campaign = SAMPLE
    if quick:
        campaign = folder / "campaign"
        campaign.mkdir()
        for source in sorted(SAMPLE.iterdir())[:QUICK_RUNS]:
            (shutil.copytree if source.is_dir() else shutil.copy2)(source,
                                                                   campaign / source.name)
    url = f"sqlite:///{folder / 'bench.sqlite'}"
    with contextlib.redirect_stdout(io.StringIO()):
        assert swtlab(["process", str(campaign), "--db", url, "--quiet"]) == 0
    return url


def _phases(url: str) -> dict[str, float]:
    """The number of runs and the seconds of the report's phases in this process (imports
    already paid)."""
    from campaign_report.data import campaign_names, gather
    from campaign_report.html import render_page
    from campaign_report.render import build_page
    from traceability import open_database

    start = time.perf_counter()
    with open_database(url, read_only=True)() as session:
        data = gather(session, campaign_names(session)[0], url)
    gathered = time.perf_counter()
    drawn = []

    def timed(items, desc):  # the time-series figures are drawn while the progress runs
        for item in items:
            yield item
        drawn.append(time.perf_counter())

    page = build_page(data, timed)
    built = time.perf_counter()
    render_page(page)
    done = time.perf_counter()
    return {"runs": len(data.runs), "gather_s": gathered - start,
            "timeseries_s": drawn[0] - gathered,
            "other_sections_s": built - drawn[0], "html_s": done - built}


def main(quick: bool = False, db: str | None = None) -> dict:
    _one_core()
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        if db is None:
            db = _process(folder, quick)
        phases = _phases(db)
        runs = phases.pop("runs")
        page = folder / "page.html"
        report_argv = [sys.executable, "-m", "swtlab_cli.main", "report", "--db", db, "-o",
                       str(page), "--quiet"]
        baseline_argv = [sys.executable, "-c", BASELINE.format(runs=runs)]
        measured = [(_child_once(report_argv), _child_once(baseline_argv))
                    for _ in range(REPEATS)]  # interleaved: both see the same load
        report = tuple(min(m[0][i] for m in measured) for i in (0, 1))
        baseline = tuple(min(m[1][i] for m in measured) for i in (0, 1))
        size_mb = page.stat().st_size / 1e6
    ratio, cpu_ratio = report[0] / baseline[0], report[1] / baseline[1]
    print(f"report of {runs} runs on one core: {report[0]:.2f} s wall, {report[1]:.2f} s CPU, "
          f"page {size_mb:.1f} MB (issue 19.5: <= 8 s)")
    print(f"baseline ({runs} new 4-axes figures to PNG): {baseline[0]:.2f} s wall, "
          f"{baseline[1]:.2f} s CPU")
    print(f"report / baseline: {ratio:.2f} wall, {cpu_ratio:.2f} CPU (CPU: on a shared "
          "machine, where wall time includes waiting)")
    print("phases in one process: " + ", ".join(f"{k.removesuffix('_s')} {v:.2f} s"
                                               for k, v in phases.items()))
    return {"runs": runs, "report_wall_s": report[0], "report_cpu_s": report[1],
            "baseline_wall_s": baseline[0], "baseline_cpu_s": baseline[1],
            "ratio": ratio, "cpu_ratio": cpu_ratio, "page_mb": size_mb, **phases}


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help=f"the first {QUICK_RUNS} runs")
    parser.add_argument("--db", help="an already processed sample campaign (skips processing)")
    args = parser.parse_args()
    main(args.quick, args.db)
