"""Follow-up runs on an apart campaign (testbeds.apart.followup): the proposed conditions
(plain JSON, as a gap report lists them) become runs of the same campaign, its truth
unchanged, new run ids, the smooth wheel where the proposal has no grousers; the written
follow-up holds the campaign's runs and the new ones, and its truth document says which test
was added. In-family: the steady values are checked against the campaign's own truth."""

from __future__ import annotations

import json

import numpy as np
import pytest

from testbeds.apart.campaign import draw_campaign, write_campaign_folder
from testbeds.apart.followup import (by_kind, followup_rows, followup_start_times, main,
                                     resolved, kind_of, write_followup)

G0 = 9.80665


def _lugged_campaign():
    """The first campaign of seed 1 whose wheel has grousers."""
    for index in range(40):
        drawn = draw_campaign(1, index)
        if drawn["plan"].wheel.grouser_count:
            return index, drawn
    raise AssertionError("no lugged campaign in 40")


def test_followup_runs_are_the_same_campaigns_at_the_proposed_conditions():
    index, drawn = _lugged_campaign()
    load = float(drawn["plan"].loads_n[0])
    conditions = [{"source": "x", "load_set_n": load, "slip": 0.33, "multipass": 0,
                   "gravity_mps2": G0},
                  {"source": "smooth wheel", "load_set_n": load, "slip": 0.33, "multipass": 0,
                   "gravity_mps2": G0, "grouser_count": 0, "grouser_height_m": 0.0}]
    rows, failed = followup_rows(drawn, conditions, "top")
    assert failed == 0 and [r["source"] for r in rows] == ["main", "smooth"]
    old_ids = {run.run_id for _, run in drawn["plan"].runs}
    ids = [r["run"].run_id for r in rows]
    assert len(set(ids)) == 2 and not set(ids) & old_ids
    main, smooth = rows
    assert main["run"].wheel == drawn["plan"].wheel
    assert smooth["run"].wheel.grouser_count == 0
    assert smooth["run"].wheel.radius_m == drawn["plan"].wheel.radius_m
    for r in rows:
        assert r["run"].load_n == load and r["run"].slip == pytest.approx(0.33, abs=0.015)
        assert r["steady"]["dp_n"] == pytest.approx(
            drawn["truth"].steady(r["run"], r["scatter"])["dp_n"], rel=1e-12)
    # same campaign, same arm: the same runs
    again, _ = followup_rows(drawn, conditions, "top")
    assert [r["steady"]["dp_n"] for r in again] == [r["steady"]["dp_n"] for r in rows]



def test_followup_runs_start_after_the_campaigns_last_run_one_after_the_other():
    """A lab's log: the follow-up comes after the campaign (whose soil its truth holds, the
    campaign's end), not in a block months away that a drift in time could take."""
    from datetime import datetime

    from testbeds.apart.campaign import RESET_MIN, lab_rig, start_times

    index, drawn = _lugged_campaign()
    load = float(drawn["plan"].loads_n[0])
    conditions = [{"source": "x", "load_set_n": load, "slip": s, "multipass": 0,
                   "gravity_mps2": G0} for s in (0.2, 0.5)]
    rows, _ = followup_rows(drawn, conditions, "top")
    run_s = lab_rig(drawn["seed"], drawn["index"], drawn["plan"]).timeline.duration_s
    campaign = [datetime.fromisoformat(t) for t in
                start_times(drawn["seed"], drawn["index"], drawn["plan"], run_s).values()]
    started = [datetime.fromisoformat(t) for t in followup_start_times(drawn, rows).values()]
    gap_s = run_s + 60.0 * RESET_MIN  # a run and the reset between runs
    assert (started[0] - max(campaign)).total_seconds() == pytest.approx(gap_s)
    assert (started[1] - started[0]).total_seconds() == pytest.approx(gap_s)


def test_written_followup_holds_the_campaign_and_the_new_runs(tmp_path):
    index, drawn = _lugged_campaign()
    src = tmp_path / "bench"
    truth = write_campaign_folder(src, 1, index)
    name = drawn["name"]
    load = float(drawn["plan"].loads_n[-1])
    test = {"test": "two runs", "conditions": [
        {"load_set_n": load, "slip": s, "multipass": 0, "gravity_mps2": G0} for s in (0.6, 0.8)]}
    out = tmp_path / "followups"
    doc = write_followup(src / name, out, truth, "top", test)
    folder = out / f"{name}_top"
    before = sorted(p.name for p in (src / name / "campaign").iterdir())
    after = sorted(p.name for p in (folder / "campaign").iterdir())
    assert set(before) < set(after) and len(after) == len(before) + 2
    assert doc["followup"] == {"of": name, "arm": "top", "test": "two runs", "runs": 2,
                               "runs_without_equilibrium": 0}
    assert len(doc["runs"]) == len(truth["runs"]) + 2
    assert doc["effects"] == truth["effects"] and doc["soil"] == truth["soil"]
    assert json.loads((out / "truth" / f"{name}_top.json").read_text()) == json.loads(
        json.dumps(doc))
    assert not (folder / "truth").exists() and not (folder / "gap.json").exists()


@pytest.mark.parametrize("truth, row, expected", [
    ({"effects": ["grousers"], "outside": []}, {"verdict": ["grousers"], "outcome": "right"}, True),
    ({"effects": ["grousers"], "outside": []}, {"verdict": "inconclusive",
                                                "outcome": "inconclusive"}, False),
    ({"effects": [], "outside": ["soil_drift"]}, {"verdict": "inconclusive",
                                                  "outcome": "right"}, False),
    ({"effects": [], "outside": ["soil_drift"]}, {"verdict": "outside_candidates",
                                                  "outcome": "right"}, True),
    ({"effects": [], "outside": []}, {"verdict": [], "outcome": "right"}, True),
])
def test_resolved_means_a_right_call(truth, row, expected):
    assert resolved(row, truth) is expected


@pytest.mark.parametrize("slips, expected", [
    ((-0.4, -0.2, -0.1), "braked slips"), ((0.03, 0.08, 0.15), "low slips"),
    ((0.6, 0.75, 0.9), "high slips"), ((-0.1, 0.6), "low slips")])
def test_a_slip_test_is_named_by_its_band(slips, expected):
    test = {"kind": "slips", "conditions": [{"slip": s} for s in slips]}
    assert kind_of(test) == expected
    assert kind_of({"kind": "smooth wheel", "conditions": []}) == "smooth wheel"


def _result(p_before, top, random):
    arm = {"top": top, "random": random}
    return {"p_true": p_before, **{k: {"kind": v[0], "gain_bits": v[1], "p_true": v[2],
                                       "resolved": v[2] >= 0.9} for k, v in arm.items()}}


def test_by_kind_pools_both_arms_and_counts_what_the_truth_did(tmp_path, capsys):
    results = [_result(0.5, ("high slips", 1.0, 0.25), ("gravity", 0.2, 0.95)),
               _result(0.4, ("high slips", 0.6, 0.4), ("high slips", 0.8, 0.8))]
    table = {k["kind"]: k for k in by_kind(results)}
    high = table["high slips"]
    assert high["n"] == 3 and high["gain_bits"] == pytest.approx(0.8)
    assert high["median_log_change"] == pytest.approx(0.0)  # ln(0.5), 0, ln(2): median 0
    assert (high["rises"], high["resolved"]) == (1, 0)
    assert table["gravity"]["median_log_change"] == pytest.approx(np.log(0.95 / 0.5))
    assert (table["gravity"]["rises"], table["gravity"]["resolved"]) == (1, 1)
    kept = tmp_path / "fu.json"
    kept.write_text(json.dumps({"campaigns": results}))
    assert main(["--summarise", str(kept)]) == 0
    printed = capsys.readouterr().out
    assert "| top | 0 / 2 | 0 / 2 |" in printed and "| random | 1 / 2 | 2 / 2 |" in printed
    assert "| high slips | 3 | 0.80 | +0.00 | 1 | 0 |" in printed
