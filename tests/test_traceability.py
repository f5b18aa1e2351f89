"""Traceability database: raw-file versions, idempotent re-ingest, batches past bad runs."""

from __future__ import annotations

import hashlib
import importlib.metadata

import shutil
from pathlib import Path

import pytest
from sqlalchemy import func, inspect, select

import ingest
from ingest.inspect_report import report
from swtlab_cli.main import main
from traceability import open_database, store_ingested_run
from traceability.database import upgrade
from traceability.models import (Calibration, IngestFailure, ProcessingRecord, RawFile, Run,
                                 TestCondition)
from traceability.store import StoreOutcome

SAMPLE = Path(__file__).resolve().parents[1] / "sample_data" / "campaign"


def _some_runs(kind: str, count: int) -> list[Path]:
    runs = sorted(SAMPLE.glob("*.mcap")) if kind == "mcap" else sorted(
        p.parent for p in SAMPLE.glob("*/run.json"))
    assert len(runs) >= count, f"sample campaign has fewer than {count} {kind} runs"
    return runs[:count]


def _store(factory, path: Path) -> StoreOutcome:
    run = ingest.read_run(path)
    with factory.begin() as session:
        _, outcome = store_ingested_run(session, run, report(run)["streams"], {"test": True})
    return outcome


def _count(factory, model) -> int:
    with factory() as session:
        return session.scalar(select(func.count()).select_from(model))


def test_unchanged_file_changes_nothing_and_changed_file_gets_new_version(tmp_path, db_url):
    csv_run = tmp_path / "run_csv"
    shutil.copytree(_some_runs("csv", 1)[0], csv_run)
    mcap_run = tmp_path / "run.mcap"
    shutil.copy(_some_runs("mcap", 1)[0], mcap_run)
    factory = open_database(db_url)

    assert _store(factory, csv_run) is StoreOutcome.NEW_RUN
    assert _store(factory, mcap_run) is StoreOutcome.NEW_RUN
    before = {m: _count(factory, m) for m in (RawFile, ProcessingRecord, Calibration, Run)}
    assert _store(factory, csv_run) is StoreOutcome.UNCHANGED
    assert _store(factory, mcap_run) is StoreOutcome.UNCHANGED
    assert {m: _count(factory, m) for m in before} == before

    # Edit one force sample of the CSV run: a new version, the old one kept untouched.
    wrench = csv_run / "hub_wrench.csv"
    lines = wrench.read_text().splitlines()
    cells = lines[5].split(",")
    cells[3] = f"{float(cells[3]) + 1.0:.3f}"
    lines[5] = ",".join(cells)
    wrench.write_text("\n".join(lines) + "\n")
    assert _store(factory, csv_run) is StoreOutcome.NEW_VERSION
    with factory() as session:
        versions = session.scalars(select(RawFile).join(Run).where(
            Run.run_id == ingest.read_run(csv_run).run_id).order_by(RawFile.version)).all()
        assert [v.version for v in versions] == [1, 2]
        assert versions[0].sha256 != versions[1].sha256
        assert versions[0].processing_id != versions[1].processing_id
        assert session.scalar(select(func.count()).select_from(Run)) == 2


def test_conditions_and_calibrations_are_recorded(db_url):
    path = _some_runs("mcap", 1)[0]
    run = ingest.read_run(path)
    factory = open_database(db_url)
    _store(factory, path)
    with factory() as session:
        condition = session.scalars(select(TestCondition)).one()
        assert condition.load_n == run.metadata.run.condition.load_set_n
        assert condition.mode == run.metadata.run.condition.mode
        assert condition.multipass == run.metadata.run.condition.multipass
        assert condition.wheel.radius_m == run.metadata.wheel.radius_m
        raw = session.scalars(select(RawFile)).one()
        zeros = {c.field: -c.offset for c in raw.calibrations if c.kind == "zero"}
        assert zeros == pytest.approx(run.metadata.zero)
        assert raw.size_bytes == path.stat().st_size
        assert {s["topic"] for s in raw.channel_summary} == set(run.streams)
        record = session.scalars(select(ProcessingRecord)).one()
        assert record.swtlab_version == importlib.metadata.version("swtlab")
        lock = Path(__file__).resolve().parents[1] / "requirements.lock"  # read apart here
        assert record.lock_sha256 == hashlib.sha256(lock.read_bytes()).hexdigest()


def test_migrations_go_up_and_down(db_url):
    from alembic import command
    from alembic.config import Config
    from sqlalchemy import create_engine

    from traceability.database import MIGRATIONS

    engine = create_engine(db_url)
    upgrade(engine)
    assert {"raw_file", "run", "test_condition", "calibration"} <= set(
        inspect(engine).get_table_names())
    config = Config()
    config.set_main_option("script_location", str(MIGRATIONS))
    with engine.begin() as connection:
        config.attributes["connection"] = connection
        command.downgrade(config, "base")
    assert set(inspect(engine).get_table_names()) == {"alembic_version"}


def test_batch_goes_on_past_bad_runs(tmp_path, capsys, db_url):
    campaign = tmp_path / "campaign"
    campaign.mkdir()
    good = _some_runs("mcap", 2)
    for path in good:
        shutil.copy(path, campaign / path.name)
    corrupt = campaign / "corrupt.mcap"
    corrupt.write_bytes(good[0].read_bytes()[: good[0].stat().st_size // 2])
    db = db_url

    assert main(["process", str(campaign), "--db", db, "--quiet"]) == 0
    out = capsys.readouterr().out
    assert "processed 2 of 3 runs" in out and "1 failed" in out
    assert "corrupt.mcap" in out
    factory = open_database(db)
    assert _count(factory, RawFile) == 2
    assert _count(factory, IngestFailure) == 1
    # the failure is listed again on the next call, but stored once
    assert main(["process", str(campaign), "--db", db, "--quiet"]) == 0
    assert "1 failed" in capsys.readouterr().out
    assert _count(factory, IngestFailure) == 1

    only_bad = tmp_path / "only_bad"
    only_bad.mkdir()
    shutil.copy(corrupt, only_bad / corrupt.name)
    assert main(["process", str(only_bad), "--db", db, "--quiet"]) == 3


def test_migrations_match_the_models(tmp_path):
    """Alembic's autogenerate finds nothing to add: the migrations create exactly the ORM schema."""
    from alembic.autogenerate import compare_metadata
    from alembic.migration import MigrationContext
    from sqlalchemy import create_engine

    from traceability.models import Base

    engine = create_engine(f"sqlite:///{tmp_path / 'db.sqlite'}")
    upgrade(engine)
    with engine.connect() as connection:
        assert compare_metadata(MigrationContext.configure(connection), Base.metadata) == []
