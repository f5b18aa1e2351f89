"""``swtlab process --jobs N`` and ``--dask``, ``process_campaign(client=...)``: the runs are
computed elsewhere and stored by one writer, and every stored row is the one the serial run
stores (failed runs included); each of N workers runs numba, OpenCV and BLAS on its share
of the cores; the CLI's start-up imports no numerical library."""

from __future__ import annotations

import os
import shutil
import sqlite3
import subprocess
import sys
from pathlib import Path

import pandas as pd
import pytest

import swtlab
from swtlab_base.cores import threads_per_worker
from swtlab.pipeline.process import ProcessSettings, process_file, worker_pool
from swtlab_cli.main import COMMANDS, command_module, main

pytestmark = pytest.mark.slow  # sample runs processed serially, in a pool and on a cluster

SAMPLE = Path(__file__).resolve().parents[1] / "sample_data" / "campaign"
RUNS = ("L070_MP0_SC_s+010", "L180_MP0_SC_s+020", "L300_MP1_SC_s+035", "L180_MP0_TW",
        "L180_MP0_SC_s+090")
#: when a row was made, not what it holds
WHEN = {"created_at"}


@pytest.fixture(scope="module")
def campaign(tmp_path_factory) -> Path:
    """Five sample runs (one digs in: no stable phase) and a file that is no MCAP."""
    folder = tmp_path_factory.mktemp("parallel") / "campaign"
    folder.mkdir()
    for run_id in RUNS:
        source = SAMPLE / f"{run_id}.mcap"
        if source.exists():
            shutil.copy(source, folder / source.name)
        else:
            shutil.copytree(SAMPLE / run_id, folder / run_id)
    (folder / "broken.mcap").write_bytes(b"not an mcap file")
    return folder


def _rows(db: Path) -> dict[str, list[tuple]]:
    """Every row of every table (but when it was made), in id order."""
    with sqlite3.connect(db) as con:
        tables = [t for (t,) in con.execute(
            "SELECT name FROM sqlite_master WHERE type = 'table' AND name NOT LIKE 'sqlite_%' "
            "AND name != 'alembic_version' ORDER BY name")]
        out = {}
        for table in tables:
            columns = [c[1] for c in con.execute(f"PRAGMA table_info({table})")]
            kept = ", ".join(f'"{c}"' for c in columns if c not in WHEN)
            out[table] = con.execute(f"SELECT {kept} FROM {table} ORDER BY rowid").fetchall()
    return out


def _process(campaign: Path, db: Path, *options: str) -> int:
    return main(["process", str(campaign), "--db", str(db), "--quiet", *options])


@pytest.fixture(scope="module")
def serial(campaign, tmp_path_factory) -> dict[str, list[tuple]]:
    db = tmp_path_factory.mktemp("serial") / "db.sqlite"
    assert _process(campaign, db, "--jobs", "1") == 0
    return _rows(db)


def test_two_worker_processes_store_the_rows_of_the_serial_run(campaign, serial, tmp_path,
                                                                capsys):
    db = tmp_path / "db.sqlite"
    assert _process(campaign, db, "--jobs", "2") == 0
    out = capsys.readouterr().out
    assert f"processed 5 of {len(RUNS) + 1} runs" in out and "1 failed" in out
    rows = _rows(db)
    assert len(rows["run_result"]) == 5 and len(rows["ingest_failure"]) == 1
    assert len(rows["run_quantity"]) == 5 * 8 and rows["run_trace"] and rows["run_uncertainty"]
    assert rows == serial
    assert _process(campaign, db, "--jobs", "2") == 0   # again: nothing new
    assert "(5 already up to date)" in capsys.readouterr().out and _rows(db) == serial


def _threads_after_a_run(path: Path) -> dict:
    """In a worker: process one run with its soil flow, then the threads it may use."""
    import cv2
    import numba
    from threadpoolctl import threadpool_info

    done = process_file(path, ProcessSettings())
    return {"flow": done.flow is not None, "failures": done.failures,
            "numba": numba.get_num_threads(), "opencv": cv2.getNumThreads(),
            "blas": {i["filepath"]: i["num_threads"] for i in threadpool_info()}}


@pytest.mark.slow_workers  # a pool of two worker processes started
def test_each_of_two_workers_runs_on_its_share_of_the_cores():
    """On 2 cores each of 2 workers runs 1 numba, OpenCV and BLAS thread (not 2), also
    after a run with soil flow (numba kernels, OpenCV, libraries loaded by the run); and
    this process's OpenCV thread pool, used first, does not hang the workers."""
    share = max(1, len(os.sched_getaffinity(0)) // 2)
    with_frames = [SAMPLE / "L180_MP0_SC_s+035.mcap", SAMPLE / "L180_MP0_FS"]
    assert _threads_after_a_run(with_frames[0])["flow"]
    with worker_pool(2) as pool:
        seen = list(pool.map(_threads_after_a_run, with_frames))
    for worker in seen:
        assert worker["flow"] and worker["failures"] == []
        assert worker["numba"] == share and worker["opencv"] == share
        assert len(worker["blas"]) >= 2 and set(worker["blas"].values()) == {share}


def test_the_cores_are_split_evenly_and_never_below_one_thread():
    cores = os.sched_getaffinity(0)
    assert [threads_per_worker(n) for n in (1, 2, 3)] == [len(cores), len(cores) // 2,
                                                          max(1, len(cores) // 3)]
    os.sched_setaffinity(0, {min(cores)})
    try:
        assert [threads_per_worker(n) for n in (1, 2)] == [1, 1]
    finally:
        os.sched_setaffinity(0, cores)
    with pytest.raises(ValueError, match="workers 0 must be >= 1"):
        threads_per_worker(0)


@pytest.mark.slow_workers  # a two-worker LocalCluster started
def test_a_dask_cluster_of_two_workers_gives_the_serial_results(campaign, serial, tmp_path,
                                                                capsys):
    distributed = pytest.importorskip("distributed")
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                                  dashboard_address=None) as cluster:
        db = tmp_path / "db.sqlite"
        assert _process(campaign, db, "--dask", cluster.scheduler_address) == 0
        assert _rows(db) == serial
        with distributed.Client(cluster) as client:
            on_cluster = swtlab.process_campaign(campaign, client=client, soil_flow=False,
                                                 keep_samples=False)
    here = swtlab.process_campaign(campaign, soil_flow=False)
    pd.testing.assert_frame_equal(on_cluster.results, here.results)
    read = [r for r in on_cluster.runs if r.run is not None]
    assert len(read) == 5 and all(r.run.channels.empty and not r.run.streams for r in read)
    assert all(len(r.run.channels) > 1000 for r in here.runs if r.run is not None)
    assert on_cluster.failures == here.failures and len(here.failures) == 1
    assert here.failures[0].stage == "ingest" and "broken.mcap" in here.failures[0].file


def test_an_unreachable_scheduler_is_one_line_and_exit_3(campaign, tmp_path, capsys,
                                                         monkeypatch):
    pytest.importorskip("distributed")
    from swtlab_base import cluster

    monkeypatch.setattr(cluster, "CONNECT_TIMEOUT_S", 1)
    code = _process(campaign, tmp_path / "db.sqlite", "--dask", "tcp://127.0.0.1:9")
    err = capsys.readouterr().err.strip()
    assert code == 3 and err.startswith("swtlab process: --dask tcp://127.0.0.1:9: cannot reach")
    assert len(err.splitlines()) == 1


@pytest.mark.parametrize("jobs", ["0", "two"])
def test_jobs_below_one_is_a_usage_error(campaign, tmp_path, jobs):
    with pytest.raises(SystemExit) as exit_:
        _process(campaign, tmp_path / "db.sqlite", "--jobs", jobs)
    assert exit_.value.code == 2


def test_the_command_line_starts_without_numpy_scipy_pandas_or_the_database():
    code = ("import sys, contextlib, io\n"
            "from swtlab_cli.main import main\n"
            "with contextlib.suppress(SystemExit), contextlib.redirect_stdout(io.StringIO()):\n"
            "    main(['--help'])\n"
            "heavy = {'numpy', 'scipy', 'pandas', 'matplotlib', 'sqlalchemy', 'swtlab.pipeline'}\n"
            "print(sorted(heavy & set(sys.modules)))\n")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         check=True, cwd=Path(__file__).resolve().parents[1]).stdout
    assert out.strip() == "[]"


def test_the_listed_help_is_each_command_s_own():
    import argparse

    for name, help_text in COMMANDS.items():
        sub = argparse.ArgumentParser().add_subparsers()
        command_module(name).register(sub)
        assert [a.help for a in sub._choices_actions] == [help_text], name
