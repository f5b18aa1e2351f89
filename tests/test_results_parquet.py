"""``swtlab results --parquet``: a campaign processed from HDF5 and MATLAB files (the formats
reach ``swtlab process``), its results table back from Parquet with every dtype."""

from __future__ import annotations

import shutil
from pathlib import Path

import pandas as pd

import swtlab
from swtlab_cli.main import main
from bench import format_files as fw

SAMPLE = Path(__file__).resolve().parents[1] / "sample_data" / "campaign"
RUNS = ("L070_MP0_SC_s+010", "L180_MP0_SC_s+020", "L300_MP1_SC_s+060")


def test_results_parquet_round_trips_with_dtypes(tmp_path):
    campaign = tmp_path / "campaign"
    campaign.mkdir()
    shutil.copy(SAMPLE / f"{RUNS[0]}.mcap", campaign)
    fw.write_hdf5(fw.read_spec_mcap(SAMPLE / f"{RUNS[1]}.mcap"), campaign / f"{RUNS[1]}.h5")
    fw.write_mat5(fw.read_spec_mcap(SAMPLE / f"{RUNS[2]}.mcap"), campaign / f"{RUNS[2]}.mat")
    url = f"sqlite:///{tmp_path / 'db.sqlite'}"
    assert main(["process", str(campaign), "--db", url, "--quiet"]) == 0
    out = tmp_path / "results.parquet"
    assert main(["results", "--db", url, "--parquet", str(out)]) == 0
    back = pd.read_parquet(out)
    results = swtlab.load(url).results
    assert sorted(back["run_id"]) == sorted(RUNS) and len(back) == 3
    assert (back["status"] != "failed").all()
    pd.testing.assert_frame_equal(back, results.reset_index(drop=True), check_exact=True)
    assert dict(back.dtypes) == dict(results.dtypes)
    # the Campaign's own DataFrame through Parquet
    results.to_parquet(tmp_path / "campaign.parquet")
    pd.testing.assert_frame_equal(pd.read_parquet(tmp_path / "campaign.parquet"), results)
