"""``swtlab.process_into`` and ``swtlab process`` store the rows of ``swtlab.process_campaign``
then ``swtlab.store``, drift pooled over the same runs (issue 39, item 2), on five runs of the
committed sample campaign."""

from __future__ import annotations

import shutil
from pathlib import Path

import pandas as pd
import pytest

import swtlab
from swtlab_cli.main import main

CAMPAIGN = Path(__file__).resolve().parents[1] / "sample_data" / "campaign"
#: a towed run, driven runs at two loads, one without a stable phase (no side-camera frames)
RUNS = ["L180_MP0_TW", "L180_MP0_SC_s+020", "L180_MP0_SC_s+090", "L070_MP0_SC_s+010",
        "L070_MP0_SC_s+060"]
#: columns that number rows, not results
IDS = ["result_id"]


def _copy(folder: Path, runs: list[str]) -> Path:
    folder.mkdir(parents=True, exist_ok=True)
    for run in runs:
        source = CAMPAIGN / f"{run}.mcap"
        if source.exists():
            shutil.copy(source, folder / source.name)
        else:
            shutil.copytree(CAMPAIGN / run, folder / run)
    return folder


def _rows(db_url: str) -> pd.DataFrame:
    table = swtlab.load(db_url).results.drop(columns=IDS)
    return table.sort_values("run_id").reset_index(drop=True)


@pytest.fixture(scope="module")
def folder(tmp_path_factory) -> Path:
    return _copy(tmp_path_factory.mktemp("into") / "campaign", RUNS)


@pytest.fixture(scope="module")
def cli_rows(folder, tmp_path_factory) -> pd.DataFrame:
    url = f"sqlite:///{tmp_path_factory.mktemp('cli') / 'swtlab.sqlite'}"
    assert main(["process", str(folder), "--db", url, "--jobs", "1", "--quiet"]) == 0
    return _rows(url)


def test_the_api_and_swtlab_process_store_the_same_rows(folder, cli_rows, tmp_path):
    url = f"sqlite:///{tmp_path / 'api.sqlite'}"
    campaign = swtlab.process_campaign(folder)
    assert swtlab.store(campaign, url) == len(RUNS)
    api = _rows(url)
    assert sorted(api["run_id"]) == sorted(RUNS)
    assert (api["status"] == "no_stable_phase").sum() == 1
    pd.testing.assert_frame_equal(api, cli_rows)


def test_a_campaign_stored_in_two_calls_gets_the_rows_of_one(folder, cli_rows, tmp_path):
    # the drift diffusion is pooled over every run of the campaign under the folder: the
    # runs stored by the first call are pooled again when the second adds runs
    url = f"sqlite:///{tmp_path / 'two.sqlite'}"
    part = _copy(tmp_path / "campaign", RUNS[:3])
    first = swtlab.process_into(url, part)
    assert len(first.stored) == 3 and not first.failures
    alone = _rows(url)
    drift = [c for c in alone if c.endswith("_u_zero_drift")]
    then = cli_rows[cli_rows["run_id"].isin(RUNS[:3])].reset_index(drop=True)
    assert not alone[drift].equals(then[drift])  # pooled over three runs: other budgets
    _copy(part, RUNS[3:])
    second = swtlab.process_into(url, part)
    assert (len(second.stored), second.up_to_date) == (2, 3)
    both = _rows(url)
    both["raw_file_path"] = both["raw_file_path"].str.replace(str(part), str(folder))
    pd.testing.assert_frame_equal(both, cli_rows)
    third = swtlab.process_into(url, part)
    assert (len(third.stored), third.up_to_date) == (0, 5)
    assert _rows(url).drop(columns="raw_file_path").equals(both.drop(columns="raw_file_path"))

