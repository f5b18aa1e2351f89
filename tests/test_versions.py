"""Versions mean what they say (issue 17, item 4): a new version carries its condition and its
results, another file's run_id is refused unless allowed, a reverted file is current again, a
vanished file is marked missing, a run without run_id is found by its content. On SQLite and
PostgreSQL (``db_url``). The runs are the synthetic spec MCAP of conftest, whose constant
``fz`` is the true wheel load."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import pytest
from sqlalchemy import func, select

from swtlab.pipeline.campaign import FailureKind
from swtlab_cli.main import main
from traceability import open_database
from traceability.models import RawFile, Run, RunResult

pytestmark = pytest.mark.slow  # every test stores runs on SQLite and PostgreSQL (1-3 s each)


def _write(path: Path, tools, fz_n: float = 150.0, **records) -> Path:
    """A spec MCAP at ``path`` whose set load is ``fz_n`` and whose hub measures ``fz_n``;
    ``records``: changes of the run record (None removes a key)."""
    topics = tools.truth_topics()
    topics["/hub/wrench"]["fz"] = fz_n + 0 * topics["/hub/wrench"]["fz"]
    run = {"load_N": f"{fz_n:g}", **records}
    path.parent.mkdir(parents=True, exist_ok=True)
    return tools.write_mcap(path, tools.Spec(topics=topics, records=tools.records(run=run)))


def _process(folder: Path, db_url: str, capsys, *extra: str) -> str:
    assert main(["process", str(folder), "--db", db_url, "--quiet", *extra]) == 0
    return capsys.readouterr().out


def _results(db_url: str, capsys) -> list[dict]:
    assert main(["results", "--db", db_url, "--json"]) == 0
    return json.loads(capsys.readouterr().out)


def _count(db_url: str, model) -> int:
    with open_database(db_url, read_only=True)() as session:
        return session.scalar(select(func.count()).select_from(model))


def test_new_version_updates_condition_and_results(tmp_path, db_url, ingest_tools, capsys):
    run = _write(tmp_path / "c" / "a.mcap", ingest_tools, fz_n=180.0)
    _process(tmp_path / "c", db_url, capsys)
    _write(run, ingest_tools, fz_n=190.0)  # the load corrected: a new version of r001
    _process(tmp_path / "c", db_url, capsys)
    (row,) = _results(db_url, capsys)
    assert (row["run_id"], row["raw_file_version"], row["load_set_n"]) == ("r001", 2, 190.0)
    assert row["wheel_load_n_mean"] == pytest.approx(190.0, abs=1e-6)
    with open_database(db_url, read_only=True)() as session:
        db_run = session.scalars(select(Run)).one()
        assert db_run.condition.load_n == 190.0 and db_run.current_version == 2
    assert _count(db_url, RawFile) == 2 and _count(db_url, RunResult) == 2


def test_another_file_claiming_a_run_id_is_refused_unless_allowed(tmp_path, db_url,
                                                                  ingest_tools, capsys):
    first = _write(tmp_path / "c" / "a.mcap", ingest_tools, fz_n=180.0)
    _process(tmp_path / "c", db_url, capsys)
    other = _write(tmp_path / "c" / "b.mcap", ingest_tools, fz_n=300.0)  # run_id r001 too
    out = _process(tmp_path / "c", db_url, capsys)
    refusal = next(line for line in out.splitlines() if "claims run_id" in line)
    assert str(other) in refusal and str(first) in refusal and "--allow-run-id-reuse" in refusal
    assert "1 failed" in out
    rows = _results(db_url, capsys)  # the refused file is listed as failed, of stage store
    (row,) = [r for r in rows if r["status"] != "failed"]
    (refused,) = [r for r in rows if r["status"] == "failed"]
    assert (refused["raw_file_path"], refused["failure_stage"]) == (str(other), "store")
    assert (row["raw_file_path"], row["load_set_n"]) == (str(first), 180.0)
    assert _count(db_url, RawFile) == 1

    _process(tmp_path / "c", db_url, capsys, "--allow-run-id-reuse")
    for _ in range(2):  # allowed once; the first file, still there, does not take it back
        (row,) = _results(db_url, capsys)
        assert (row["raw_file_path"], row["load_set_n"]) == (str(other), 300.0)
        assert row["wheel_load_n_mean"] == pytest.approx(300.0, abs=1e-6)
        assert row["raw_file_version"] == 2
        _process(tmp_path / "c", db_url, capsys)
    other.unlink()  # the run's current file gone: the first file's version is current again
    _process(tmp_path / "c", db_url, capsys)
    (row,) = _results(db_url, capsys)
    assert (row["raw_file_path"], row["load_set_n"], row["raw_file_version"]) == (
        str(first), 180.0, 1)


def test_reverted_file_makes_its_version_current_again(tmp_path, db_url, ingest_tools, capsys):
    run = _write(tmp_path / "c" / "a.mcap", ingest_tools, fz_n=180.0)
    old_bytes = run.read_bytes()
    _process(tmp_path / "c", db_url, capsys)
    _write(run, ingest_tools, fz_n=190.0)
    _process(tmp_path / "c", db_url, capsys)
    run.write_bytes(old_bytes)
    _process(tmp_path / "c", db_url, capsys)
    (row,) = _results(db_url, capsys)
    assert (row["raw_file_version"], row["load_set_n"]) == (1, 180.0)
    assert row["wheel_load_n_mean"] == pytest.approx(180.0, abs=1e-6)
    assert _count(db_url, RawFile) == 2 and _count(db_url, RunResult) == 2
    out = _process(tmp_path / "c", db_url, capsys)  # now up to date without reading it
    assert "(1 already up to date)" in out


def test_missing_file_is_marked_and_listed_with_a_notice(tmp_path, db_url, ingest_tools,
                                                         capsys):
    kept = _write(tmp_path / "c" / "a.mcap", ingest_tools)
    gone = _write(tmp_path / "c" / "b.mcap", ingest_tools, run_id="r002")
    _process(tmp_path / "c", db_url, capsys)
    saved = gone.read_bytes()
    gone.unlink()
    out = _process(tmp_path / "c", db_url, capsys)
    assert f"missing: {gone} (run r002)" in out
    assert main(["results", "--db", db_url, "--json"]) == 0
    captured = capsys.readouterr()
    rows = {r["run_id"]: r for r in json.loads(captured.out)}
    assert rows["r002"]["raw_file_missing"] is True and rows["r001"]["raw_file_missing"] is False
    assert "notice" in captured.err and str(gone) in captured.err and str(kept) not in captured.err
    gone.write_bytes(saved)  # back: no longer marked
    assert "  missing: " not in _process(tmp_path / "c", db_url, capsys)
    assert not any(r["raw_file_missing"] for r in _results(db_url, capsys))


def test_run_without_run_id_is_found_by_content_when_renamed(tmp_path, db_url, ingest_tools,
                                                             capsys):
    run = _write(tmp_path / "c" / "first_name.mcap", ingest_tools, run_id=None)
    _process(tmp_path / "c", db_url, capsys)
    renamed = tmp_path / "c" / "sub" / "second_name.mcap"
    renamed.parent.mkdir()
    shutil.move(run, renamed)
    out = _process(tmp_path / "c", db_url, capsys)
    assert "(1 already up to date)" in out and "  missing: " not in out
    (row,) = _results(db_url, capsys)  # once in the results, so once in every fit
    assert (row["run_id"], row["raw_file_path"]) == ("first_name", str(renamed))
    assert _count(db_url, Run) == 1 and _count(db_url, RawFile) == 1


def test_python_store_refuses_a_claimed_run_id_as_a_failure(tmp_path, db_url, ingest_tools):
    import swtlab

    first = _write(tmp_path / "c" / "a.mcap", ingest_tools, fz_n=180.0)
    assert swtlab.store(swtlab.process_campaign(tmp_path / "c"), db_url) == 1
    other = _write(tmp_path / "c" / "b.mcap", ingest_tools, fz_n=300.0)
    campaign = swtlab.process_campaign(tmp_path / "c")
    assert swtlab.store(campaign, db_url) == 0
    (failure,) = campaign.failures
    assert failure.stage == "store" and failure.file == str(other)
    # the user's input (the run id), reported on a line that names the file itself
    assert (failure.error_type, failure.kind) == ("RunIdClaimed", FailureKind.INPUT)
    assert failure.line == f"{other}: store: {failure.reason}"
    assert str(first) in failure.reason and "claims run_id 'r001'" in failure.reason
    assert list(swtlab.load(db_url).results["load_set_n"]) == [180.0]
