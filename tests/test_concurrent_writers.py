"""Concurrent writers (issue 17, item 5): four ``swtlab process`` at once on one database, over
one folder and over four disjoint folders: no crash, every run stored once. Real processes,
each with its own connections, small synthetic runs (conftest's spec MCAP), SQLite and
PostgreSQL.

The writers are forked from the test process with the stack already imported: a fresh
interpreter spends about 3 CPU-s importing it before it writes, which tested nothing here
(16 of them were 50 of this file's 70 CPU-s), and forked writers reach the database together
instead of staggered by their start-up."""

from __future__ import annotations

import multiprocessing
import os
import subprocess
import sys
from pathlib import Path

import pytest
from sqlalchemy import func, select

from swtlab_cli.main import main
from traceability import open_database
from traceability.models import Campaign, RawFile, Run, RunResult, TestCondition

WRITERS = 4


def _short_topics(tools, duration_s: float = 2.0) -> dict:
    """conftest's truth topics cut to their first ``duration_s`` (a quick run to process)."""
    return {topic: {k: v[fields["t_ns"] < duration_s * 1e9] for k, v in fields.items()}
            for topic, fields in tools.truth_topics().items()}


def _folder(folder: Path, tools, run_ids: list[str]) -> Path:
    for run_id in run_ids:
        folder.mkdir(parents=True, exist_ok=True)
        tools.write_mcap(folder / f"{run_id}.mcap",
                         tools.Spec(topics=_short_topics(tools),
                                    records=tools.records(run={"run_id": run_id})))
    return folder


def _warm(folder: Path, scratch: Path) -> None:
    """``folder`` processed here into a scratch database first, so that the forked writers
    inherit every module (and numba function) ``swtlab process`` loads instead of each
    loading them (once per test process: after the first, a fraction of a second)."""
    assert main(["process", str(folder), "--db", f"sqlite:///{scratch}", "--quiet"]) == 0


def _writer(argv: list[str], out: Path, err: Path) -> None:
    """A forked writer: ``swtlab process`` as the command line runs it, its stdout and stderr
    (Python's and the file descriptors) into ``out`` and ``err``."""
    with open(out, "w") as stdout, open(err, "w") as stderr:
        os.dup2(stdout.fileno(), 1)
        os.dup2(stderr.fileno(), 2)
        sys.stdout, sys.stderr = stdout, stderr
        code = main(argv)
        stdout.flush()
        stderr.flush()
    sys.exit(code)


def _run_together(folders: list[Path], db_url: str, logs: Path
                  ) -> list[subprocess.CompletedProcess]:
    """Four writers forked at once; each one's exit code, stdout and stderr (in ``logs``)."""
    fork = multiprocessing.get_context("fork")
    logs.mkdir()
    started = []
    for k, folder in enumerate(folders):
        argv = ["process", str(folder), "--db", db_url, "--quiet"]
        out, err = logs / f"{k}.out", logs / f"{k}.err"
        process = fork.Process(target=_writer, args=(argv, out, err))
        process.start()
        started.append((argv, process, out, err))
    done = []
    for argv, process, out, err in started:
        process.join(timeout=300)
        if process.is_alive():
            process.kill()
            process.join()
        done.append(subprocess.CompletedProcess(argv, process.exitcode, out.read_text(),
                                                err.read_text()))
    return done


def _stored(db_url: str) -> dict[str, object]:
    with open_database(db_url, read_only=True)() as session:
        counts = {m.__name__: session.scalar(select(func.count()).select_from(m))
                  for m in (Campaign, Run, RawFile, RunResult, TestCondition)}
        counts["run_ids"] = sorted(session.scalars(select(Run.run_id)).all())
        return counts


@pytest.mark.slow  # four swtlab processes at once
@pytest.mark.slow_workers
@pytest.mark.parametrize("layout", ["same folder", "disjoint folders"])
def test_four_writers_at_once_store_every_run_once(tmp_path, db_url, ingest_tools, layout):
    run_ids = [f"r{i:03d}" for i in range(WRITERS)]
    if layout == "same folder":
        folders = [_folder(tmp_path / "all", ingest_tools, run_ids)] * WRITERS
    else:
        folders = [_folder(tmp_path / f"part{k}", ingest_tools, [run_id])
                   for k, run_id in enumerate(run_ids)]
    _warm(folders[0], tmp_path / "scratch.sqlite")
    done = _run_together(folders, db_url, tmp_path / "logs")
    for process in done:
        assert process.returncode == 0, process.stderr[-2000:]
        assert process.stderr == ""
    stored = _stored(db_url)
    assert stored["run_ids"] == run_ids  # each once
    assert (stored["Campaign"], stored["Run"], stored["RawFile"], stored["RunResult"]) == (
        1, WRITERS, WRITERS, WRITERS)
    assert stored["TestCondition"] == 1  # one set point, created once
