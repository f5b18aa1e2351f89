"""Database URLs and schemas (issue 17, items 5 and 8): a plain path is SQLite, ``postgres://``
is understood, read commands create nothing and never migrate, an unreachable server or a
refused login is exit 3 naming the host and not the password; user text up to 1,000
characters is held, longer or NUL-bearing names refused alike on SQLite and PostgreSQL."""

from __future__ import annotations

import json
import os
from pathlib import Path

import pytest
from sqlalchemy import create_engine
from sqlalchemy.engine import make_url

from swtlab_cli import exit_codes
from swtlab_cli.main import main
from traceability import open_database
from traceability.database import database_url, head_revision

SAMPLE_RUN = Path(__file__).resolve().parents[1] / "sample_data" / "campaign" / \
    "L070_MP0_SC_s+010.mcap"


def _one_line_error(capsys, command: str) -> str:
    captured = capsys.readouterr()
    assert captured.err.count("\n") == 1 and captured.err.startswith(f"swtlab {command}: ")
    return captured.err


def test_plain_path_is_sqlite_and_postgres_scheme_is_psycopg(tmp_path, capsys):
    assert database_url("db/x.sqlite") == f"sqlite:///{Path('db/x.sqlite').resolve()}"
    assert database_url("postgres://u:p@h:5/d") == "postgresql+psycopg://u:p@h:5/d"
    assert database_url("postgresql://u@h/d") == "postgresql+psycopg://u@h/d"
    assert database_url("sqlite:///a.sqlite") == "sqlite:///a.sqlite"
    campaign = tmp_path / "c"
    campaign.mkdir()
    (campaign / SAMPLE_RUN.name).write_bytes(SAMPLE_RUN.read_bytes())
    path = tmp_path / "plain" / "swtlab.sqlite"
    assert main(["process", str(campaign), "--db", str(path), "--quiet"]) == 0
    assert path.is_file()
    capsys.readouterr()
    assert main(["results", "--db", str(path), "--json"]) == 0
    assert [r["run_id"] for r in json.loads(capsys.readouterr().out)] == [SAMPLE_RUN.stem]


@pytest.mark.parametrize("argv", [
    ["results", "--db", "{db}"], ["export", "--db", "{db}", "-o", "{tmp}/wpm.csv"],
    ["report", "--db", "{db}", "-o", "{tmp}/r.html"],
    ["gap", "--measured", "{db}", "--sim", "bb2_sand"]])
def test_read_commands_on_a_missing_database_create_nothing(tmp_path, capsys, argv):
    db = f"sqlite:///{tmp_path / 'typo' / 'typo.sqlite'}"
    argv = [a.format(db=db, tmp=tmp_path) for a in argv]
    assert main(argv) == exit_codes.BAD_INPUT
    err = _one_line_error(capsys, argv[0])
    assert "no such database file" in err and "swtlab process" in err
    assert sorted(p.name for p in tmp_path.iterdir()) == []  # no file, no folder


def test_unreachable_server_and_refused_login_name_the_host_not_the_password(capsys, db_url):
    if db_url.startswith("sqlite"):  # a closed port: nothing listens on 1
        url = "postgres://lab:s3cret-pw@127.0.0.1:1/swtlab"
    else:  # a running server, a role it does not know
        url = make_url(db_url).set(username="nobody_here", password="s3cret-pw").render_as_string(
            hide_password=False)
    assert main(["results", "--db", url]) == exit_codes.BAD_INPUT
    err = _one_line_error(capsys, "results")
    assert "127.0.0.1" in err and "s3cret-pw" not in err and "internal error" not in err


def test_read_commands_never_migrate_and_name_the_upgrade(tmp_path, capsys, db_url):
    from alembic import command
    from alembic.config import Config
    from alembic.migration import MigrationContext

    from traceability.database import MIGRATIONS

    open_database(db_url)
    engine = create_engine(database_url(db_url))
    config = Config()
    config.set_main_option("script_location", str(MIGRATIONS))
    with engine.begin() as connection:
        config.attributes["connection"] = connection
        command.downgrade(config, "0007")

    def revision() -> str:
        with engine.connect() as connection:
            return MigrationContext.configure(connection).get_current_revision()

    for argv in (["results", "--db", db_url], ["report", "--db", db_url, "-o",
                                                str(tmp_path / "r.html")]):
        assert main(argv) == exit_codes.BAD_INPUT
        err = _one_line_error(capsys, argv[0])
        assert "older" in err and "swtlab migrate --db" in err
        assert revision() == "0007"
    assert main(["migrate", "--db", db_url]) == 0
    assert revision() == head_revision()
    engine.dispose()


def _run_with_id(tmp_path: Path, tools, run_id: str) -> Path:
    folder = tmp_path / "c"
    folder.mkdir(exist_ok=True)
    return tools.write_mcap(folder / f"run{len(list(folder.iterdir()))}.mcap", tools.Spec(
        topics=tools.truth_topics(), records=tools.records(run={"run_id": run_id})))


def test_run_ids_of_1000_characters_are_held_longer_or_nul_refused(tmp_path, db_url,
                                                                    ingest_tools, capsys):
    long_id = "é" + "x" * 998 + "∑"  # 1,000 characters, 1,003 bytes UTF-8
    _run_with_id(tmp_path, ingest_tools, long_id)
    too_long = _run_with_id(tmp_path, ingest_tools, "y" * 1001)
    with_nul = _run_with_id(tmp_path, ingest_tools, "a\x00b")
    assert main(["process", str(tmp_path / "c"), "--db", db_url, "--quiet"]) == 0
    out = capsys.readouterr().out
    assert "processed 1 of 3 runs" in out and "2 failed" in out
    failed = [line for line in out.splitlines() if line.startswith("  failed: ")]
    assert any(str(too_long) in f and "1001 characters" in f for f in failed)
    assert any(str(with_nul) in f and "NUL" in f for f in failed)
    assert main(["results", "--db", db_url, "--json"]) == 0
    rows = json.loads(capsys.readouterr().out)
    assert [r["run_id"] for r in rows if r["status"] != "failed"] == [long_id]
    # the refused ones are listed as failed under their file names
    assert sorted(r["run_id"] for r in rows if r["status"] == "failed") == [
        too_long.stem, with_nul.stem]


@pytest.mark.skipif(not os.environ.get("SWTLAB_TEST_POSTGRES_URL"), reason="no PostgreSQL")
def test_postgres_scheme_reads_a_processed_database(tmp_path, db_url, ingest_tools, capsys):
    if db_url.startswith("sqlite"):
        pytest.skip("the postgres:// spelling of a PostgreSQL URL")
    _run_with_id(tmp_path, ingest_tools, "r001")
    assert main(["process", str(tmp_path / "c"), "--db", db_url, "--quiet"]) == 0
    capsys.readouterr()
    plain = "postgres://" + db_url.split("://", 1)[1]
    assert main(["results", "--db", plain, "--json"]) == 0
    assert [r["run_id"] for r in json.loads(capsys.readouterr().out)] == ["r001"]


def test_an_older_database_holding_runs_is_upgraded_with_them(tmp_path, capsys):
    """A 0.2.0 database (schema 0007) with a processed run: the batch migrations rebuild
    tables that others reference, which SQLite refused under its foreign keys ("FOREIGN
    KEY constraint failed", found on the demo's database of the last release)."""
    from alembic import command
    from alembic.config import Config

    from traceability.database import MIGRATIONS

    folder = tmp_path / "c"
    folder.mkdir()
    (folder / SAMPLE_RUN.name).write_bytes(SAMPLE_RUN.read_bytes())
    db = f"sqlite:///{tmp_path / 'old.sqlite'}"
    assert main(["process", str(folder), "--db", db, "--quiet"]) == 0
    engine = create_engine(db)  # a plain engine: SQLite's foreign keys off, as at 0.2.0
    config = Config()
    config.set_main_option("script_location", str(MIGRATIONS))
    with engine.begin() as connection:
        config.attributes["connection"] = connection
        command.downgrade(config, "0007")
    engine.dispose()
    capsys.readouterr()
    assert main(["migrate", "--db", db]) == 0
    assert main(["results", "--db", db, "--json"]) == 0
    (row,) = json.loads(capsys.readouterr().out.split("\n", 1)[1])
    assert row["run_id"] == SAMPLE_RUN.stem and row["status"] in ("ok", "flagged")
