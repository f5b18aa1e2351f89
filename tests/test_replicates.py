"""Replicate runs (swtlab_base.domain.replicates): recognised by their test condition, their
spread set beside the within-run uncertainty, the larger used by the fits."""

from __future__ import annotations

import contextlib
import io
import json

import numpy as np
import pandas as pd
import pytest

import swtlab
from fitting import from_run_results
from swtlab_base.domain.replicates import NO_REPLICATES, fit_sigma, replicate_spread
from swtlab_cli.main import main as swtlab_main
from virtual_testbed import RunCondition, generate_campaign
from virtual_testbed.sample_campaign import SAMPLE_RATES


def _table(dp, u, slips):
    n = len(dp)
    return pd.DataFrame({"run_id": [f"r{i}" for i in range(n)], "wheel": "w", "soil": "s",
                         "mode": "speed_control", "multipass": 0, "load_set_n": 180.0,
                         "slip_setpoint": slips, "velocity_set_mps": 0.01,
                         "gravity_mps2": 9.81, "steer_deg": np.nan, "status": "ok",
                         "dp_n_mean": dp, "dp_n_u": u, "dp_n_se": [x / 2 for x in u]})


def test_spread_by_hand():
    # three runs at slip 0.2 reading 10, 11, 12 N (sd 1 N) with u 0.5 N; one run at 0.4
    table = _table([10.0, 11.0, 12.0, 30.0], [0.5, 0.5, 0.5, 0.7], [0.2, 0.2, 0.2, 0.4])
    spread = replicate_spread(table, quantities=("dp_n",))
    assert len(spread) == 1
    row = spread.iloc[0]
    assert (row["runs"], row["run_ids"]) == (3, ["r0", "r1", "r2"])
    assert row["mean"] == pytest.approx(11.0) and row["replicate_sd"] == pytest.approx(1.0)
    assert row["within_u"] == pytest.approx(0.5) and row["ratio"] == pytest.approx(2.0)
    assert row["larger"] == "replicates"
    # the fits: the replicate sd for the three, its own u for the lone run
    assert list(fit_sigma(table, "dp_n")) == pytest.approx([1.0, 1.0, 1.0, 0.7])
    fitted = from_run_results(table)
    assert list(fitted["dp_n_se"]) == pytest.approx([1.0, 1.0, 1.0, 0.7])


def test_a_campaign_without_replicates_says_so():
    table = _table([10.0, 30.0], [0.5, 0.7], [0.2, 0.4])
    assert replicate_spread(table).empty
    assert list(fit_sigma(table, "dp_n")) == pytest.approx([0.5, 0.7])   # own u
    assert "not measured" in NO_REPLICATES


@pytest.fixture(scope="module")
def replicated(tmp_path_factory):
    """Six replicates each of two conditions on the virtual testbed (CSV, short runs)."""
    out = tmp_path_factory.mktemp("replicates")
    conds = [RunCondition.of(f"a{i}", "speed_control", 180.0, 0, 0.3) for i in range(6)]
    conds += [RunCondition.of(f"b{i}", "speed_control", 120.0, 1, 0.1) for i in range(6)]
    conds += [RunCondition.of("c0", "towed", 250.0, 0)]
    generate_campaign(out, conds, seed=61, rates=SAMPLE_RATES, form="csv")
    return out / "campaign"


@pytest.fixture(scope="module")
def processed(replicated):
    """The replicated campaign processed once (the two tests below read it, neither changes it)."""
    return swtlab.process_campaign(replicated, soil_flow=False)


def test_replicates_recognised_and_consistent_with_the_budget(replicated, processed, tmp_path):
    campaign = processed
    spread = campaign.replicates
    assert set(map(tuple, spread["run_ids"])) == {tuple(f"a{i}" for i in range(6)),
                                                  tuple(f"b{i}" for i in range(6))}
    print(spread[["load_set_n", "quantity", "replicate_sd", "within_u", "ratio"]].round(4))
    # in-family: runs differ only by their noise, drift, clocks; the sd of 6 replicates over
    # the budget's u lies in 0.35-1.6 at 95 % (chi-square, 5 dof) if u is right
    ratios = spread.set_index(["load_set_n", "quantity"])["ratio"]
    assert 0.35 < ratios.median() < 1.6
    assert campaign.repeatability.startswith("2 condition(s) with replicate runs")
    url = f"sqlite:///{tmp_path / 'db.sqlite'}"
    with contextlib.redirect_stdout(io.StringIO()):
        assert swtlab_main(["process", str(replicated), "--db", url, "--quiet"]) == 0
    with contextlib.redirect_stdout(io.StringIO()) as listing:
        assert swtlab_main(["results", "--db", url, "--replicates", "--json"]) == 0
    rows = json.loads(listing.getvalue())
    assert {r["quantity"] for r in rows} >= {"dp_n", "torque_nm", "sinkage_m", "slip"}
    assert all(r["runs"] == 6 for r in rows)
    # swtlab process pooled the drift over the runs it stored, as process_campaign does
    with contextlib.redirect_stdout(io.StringIO()) as listing:
        assert swtlab_main(["results", "--db", url, "--json"]) == 0
    stored = pd.DataFrame(json.loads(listing.getvalue())).set_index("run_id")
    api = campaign.results.set_index("run_id")
    for q in ("dp_n", "wheel_load_n", "resistance_n"):
        assert stored[f"{q}_u"].to_numpy() == pytest.approx(api.loc[stored.index, f"{q}_u"]
                                                            .to_numpy(), rel=1e-9)
        assert (stored[f"{q}_dof"].dropna() > 5).all()   # pooled: many degrees of freedom


def test_the_report_shows_the_replicate_spread_or_says_there_is_none(processed):
    from campaign_report.data import from_results
    from campaign_report.replicates import replicates_section

    campaign = processed
    results = [r.result for r in campaign.runs]
    section = replicates_section(from_results("virtual", results), None)
    table = section.blocks[1]
    assert len(table.rows) == len(campaign.replicates)
    assert {row[5] for row in table.rows} == {"6"}           # six runs per condition
    alone = replicates_section(from_results("virtual", results[:1] + results[-1:]), None)
    assert "no replicate runs" in alone.blocks[0].text and alone.blocks[0].warning
