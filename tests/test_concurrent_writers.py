"""Concurrent writers (issue 17, item 5): four ``swtlab process`` at once on one database, over
one folder and over four disjoint folders: no crash, every run stored once. Real processes,
small synthetic runs (conftest's spec MCAP), SQLite and PostgreSQL."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest
from sqlalchemy import func, select

from traceability import open_database
from traceability.models import Campaign, RawFile, Run, RunResult, TestCondition

ROOT = Path(__file__).resolve().parents[1]
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


def _run_together(folders: list[Path], db_url: str) -> list[subprocess.CompletedProcess]:
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    started = [subprocess.Popen([sys.executable, "-m", "swtlab_cli.main", "process", str(f),
                                 "--db", db_url, "--quiet"], cwd=ROOT, env=env, text=True,
                                stdout=subprocess.PIPE, stderr=subprocess.PIPE)
               for f in folders]
    done = []
    for process in started:
        out, err = process.communicate(timeout=300)
        done.append(subprocess.CompletedProcess(process.args, process.returncode, out, err))
    return done


def _stored(db_url: str) -> dict[str, object]:
    with open_database(db_url, read_only=True)() as session:
        counts = {m.__name__: session.scalar(select(func.count()).select_from(m))
                  for m in (Campaign, Run, RawFile, RunResult, TestCondition)}
        counts["run_ids"] = sorted(session.scalars(select(Run.run_id)).all())
        return counts


@pytest.mark.slow  # four swtlab processes at once, each starting the whole stack
@pytest.mark.slow_workers
@pytest.mark.parametrize("layout", ["same folder", "disjoint folders"])
def test_four_writers_at_once_store_every_run_once(tmp_path, db_url, ingest_tools, layout):
    run_ids = [f"r{i:03d}" for i in range(WRITERS)]
    if layout == "same folder":
        folders = [_folder(tmp_path / "all", ingest_tools, run_ids)] * WRITERS
    else:
        folders = [_folder(tmp_path / f"part{k}", ingest_tools, [run_id])
                   for k, run_id in enumerate(run_ids)]
    done = _run_together(folders, db_url)
    for process in done:
        assert process.returncode == 0, process.stderr[-2000:]
        assert process.stderr == ""
    stored = _stored(db_url)
    assert stored["run_ids"] == run_ids  # each once
    assert (stored["Campaign"], stored["Run"], stored["RawFile"], stored["RunResult"]) == (
        1, WRITERS, WRITERS, WRITERS)
    assert stored["TestCondition"] == 1  # one set point, created once
