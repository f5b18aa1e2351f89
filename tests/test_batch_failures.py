"""A batch that never dies (issue 17): a run that fails at any stage is recorded with file,
stage, exception type and reason, listed by ``swtlab results`` and the report as ``failed``,
and the runs after it are stored; exit 4 only for a fault outside any run."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import numpy as np
import pytest

import swtlab
from bench.mcap_content import read_content, write_content
from swtlab.pipeline.campaign import FailureKind
from swtlab_cli import exit_codes
from swtlab_cli.main import main

SAMPLE = Path(__file__).resolve().parents[1] / "sample_data" / "campaign"
GOOD = SAMPLE / "L180_MP0_SC_s+020.mcap"


def _bool_samples(content) -> None:
    blocks = content.blocks("/hub/wrench")
    blocks[0]["fz"][0] = True
    content.set_blocks("/hub/wrench", blocks)


def _still_wheel(content) -> None:
    blocks = content.blocks("/wheel/encoder")
    for b in blocks:
        b["angle"] = [0.0] * len(b["angle"])
    content.set_blocks("/wheel/encoder", blocks)


def _changed(path: Path, run_id: str, change=None) -> Path:
    content = read_content(GOOD)
    content.metadata["swt.run"]["run_id"] = run_id
    if change is not None:
        change(content)
    return write_content(path, content)


@pytest.fixture
def folder(tmp_path) -> Path:
    """Bad runs sorted in front of a good one: unparseable bytes, bool samples, a wheel that
    never turns, a run whose results raise (injected by the tests that need it)."""
    folder = tmp_path / "campaign"
    folder.mkdir()
    (folder / "a_unparseable.mcap").write_bytes(b"\x89MCAP0\r\n" + bytes(range(256)) * 4)
    _changed(folder / "b_bool_samples.mcap", "b_bool", _bool_samples)
    _changed(folder / "c_still_wheel.mcap", "c_still", _still_wheel)
    _changed(folder / "d_results_raise.mcap", "d_raise")
    shutil.copy(GOOD, folder / "z_good.mcap")
    return folder


@pytest.fixture
def results_raise(monkeypatch):
    import run_results

    real = run_results.process_run

    def process_run(run, *args):
        if run.run_id == "d_raise":
            raise ZeroDivisionError("injected")
        return real(run, *args)

    monkeypatch.setattr(run_results, "process_run", process_run)


def test_the_pipeline_goes_on_after_every_kind_of_failure(folder, results_raise):
    campaign = swtlab.process_campaign(folder, soil_flow=False)
    table = campaign.results.set_index("run_id")
    assert table.loc["L180_MP0_SC_s+020", "status"] == "ok"
    assert table.loc["c_still", "status"] == "flagged"
    assert "wheel_angle_rad is constant" in table.loc["c_still", "flags"]
    failures = {Path(f.file).name: f for f in campaign.failures}
    assert sorted(failures) == ["a_unparseable.mcap", "b_bool_samples.mcap",
                                "d_results_raise.mcap"]
    refused = failures["a_unparseable.mcap"]
    assert (refused.stage, refused.error_type, refused.kind) \
        == ("ingest", "IngestError", FailureKind.REFUSED)
    assert refused.line == refused.reason and refused.reason.startswith(refused.file + ": ")
    assert "JSON type bool" in failures["b_bool_samples.mcap"].reason
    raised = failures["d_results_raise.mcap"]
    assert (raised.stage, raised.error_type, raised.kind, raised.reason) == (
        "results", "ZeroDivisionError", FailureKind.INTERNAL,
        "internal error (ZeroDivisionError: injected)")
    assert raised.line == f"{raised.file}: results: {raised.reason}"
    assert all("\n" not in f.reason for f in campaign.failures)


def test_swtlab_process_stores_the_good_runs_and_lists_the_failed(folder, results_raise,
                                                                  tmp_path, capsys):
    url = f"sqlite:///{tmp_path / 'swtlab.sqlite'}"
    assert main(["process", str(folder), "--db", url, "--quiet"]) == exit_codes.OK
    out = capsys.readouterr().out
    assert "processed 2 of 5 runs" in out and "3 failed" in out
    assert "d_results_raise.mcap: results: internal error (ZeroDivisionError: injected)" in out
    assert main(["results", "--db", url, "--json"]) == exit_codes.OK
    rows = {r["run_id"]: r for r in json.loads(capsys.readouterr().out)}
    assert rows["L180_MP0_SC_s+020"]["status"] == "ok" and rows["c_still"]["status"] == "flagged"
    failed = {k: r for k, r in rows.items() if r["status"] == "failed"}
    assert sorted(failed) == ["a_unparseable", "b_bool_samples", "d_raise"]
    assert failed["d_raise"]["failure_stage"] == "results"
    assert failed["d_raise"]["failure_type"] == "ZeroDivisionError"
    assert failed["b_bool_samples"]["failure_stage"] == "ingest"
    assert "JSON type bool" in failed["b_bool_samples"]["failure_reason"]
    # a rerun records nothing twice; a fixed file is no longer failed
    assert main(["process", str(folder), "--db", url, "--quiet"]) == exit_codes.OK
    capsys.readouterr()
    with swtlab_session(url) as session:
        from traceability.models import IngestFailure
        assert session.query(IngestFailure).count() == 3
    _changed(folder / "a_unparseable.mcap", "a_fixed")
    _changed(folder / "b_bool_samples.mcap", "b_bool")
    assert main(["process", str(folder), "--db", url, "--quiet"]) == exit_codes.OK
    assert main(["results", "--db", url]) == exit_codes.OK
    summary = capsys.readouterr().out
    assert "failed: d_raise" in summary and "failed: a_unparseable" not in summary
    assert "failed: b_bool" not in summary


def swtlab_session(url: str):
    from traceability import open_database

    return open_database(url)()


def test_a_run_the_database_refuses_is_a_failure_of_stage_store(folder, tmp_path, capsys,
                                                                monkeypatch):
    from swtlab.pipeline import database

    real = database.store_processed

    def refuse(session, done, parameters, **options):
        if done.path.name == "c_still_wheel.mcap":
            real(session, done, parameters, **options)
            raise ValueError("the database refuses this run")
        return real(session, done, parameters, **options)

    monkeypatch.setattr(database, "store_processed", refuse)
    url = f"sqlite:///{tmp_path / 'swtlab.sqlite'}"
    assert main(["process", str(folder), "--db", url, "--quiet"]) == exit_codes.OK
    assert "c_still_wheel.mcap: store: internal error (ValueError: the database refuses" \
        in capsys.readouterr().out
    assert main(["results", "--db", url, "--json"]) == exit_codes.OK
    rows = {r["run_id"]: r for r in json.loads(capsys.readouterr().out)}
    assert rows["c_still"]["status"] == "failed" and rows["c_still"]["failure_stage"] == "store"
    assert rows["L180_MP0_SC_s+020"]["status"] == "ok"   # stored after the refused one


def test_only_bad_runs_is_exit_3_and_a_bad_channel_map_is_exit_3(folder, tmp_path, capsys):
    only_bad = tmp_path / "only_bad"
    only_bad.mkdir()
    shutil.copy(folder / "a_unparseable.mcap", only_bad)
    url = f"sqlite:///{tmp_path / 'swtlab.sqlite'}"
    assert main(["process", str(only_bad), "--db", url, "--quiet"]) == exit_codes.BAD_INPUT
    bad_map = tmp_path / "map.toml"
    bad_map.write_text('map = "x"\n')
    capsys.readouterr()
    assert main(["process", str(folder), "--db", url, "--channel-map", str(bad_map),
                 "--quiet"]) == exit_codes.BAD_INPUT
    err = capsys.readouterr().err.strip()
    assert "\n" not in err and "map.toml: map: channel map: must be a table" in err


def test_the_report_lists_failed_runs_and_draws_a_run_id_with_math_text(tmp_path, capsys):
    """A run id holding an unbalanced matplotlib math expression is drawn literally."""
    folder = tmp_path / "campaign"
    folder.mkdir()
    _changed(folder / "math.mcap", r"run $\frac{$ x")
    (folder / "broken.mcap").write_bytes(b"not an mcap")
    url = f"sqlite:///{tmp_path / 'swtlab.sqlite'}"
    assert main(["process", str(folder), "--db", url, "--quiet"]) == exit_codes.OK
    page = tmp_path / "report.html"
    assert main(["report", "--db", url, "-o", str(page), "--quiet"]) == exit_codes.OK
    text = page.read_text(encoding="utf-8")
    assert r"run $\frac{$ x" in text
    assert '<span class="status failed">failed</span>' in text and "broken.mcap" in text
    assert "1 failed" in text
    capsys.readouterr()


def test_plain_text_escapes_every_dollar():
    from matplotlib.figure import Figure

    from campaign_report.images import to_png
    from campaign_report.style import plain_text

    fig = Figure()
    fig.suptitle(plain_text(r"run $\frac{$ x and $y$"))
    png, _ = to_png(fig)
    assert png[:4] == b"\x89PNG" and plain_text("a $b$") == r"a \$b\$"
    assert np.isfinite(len(png))


def test_a_failure_stored_before_its_type_was_recorded_reads_as_an_ingest_error():
    # migration 0010 added error_type; the rows before it were ingest failures
    from traceability.models import IngestFailure

    assert IngestFailure(error_type=None).failure_type == "IngestError"
    assert IngestFailure(error_type="RunIdClaimed").failure_type == "RunIdClaimed"
