"""`swtlab gap` end to end on a tiny processed virtual campaign; the gap bench's scoring of a
failed campaign and its option checks (the bench end to end: tests/test_gap_bench.py)."""

from __future__ import annotations

import json

import numpy as np
import pytest
from sqlalchemy import select

import terramechanics as tm
import virtual_testbed as vt
from swtlab_cli.cmd_gap import parse_laws
from validation.gap_bench import (FAST_DESIGN, ModeFiles, base_model, conditions,
                                   diagnose_campaign, diagnosis_laws, format_score,
                                   laws_option, make_campaigns, score)
from swtlab_cli.main import main
from traceability import open_database
from traceability.models import GapReport

pytestmark = [pytest.mark.slow,  # a virtual campaign generated, processed and diagnosed by the
              # command
              pytest.mark.slow_campaign, pytest.mark.slow_diagnosis]

REQUIRED = {"verdict", "probability", "hypotheses", "effect_sets", "held_out_rmse_before",
            "held_out_rmse_after", "shrink_pct", "regions", "reason", "separating_test",
            "next_tests", "admissible_tests",
            "untestable_effects"}


def test_gap_cli_on_a_processed_campaign(tmp_path, capsys):
    """Multipass missing on the lugged BB2 wheel, in family (the truth is the model's own
    multipass law); the runs in a random order, so that a soil drifting through the
    campaign cannot pass for the second pass. Multipass is found (probability >= 0.9 that it
    is part of the explanation, and it alone leads); twelve runs cannot rule out weak lugs
    beside it (docs/gap-report.md), so the verdict is multipass or inconclusive."""
    truth = base_model().with_effects(multipass={"stiffness_gain_per_pass": 0.6})
    runs = conditions(FAST_DESIGN)[:12]
    runs = [runs[i] for i in np.random.default_rng(3).permutation(len(runs))]
    vt.generate_campaign(tmp_path / "out", runs, seed=3,
                         duration_s=FAST_DESIGN.duration_s,
                         testbed=vt.Testbed(law=tm.ModelLaw(truth)))
    db = f"sqlite:///{tmp_path / 'swt.sqlite'}"
    assert main(["process", str(tmp_path / "out" / "campaign"), "--db", db, "--quiet"]) == 0
    tm.save_model(base_model(), tmp_path / "sim.toml")
    default_laws = ",".join(f"{e}={law}" for e, law in tm.DEFAULT_LAWS.items())
    code = main(["gap", "--measured", db, "--sim", str(tmp_path / "sim.toml"), "--json",
                 str(tmp_path / "gap.json"), "--html", str(tmp_path / "gap.html"), "--boot", "20",
                 "--laws", default_laws])
    assert code == 0
    report = json.loads((tmp_path / "gap.json").read_text())
    assert REQUIRED <= set(report)
    assert report["n_points"] == 12 and report["contrasts"]["multipass"] == 2
    assert report["effect_sets"][0]["label"] == "multipass"
    assert report["effect_probabilities"]["multipass"] >= report["call_probability"] == 0.9
    assert report["verdict"] in (["multipass"], "inconclusive")
    best = report["hypotheses"][0]
    assert {"key", "probability", "log_evidence", "parameters"} <= set(best)
    assert best["effects"] == ["multipass"]
    verdict_line = ("Verdict: the simulation lacks multipass" if report["verdict"] != "inconclusive"
                    else "Verdict: inconclusive")
    assert report["shrink_pct"]["sinkage_m"] > 50.0
    assert all({"slip_band", "quantity", "z", "significant"} <= set(r) for r in report["regions"])
    html = (tmp_path / "gap.html").read_text()
    assert "data:image/png;base64," in html and verdict_line in html
    assert "verdict: " + ("multipass" if report["verdict"] != "inconclusive" else
                          "inconclusive") in capsys.readouterr().out
    # recorded in the measured database, and shown by the campaign report
    with open_database(db)() as session:
        (row,) = session.scalars(select(GapReport)).all()
        assert row.verdict == report["verdict"]
        assert row.report["shrink_pct"] == report["shrink_pct"]
        assert row.processing.stage == "gap"
    page = tmp_path / "report.html"
    assert main(["report", "--db", db, "-o", str(page), "--quiet"]) == 0
    section = page.read_text().split('<section id="gap">', 1)[1].split("</section>", 1)[0]
    assert "Sim-to-real gap" in section and verdict_line in section
    assert section.count("data:image/png;base64,") >= 1


def test_gap_cli_bad_input(tmp_path, capsys):
    assert main(["gap", "--measured", str(tmp_path / "none.csv"), "--sim", "x.toml"]) == 3
    assert main(["gap", "--measured", "a", "--sim", "b", "--effects", "wings"]) == 2
    assert main(["gap", "--measured", "a", "--sim", "b", "--laws", "grousers=x"]) == 2
    assert "unknown law 'x' of effect 'grousers'" in capsys.readouterr().err
    assert parse_laws("grousers=ding2011,grousers=bekker1956,slip_sinkage=lyasko2010") == {
        "grousers": ("ding2011", "bekker1956"), "slip_sinkage": ("lyasko2010",)}


def test_a_campaign_whose_chain_fails_is_scored_as_failed_and_the_bench_goes_on(tmp_path):
    """c001's database is missing (as when every run of a source was flagged, seed 30 c013):
    its `swtlab gap` exits with a one-line error, which the bench keeps, removing the
    mode's earlier report (the other mode's stays), and scores; c000 is scored from its
    report as before."""
    tm.save_model(base_model(), tmp_path / "sim.toml")
    labels = {"c000": {"effects": [], "laws": {}}, "c001": {"effects": ["grousers"],
                                                           "laws": {"grousers": "bekker1956"}}}
    (tmp_path / "labels").mkdir()
    (tmp_path / "labels" / "labels.json").write_text(json.dumps(labels))
    files = {name: ModeFiles.of(tmp_path / name, "in-family") for name in labels}
    for name in labels:
        (tmp_path / name).mkdir()
        files[name].laws.write_text("\n")
    files["c000"].gap.write_text(json.dumps({"verdict": [], "decision": {}, "shrink_pct": {}}))
    files["c001"].gap.write_text("{}")  # this mode's earlier report
    other = ModeFiles.of(tmp_path / "c001", "held-out").gap
    other.write_text("{}")  # the other mode's report
    diagnose_campaign(tmp_path, "c001", boot=0, process=False)
    assert not files["c001"].gap.exists() and other.read_text() == "{}"
    failure = files["c001"].failure.read_text()
    assert failure.startswith("gap --measured: ") and "swtlab.sqlite" in failure
    assert len(failure.strip().splitlines()) == 1
    s = score(tmp_path / "labels" / "labels.json", tmp_path)
    assert s["by_class"]["none"]["exact"] == 1
    assert s["by_class"]["single"] == {"n": 1, "exact": 0, "exact_share": 0.0,
                                       "inconclusive": 0, "failed": 1, "confident_wrong": 0}
    assert s["failed"] == [f"c001: {failure.strip()}"]
    assert s["confusion"]["grousers"] == {"failed": 1}
    assert "failed (scored as not exact): c001: gap --measured" in format_score(s)


def test_gap_bench_modes_are_checked(tmp_path):
    with pytest.raises(ValueError, match="signal_model must be one of"):
        make_campaigns(1, 0, tmp_path, FAST_DESIGN, 1, signal_model="third")
    with pytest.raises(ValueError, match="truth_laws must be one of"):
        diagnosis_laws(0, "mixed")
    assert laws_option(None) == ""
    assert laws_option({"grousers": ("bekker1956",), "slip_sinkage": ("ding2011", "x")}) == (
        "grousers=bekker1956,slip_sinkage=ding2011,slip_sinkage=x")


def test_gap_bench_command_finds_the_bench_in_the_checkout(capsys):
    """The bench's generators are not installed with swtlab: the command imports them from
    the repository it runs from (and checks its options after that)."""
    assert main(["gap-bench", "--n", "0"]) == 2
    assert "swtlab gap-bench: --n must be >= 1" in capsys.readouterr().out
