"""swtlab process / results end to end: one row per run; a batch killed midway finishes cleanly."""

from __future__ import annotations

import json
import os
import shutil
import signal
import subprocess
import sys
import time
from pathlib import Path

import pandas as pd
import pytest
from sqlalchemy import func, select

import ingest
from swtlab_cli.main import main
from traceability import open_database
from traceability.models import ProcessingRecord, RawFile, RunQuantity, RunResult, StableWindow

pytestmark = [pytest.mark.slow,  # campaigns processed by swtlab process, one batch killed midway
              pytest.mark.slow_campaign, pytest.mark.slow_workers]

SAMPLE = Path(__file__).resolve().parents[1] / "sample_data"
QUANTITIES = ("slip", "travel_velocity_mps", "wheel_omega_radps", "wheel_load_n", "dp_n",
              "torque_nm", "thrust_n", "resistance_n", "sinkage_m")


def _small_campaign(tmp_path: Path, run_ids: list[str]) -> Path:
    campaign = tmp_path / "campaign"
    campaign.mkdir(parents=True)
    for run_id in run_ids:
        source = SAMPLE / "campaign" / f"{run_id}.mcap"
        if source.exists():
            shutil.copy(source, campaign / source.name)
        else:
            shutil.copytree(SAMPLE / "campaign" / run_id, campaign / run_id)
    return campaign


def _counts(db_url: str) -> dict[str, int]:
    with open_database(db_url)() as session:
        return {model.__name__: session.scalar(select(func.count()).select_from(model))
                for model in (RawFile, RunResult, StableWindow, RunQuantity, ProcessingRecord)}


def test_results_table_has_one_row_per_run_with_the_truth(tmp_path, db_url, capsys):
    run_ids = ["L180_MP0_SC_s+020", "L180_MP0_SC_s+090", "L180_MP0_TW", "L180_MP0_SC_s+000"]
    campaign = _small_campaign(tmp_path, run_ids)
    assert main(["process", str(campaign), "--db", db_url, "--quiet"]) == 0
    out = capsys.readouterr().out
    assert "processed 4 of 4 runs" in out and "without a stable phase" in out
    assert main(["results", "--db", db_url, "--json"]) == 0
    table = pd.DataFrame(json.loads(capsys.readouterr().out)).set_index("run_id")
    assert sorted(table.index) == sorted(run_ids)
    for q in QUANTITIES:
        assert {f"{q}_mean", f"{q}_std", f"{q}_se"} <= set(table.columns)
    assert table.loc["L180_MP0_SC_s+090", "status"] == "no_stable_phase"
    assert "digs in" in table.loc["L180_MP0_SC_s+090", "no_window_reason"]
    for run_id in ("L180_MP0_SC_s+020", "L180_MP0_TW"):
        truth = json.loads((SAMPLE / "truth" / f"{run_id}.json").read_text())
        row, means = table.loc[run_id], truth["stable_means"]
        assert row["status"] == "ok"
        assert abs(row["window_start_s"] - truth["stable_window"]["start_s"]) < 2.0
        assert abs(row["dp_n_mean"] - means["dp_n"]) < max(0.01 * abs(means["dp_n"]),
                                                          3 * row["dp_n_se"]) + 0.5
        assert abs(row["slip_mean"] - means["slip"]) < 2e-3
    csv_path = tmp_path / "results.csv"
    assert main(["results", "--db", db_url, "--csv", str(csv_path)]) == 0
    assert len(pd.read_csv(csv_path)) == len(run_ids)
    capsys.readouterr()
    # towed R against powered R near zero slip, against the truth of both runs (BB2 model at
    # 180 N: 22.6 N towed at the part II skid of -0.056, 18.1 N powered at s = 0)
    assert main(["results", "--db", db_url, "--towed", "--json"]) == 0
    (towed,) = json.loads(capsys.readouterr().out)
    assert towed["load_n"] == 180.0 and towed["towed_runs"] == ["L180_MP0_TW"]
    assert towed["powered_runs"] == ["L180_MP0_SC_s+000"]
    true_r = {run_id: json.loads((SAMPLE / "truth" / f"{run_id}.json").read_text())
              ["stable_means"]["motion_resistance_n"] for run_id in towed["towed_runs"]
              + towed["powered_runs"]}
    assert towed["towed_resistance_n"] == pytest.approx(true_r["L180_MP0_TW"], abs=1.0)
    assert towed["difference_n"] == pytest.approx(
        true_r["L180_MP0_TW"] - true_r["L180_MP0_SC_s+000"], abs=1.5)


def test_reprocessing_changes_nothing(tmp_path, db_url):
    campaign = _small_campaign(tmp_path, ["L070_MP0_SC_s+010", "L070_MP0_FS"])
    assert main(["process", str(campaign), "--db", db_url, "--quiet"]) == 0
    before = _counts(db_url)
    assert main(["process", str(campaign), "--db", db_url, "--quiet"]) == 0
    assert _counts(db_url) == before


def test_killed_batch_finishes_on_rerun_without_duplicates(tmp_path):
    """SIGKILL mid-batch, run again: every run once, nothing lost (each run is one transaction).
    One worker, so runs are stored one by one as they are done (with a worker per core a
    many-core machine stores all 16 within one poll)."""
    run_ids = sorted(p.stem for p in (SAMPLE / "campaign").glob("L300_*.mcap"))
    campaign = _small_campaign(tmp_path, run_ids)
    db_url = f"sqlite:///{tmp_path / 'swtlab.sqlite'}"
    command = [sys.executable, "-m", "swtlab_cli.main", "process", str(campaign), "--db", db_url,
               "--jobs", "1", "--quiet"]
    process = subprocess.Popen(command, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE,
                               env={**os.environ, "PYTHONUNBUFFERED": "1"})
    deadline = time.monotonic() + 120
    stored = 0
    while time.monotonic() < deadline and process.poll() is None:
        time.sleep(0.05)
        try:
            stored = _counts(db_url)["RunResult"]
        except Exception:  # the schema may not exist yet
            continue
        if stored >= 3:
            process.send_signal(signal.SIGKILL)
            break
    process.wait(timeout=60)
    assert process.returncode == -signal.SIGKILL, "the batch ended before it could be killed"
    assert 3 <= stored < len(run_ids)
    kept = _counts(db_url)
    assert kept["RunResult"] >= stored
    assert main(["process", str(campaign), "--db", db_url, "--quiet"]) == 0
    after = _counts(db_url)
    assert after["RunResult"] == after["RawFile"] == len(run_ids)
    assert after["StableWindow"] == len(run_ids)
    with open_database(db_url)() as session:
        paths = session.scalars(select(RawFile.path)).all()
    assert len(set(paths)) == len(paths) == len(run_ids)


@pytest.mark.skipif(sys.platform != "linux", reason="the workers' end rests on Linux's prctl")
def test_workers_end_with_a_killed_batch(tmp_path):
    """SIGKILL a ``--jobs 2`` batch once its workers run: both workers are gone within 10 s
    (before, they waited on their task queue for ever)."""
    psutil = pytest.importorskip("psutil")
    run_ids = sorted(p.stem for p in (SAMPLE / "campaign").glob("L300_*.mcap"))
    campaign = _small_campaign(tmp_path, run_ids)
    command = [sys.executable, "-m", "swtlab_cli.main", "process", str(campaign), "--db",
               f"sqlite:///{tmp_path / 'swtlab.sqlite'}", "--jobs", "2", "--quiet"]
    process = subprocess.Popen(command, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    batch = psutil.Process(process.pid)
    deadline = time.monotonic() + 120
    workers = []
    while time.monotonic() < deadline and process.poll() is None and len(workers) < 2:
        time.sleep(0.05)
        workers = batch.children()
    assert len(workers) == 2, "the batch ended before its two workers ran"
    time.sleep(1.0)  # past the workers' start (their initializer)
    process.send_signal(signal.SIGKILL)
    process.wait(timeout=60)

    def running(worker) -> bool:
        try:
            return worker.status() != psutil.STATUS_ZOMBIE
        except psutil.NoSuchProcess:
            return False

    deadline = time.monotonic() + 10
    while time.monotonic() < deadline and any(running(w) for w in workers):
        time.sleep(0.1)
    left = [w.pid for w in workers if running(w)]
    for pid in left:
        os.kill(pid, signal.SIGKILL)
    assert not left, f"workers {left} outlived their killed batch"


def test_campaign_rig_compliance_is_applied_and_stored(tmp_path):
    """A campaign's [rig_compliance] lifts the hub by m_per_n * (fz - ref): sinkage drops by it."""
    run_id = "L300_MP0_SC_s+020"
    plain = _small_campaign(tmp_path / "plain", [run_id])
    compliant = _small_campaign(tmp_path / "compliant", [run_id])
    (compliant / "swtlab.toml").write_text(
        '[rig_compliance]\nkind = "linear"\nm_per_n = 1.0e-5\nreference_load_n = 0.0\n'
        'source = "frame deflection test 2026-11"\n')
    results = {}
    for name, campaign in (("plain", plain), ("compliant", compliant)):
        url = f"sqlite:///{tmp_path / name}.sqlite"
        assert main(["process", str(campaign), "--db", url, "--quiet"]) == 0
        with open_database(url)() as session:
            result = session.scalars(select(RunResult)).one()
            results[name] = ({q.quantity: q.mean for q in result.quantities},
                             result.corrections)
    (plain_q, _), (comp_q, comp_c) = results["plain"], results["compliant"]
    assert comp_c["rig_compliance"]["m_per_n"] == 1.0e-5
    assert comp_c["rig_compliance"]["source"] == "frame deflection test 2026-11"
    expected_shift_m = 1.0e-5 * comp_q["wheel_load_n"]  # about 3 mm at 300 N
    assert plain_q["sinkage_m"] - comp_q["sinkage_m"] == pytest.approx(expected_shift_m, rel=0.02)
    assert comp_c["hub_height_correction_mean_m"] == pytest.approx(expected_shift_m, rel=0.01)
    truth_zero = ingest.read_run(compliant / f"{run_id}.mcap").metadata.zero
    assert comp_c["tare"]["zero_offsets_subtracted"] == pytest.approx(truth_zero)
