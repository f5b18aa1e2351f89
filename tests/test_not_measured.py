"""Every budget says what it could not measure: the ``not_measured`` column of ``swtlab
results`` (summary, ``--json``) and of ``run_results.results_table``, and the report's note
beside u( ).

Second-rig runs (validation/second_rig) written without the spec's calibration-uncertainty
keys and, for one run, without its rest readings at the end (the rig's rest phase cut from the
timeline): what is missing is known by construction, so the column is checked against it.
Two runs share a condition (replicates), one stands alone.
"""

from __future__ import annotations

import json

import pandas as pd
import pytest

import swtlab
from campaign_report.data import from_results
from campaign_report.sections import not_measured_note
from run_results import results_table
from swtlab_base.domain.replicates import SINGLE_RUN
from swtlab_cli.main import main
from validation.second_rig import Rig, RunCondition, Timeline, write_campaign

CALIBRATION = "calibration (no gain_rel_u / offset_u in swt.calibration)"


def _truth(condition):
    return {"slip": condition.slip_setpoint, "travel_velocity_mps": condition.velocity_mps,
            "wheel_load_n": condition.load_n, "dp_n": 0.3 * condition.load_n,
            "torque_nm": 4.0, "sinkage_m": 0.006}


@pytest.fixture(scope="module")
def campaign(tmp_path_factory):
    out = tmp_path_factory.mktemp("nm")
    pair = [RunCondition(f"rep{i}", "speed_control", 150.0, 0.2) for i in (1, 2)]
    write_campaign(out, pair + [RunCondition("alone", "speed_control", 200.0, 0.4)], _truth,
                   seed=3, form="csv")
    # no rest after the drive: the run ends 0.2 s after the wheel stops
    no_rest = Rig(timeline=Timeline(duration_s=48.7, rest_after_s=0.2))
    write_campaign(out, [RunCondition("norest", "speed_control", 250.0, 0.3)], _truth, seed=3,
                   form="csv", rig=no_rest)
    return out / "campaign"


def test_the_column_lists_what_each_run_could_not_measure(campaign):
    results = swtlab.process_campaign(campaign, soil_flow=False).results.set_index("run_id")
    for run_id in ("rep1", "rep2", "alone", "norest"):
        assert CALIBRATION in results.loc[run_id, "not_measured"]
    assert SINGLE_RUN in results.loc["alone", "not_measured"]
    assert SINGLE_RUN in results.loc["norest", "not_measured"]
    assert SINGLE_RUN not in results.loc["rep1", "not_measured"]
    assert "no rest readings" in results.loc["norest", "not_measured"]
    assert "no rest readings" not in results.loc["rep1", "not_measured"]


def test_results_cli_and_the_report_show_it(campaign, tmp_path, capsys):
    db = f"sqlite:///{tmp_path / 'lab.sqlite'}"
    assert main(["process", str(campaign), "--db", db, "--quiet"]) == 0
    capsys.readouterr()
    assert main(["results", "--db", db, "--json"]) == 0
    table = pd.DataFrame(json.loads(capsys.readouterr().out)).set_index("run_id")
    assert SINGLE_RUN in table.loc["alone", "not_measured"]
    assert "no rest readings" in table.loc["norest", "not_measured"]
    assert main(["results", "--db", db]) == 0
    summary = capsys.readouterr().out
    header = summary.splitlines()[0]
    assert header.rstrip().endswith("not_measured")
    alone = next(line for line in summary.splitlines() if line.lstrip().startswith("alone"))
    assert "run-to-run repeatability" in alone and "calibration" in alone
    assert "(no gain_rel_u" not in alone   # the summary gives the items' heads only


def test_the_report_note_counts_the_runs(campaign):
    results = [p.result for p in swtlab.process_campaign(campaign, soil_flow=False).runs]
    data = from_results("nm", results)
    note = not_measured_note(data)
    assert "calibration (4 of 4 runs)" in note
    assert "run-to-run repeatability (2 of 4 runs)" in note
    assert "zero drift (1 of 4 runs)" in note
    assert list(results_table(results)["not_measured"]) == list(data.results["not_measured"])
