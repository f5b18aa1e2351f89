"""Database reliability (issue 17, item 9): kill points survived and concurrent writers.

Kill points: ``swtlab process`` of a small campaign (4 sample runs) on a fresh SQLite file,
SIGKILLed once a seeded random number of runs are stored, a random part of one run's time
later, then run again to the end;
each such database must equal one processed without a kill (every run's version, path,
sha256, condition, status, window and quantities), with 0 duplicates, 0 orphans and SQLite's
integrity and foreign-key checks clean.

Concurrent writers: 4 ``swtlab process`` at once on one database over one folder and over 4
disjoint folders; outcome: processes that crashed (exit != 0), runs stored once, duplicates.
SQLite always; PostgreSQL too where ``SWTLAB_TEST_POSTGRES_URL`` names a server (each case in a
fresh database, dropped after). ``python -m bench reliability_db [--quick]``.
"""

from __future__ import annotations

import os
import random
import shutil
import signal
import subprocess
import sys
import tempfile
import time
import uuid
from pathlib import Path

from sqlalchemy import create_engine, func, select, text
from sqlalchemy.engine import make_url

from traceability import open_database
from traceability.models import (Base, ProcessingRecord, RawFile, Run, RunQuantity, RunResult,
                                 StableWindow)

ROOT = Path(__file__).resolve().parents[1]
SAMPLE = ROOT / "sample_data" / "campaign"
KILL_RUNS = ["L070_MP0_SC_s+000", "L070_MP0_SC_s+010", "L070_MP0_SC_s+020", "L070_MP0_FS"]
WRITERS = 4


def _campaign(folder: Path, names: list[str]) -> Path:
    folder.mkdir(parents=True, exist_ok=True)
    for name in names:
        source = SAMPLE / f"{name}.mcap"
        if source.exists():
            shutil.copy(source, folder / source.name)
        else:
            shutil.copytree(SAMPLE / name, folder / name)
    return folder


def _command(folder: Path, db_url: str) -> list[str]:
    return [sys.executable, "-m", "swtlab_cli.main", "process", str(folder), "--db", db_url,
            "--quiet"]


def _start(folder: Path, db_url: str) -> subprocess.Popen:
    return subprocess.Popen(_command(folder, db_url), cwd=ROOT, stdout=subprocess.DEVNULL,
                            stderr=subprocess.PIPE, text=True,
                            env={**os.environ, "PYTHONPATH": str(ROOT)})


def _content(db_url: str) -> dict:
    """Everything a run's numbers are, without row ids and times."""
    with open_database(db_url, read_only=True)() as session:
        out = {}
        for db_run in session.scalars(select(Run)).all():
            c = db_run.condition
            files = sorted((f.version, Path(f.path).name, f.sha256, f.size_bytes)
                           for f in db_run.raw_files)
            results = []
            for f in db_run.raw_files:
                for r in session.scalars(select(RunResult).filter_by(raw_file_id=f.id)).all():
                    results.append((f.version, r.params_sha256, r.status, tuple(r.flags),
                                    r.window.start_s, r.window.end_s,
                                    tuple((q.quantity, q.mean, q.std, q.se, q.n)
                                          for q in r.quantities)))
            out[db_run.run_id] = (db_run.current_version, c.load_n, c.mode, c.slip_setpoint,
                                  files, sorted(results))
        return out


def _counts(db_url: str) -> dict[str, int]:
    with open_database(db_url, read_only=True)() as session:
        return {t.name: session.scalar(select(func.count()).select_from(t))
                for t in Base.metadata.sorted_tables}


def _duplicates_and_orphans(db_url: str) -> tuple[int, int]:
    """Rows stored twice (a run, a file version, a result of one version and parameters) and
    rows nothing leads to (a run without its file, a file without a result, a window without
    its result, a processing record no row names)."""
    with open_database(db_url, read_only=True)() as session:
        def count(query) -> int:
            return session.scalar(select(func.count()).select_from(query.subquery()))

        duplicates = (
            count(select(Run.campaign_id, Run.run_id).group_by(Run.campaign_id, Run.run_id)
                  .having(func.count() > 1))
            + count(select(RawFile.sha256).group_by(RawFile.sha256).having(func.count() > 1))
            + count(select(RunResult.raw_file_id, RunResult.params_sha256)
                    .group_by(RunResult.raw_file_id, RunResult.params_sha256)
                    .having(func.count() > 1)))
        used = set()
        for model in Base.registry.mappers:
            cls = model.class_
            if hasattr(cls, "processing_id"):
                used |= set(session.scalars(select(cls.processing_id)).all())
        orphans = (
            count(select(Run.id).where(~Run.raw_files.any()))
            + count(select(RawFile.id).where(RawFile.id.not_in(select(RunResult.raw_file_id))))
            + count(select(StableWindow.id).where(
                StableWindow.id.not_in(select(RunResult.stable_window_id))))
            + count(select(RunQuantity.id).where(
                RunQuantity.run_result_id.not_in(select(RunResult.id))))
            + len(set(session.scalars(select(ProcessingRecord.id)).all()) - used))
        return duplicates, orphans


def _results_stored(path: Path) -> int:
    """Results in a SQLite file a killed process left (0 where it made no schema yet)."""
    if not path.is_file():
        return 0
    engine = create_engine(f"sqlite:///{path}")
    try:
        with engine.connect() as connection:
            return connection.exec_driver_sql("SELECT count(*) FROM run_result").scalar()
    except Exception:  # killed before the table existed
        return 0
    finally:
        engine.dispose()


def _sqlite_checks(path: Path) -> tuple[str, int]:
    engine = create_engine(f"sqlite:///{path}")
    with engine.connect() as connection:
        integrity = connection.exec_driver_sql("PRAGMA integrity_check").scalar()
        broken_keys = len(connection.exec_driver_sql("PRAGMA foreign_key_check").all())
    engine.dispose()
    return integrity, broken_keys


def _timed(process: subprocess.Popen, path: Path) -> tuple[float, float]:
    """Seconds until the first result is in ``path`` and until ``process`` ends (exit 0)."""
    start = time.perf_counter()
    first_s = None
    while process.poll() is None:
        if first_s is None and _results_stored(path):
            first_s = time.perf_counter() - start
        time.sleep(0.05)
    full_s = time.perf_counter() - start
    if process.returncode != 0:
        raise RuntimeError(f"swtlab process failed: {process.stderr.read()[-500:]}")
    return (first_s or full_s), full_s


def kill_points(kills: int, seed: int = 0) -> dict:
    """``kills`` trials, each on a fresh SQLite file: SIGKILL once a random number k of runs
    (0 .. runs - 1) are stored, a random part of one run's time later (inside reading,
    processing or storing run k + 1), run again to the end, compare with an unkilled
    database."""
    rng = random.Random(seed)
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    with tempfile.TemporaryDirectory() as tmp:
        folder = _campaign(Path(tmp) / "campaign", KILL_RUNS)
        reference_path = Path(tmp) / "reference.sqlite"
        reference = f"sqlite:///{reference_path}"
        first_s, full_s = _timed(_start(folder, reference), reference_path)
        per_run_s = max((full_s - first_s) / (len(KILL_RUNS) - 1), 0.1)
        expected = (_content(reference), _counts(reference))
        survived = landed = mid_batch = duplicates = orphans = broken_keys = 0
        integrity = set()
        for trial in range(kills):
            killed_path = Path(tmp) / f"killed{trial}.sqlite"
            killed = f"sqlite:///{killed_path}"
            process = _start(folder, killed)
            after = rng.randrange(len(KILL_RUNS))  # results stored before the kill's run
            while process.poll() is None and _results_stored(killed_path) < after:
                time.sleep(0.02)
            time.sleep(rng.uniform(0.0, per_run_s))
            landed += process.poll() is None
            process.send_signal(signal.SIGKILL)
            process.wait(timeout=120)
            mid_batch += 0 < _results_stored(killed_path) < len(KILL_RUNS)
            subprocess.run(_command(folder, killed), cwd=ROOT, check=True,
                           stdout=subprocess.DEVNULL, env=env)
            survived += (_content(killed), _counts(killed)) == expected
            found = _duplicates_and_orphans(killed)
            duplicates, orphans = duplicates + found[0], orphans + found[1]
            check, keys = _sqlite_checks(killed_path)
            integrity.add(check)
            broken_keys += keys
    return {"kills": kills, "kills_landed": landed, "kills_mid_batch": mid_batch,
            "survived": survived, "runs": len(KILL_RUNS), "first_result_s": first_s,
            "uninterrupted_s": full_s, "duplicates": duplicates,
            "orphans": orphans, "integrity": sorted(integrity),
            "foreign_key_violations": broken_keys}


def _postgres_database(admin_url: str) -> tuple[str, callable]:
    name = f"swtlab_bench_{uuid.uuid4().hex[:10]}"
    admin = create_engine(admin_url, isolation_level="AUTOCOMMIT")
    with admin.connect() as connection:
        connection.execute(text(f'CREATE DATABASE "{name}"'))

    def drop() -> None:
        with admin.connect() as connection:
            connection.execute(text(f'DROP DATABASE "{name}" WITH (FORCE)'))
        admin.dispose()

    return make_url(admin_url).set(database=name).render_as_string(hide_password=False), drop


def concurrent_writers(backend: str, layout: str, runs: int) -> dict:
    """``WRITERS`` processes at once; how many crashed, runs stored against runs given."""
    names = sorted(p.stem for p in SAMPLE.glob("L180_MP0_SC_*.mcap"))[:runs]
    with tempfile.TemporaryDirectory() as tmp:
        if layout == "same folder":
            folders = [_campaign(Path(tmp) / "all", names)] * WRITERS
        else:
            folders = [_campaign(Path(tmp) / f"part{k}", names[k::WRITERS])
                       for k in range(WRITERS)]
        drop = None
        db_url = f"sqlite:///{tmp}/swtlab.sqlite"
        if backend == "postgresql":
            db_url, drop = _postgres_database(os.environ["SWTLAB_TEST_POSTGRES_URL"])
        try:
            start = time.perf_counter()
            processes = [_start(f, db_url) for f in folders]
            errors = [p.communicate(timeout=600)[1] for p in processes]
            seconds = time.perf_counter() - start
            crashed = sum(p.returncode != 0 for p in processes)
            with open_database(db_url, read_only=True)() as session:
                stored = session.scalars(select(Run.run_id)).all()
            duplicates, orphans = _duplicates_and_orphans(db_url)
        finally:
            if drop:
                drop()
    return {"backend": backend, "layout": layout, "writers": WRITERS, "runs": len(names),
            "crashed": crashed, "stored_once": len(set(stored) & set(names)),
            "duplicates": duplicates + len(stored) - len(set(stored)), "orphans": orphans,
            "seconds": seconds, "first_error": next((e.strip().splitlines()[-1]
                                                      for e in errors if e.strip()), "")}


def main(quick: bool = False) -> dict:
    kills = kill_points(6 if quick else 24)
    print(f"kill points: {kills['kills']} SIGKILLs of swtlab process over {kills['runs']} runs "
          f"({kills['uninterrupted_s']:.1f} s uninterrupted), each after a random number of runs "
          f"stored and a random part of the next run ({kills['kills_landed']} "
          f"before it ended, {kills['kills_mid_batch']} with some runs stored and some not), "
          f"each run again to the end: {kills['survived']} of "
          f"{kills['kills']} identical to the unkilled database, {kills['duplicates']} "
          f"duplicates, {kills['orphans']} orphans, integrity {', '.join(kills['integrity'])}, "
          f"{kills['foreign_key_violations']} foreign-key violations")
    backends = ["sqlite"] + (["postgresql"] if os.environ.get("SWTLAB_TEST_POSTGRES_URL")
                             else [])
    rows = [concurrent_writers(b, layout, 4) for b in backends
            for layout in ("same folder", "disjoint folders")]
    print(f"{'backend':11} {'layout':17} {'writers':>7} {'runs':>5} {'crashed':>7} "
          f"{'stored once':>11} {'duplicates':>10} {'orphans':>7} {'s':>6}")
    for r in rows:
        print(f"{r['backend']:11} {r['layout']:17} {r['writers']:7d} {r['runs']:5d} "
              f"{r['crashed']:7d} {r['stored_once']:11d} {r['duplicates']:10d} "
              f"{r['orphans']:7d} {r['seconds']:6.1f}")
        if r["first_error"]:
            print(f"  first error: {r['first_error']}")
    if len(backends) == 1:
        print("  (PostgreSQL not measured: set SWTLAB_TEST_POSTGRES_URL, e.g. source "
              ".ci/postgres.sh)")
    return {"kill_points": kills, "concurrent_writers": rows}
