"""A small processed campaign for the report tests (shared by test_report*.py), and a check
that it holds what those tests rely on: ok, flagged and no-stable-phase runs, three loads."""

from __future__ import annotations

import shutil
from pathlib import Path

from sqlalchemy import select

from swtlab_cli.main import main as swtlab_main
from traceability import open_database
from traceability.models import RawFile, Run, RunResult
from traceability.queries import latest_results

SAMPLE = Path(__file__).resolve().parents[1] / "sample_data" / "campaign"
#: fitted loads 70 and 180 N, the 180 N 90 % run digs in (no stable phase), 120 N kept aside
SMALL_RUNS = ([f"L070_MP0_SC_s{s}.mcap" for s in ("-010", "+000", "+005", "+010", "+020",
                                                  "+035", "+060")]
              + [f"L180_MP0_SC_s{s}.mcap" for s in ("-010", "+000", "+005", "+010", "+020",
                                                    "+035", "+060", "+090")]
              + [f"L120_MP0_SC_s{s}.mcap" for s in ("-005", "+003", "+015", "+045")]
              + ["L070_MP0_FS"])
FLAGGED_RUN = "L070_MP0_SC_s+005"
FLAG = "grouser passing frequency 0.31 Hz differs from n*omega/2pi (test flag)"
NO_STABLE_RUN = "L180_MP0_SC_s+090"


def build_small_campaign(folder: Path, runs=SMALL_RUNS, export: bool = True) -> str:
    """Copy ``runs`` of the sample campaign, process them into a SQLite database, mark
    :data:`FLAGGED_RUN` flagged (the sample has no flagged run), export the WPM CSV when
    ``export``; the database URL."""
    campaign = folder / "campaign"
    campaign.mkdir(parents=True)
    for name in runs:
        source = SAMPLE / name
        if source.is_dir():
            shutil.copytree(source, campaign / name)
        else:
            shutil.copy2(source, campaign / name)
    url = f"sqlite:///{folder / 'swtlab.sqlite'}"
    assert swtlab_main(["process", str(campaign), "--db", url, "--quiet"]) == 0
    with open_database(url).begin() as session:
        result = session.scalars(select(RunResult).join(RawFile).join(Run)
                                 .where(Run.run_id == FLAGGED_RUN)).one()
        result.status, result.flags = "flagged", [FLAG]
    if export:
        assert swtlab_main(["export", "--db", url, "-o", str(folder / "wpm.csv")]) == 0
    return url


def test_small_campaign_has_every_status(tmp_path):
    url = build_small_campaign(tmp_path, runs=["L070_MP0_SC_s+005.mcap", "L180_MP0_SC_s+090.mcap",
                                               "L070_MP0_FS"], export=False)
    with open_database(url)() as session:
        table = latest_results(session)
    status = dict(zip(table["run_id"], table["status"]))
    assert status == {FLAGGED_RUN: "flagged", NO_STABLE_RUN: "no_stable_phase",
                      "L070_MP0_FS": "ok"}
