"""`swtlab gap` end to end on a tiny processed virtual campaign; `swtlab gap-bench` blind and
scored through its labels file."""

from __future__ import annotations

import json

from sqlalchemy import select

import terramechanics as tm
import virtual_testbed as vt
from validation.gap_bench import FAST_DESIGN, base_model, conditions, run_bench, score
from swtlab_cli.main import main
from traceability import open_database
from traceability.models import GapReport

REQUIRED = {"verdict", "candidates", "held_out_rmse_before", "held_out_rmse_after",
            "shrink_pct", "regions", "reason", "separating_test", "untestable_effects"}


def test_gap_cli_on_a_processed_campaign(tmp_path, capsys):
    truth = base_model().with_effects(slip_sinkage={"n1": 0.7})
    vt.generate_campaign(tmp_path / "out", conditions(FAST_DESIGN)[:12], seed=3,
                         duration_s=FAST_DESIGN.duration_s,
                         testbed=vt.Testbed(law=tm.ModelLaw(truth)))
    db = f"sqlite:///{tmp_path / 'swt.sqlite'}"
    assert main(["process", str(tmp_path / "out" / "campaign"), "--db", db, "--quiet"]) == 0
    tm.save_model(base_model(), tmp_path / "sim.toml")
    code = main(["gap", "--measured", db, "--sim", str(tmp_path / "sim.toml"), "--json",
                 str(tmp_path / "gap.json"), "--html", str(tmp_path / "gap.html"), "--boot", "20"])
    assert code == 0
    report = json.loads((tmp_path / "gap.json").read_text())
    assert REQUIRED <= set(report)
    assert report["n_points"] == 12 and report["contrasts"]["multipass"] == 2
    assert report["verdict"] == ["slip_sinkage"]
    best = report["candidates"][0]
    assert {"label", "held_out_score", "parameters", "aicc"} <= set(best)
    assert report["shrink_pct"]["sinkage_m"] > 50.0
    assert all({"slip_band", "quantity", "z", "significant"} <= set(r) for r in report["regions"])
    html = (tmp_path / "gap.html").read_text()
    assert "data:image/png;base64," in html and "slip_sinkage" in html
    assert "verdict: slip_sinkage" in capsys.readouterr().out
    # recorded in the measured database, and shown by the campaign report
    with open_database(db)() as session:
        (row,) = session.scalars(select(GapReport)).all()
        assert row.verdict == ["slip_sinkage"] and row.report["shrink_pct"] == report["shrink_pct"]
        assert row.processing.stage == "gap"
    page = tmp_path / "report.html"
    assert main(["report", "--db", db, "-o", str(page), "--quiet"]) == 0
    section = page.read_text().split('<section id="gap">', 1)[1].split("</section>", 1)[0]
    assert "Sim-to-real gap" in section and "slip_sinkage" in section
    assert section.count("data:image/png;base64,") >= 1


def test_gap_cli_bad_input(tmp_path, capsys):
    assert main(["gap", "--measured", str(tmp_path / "none.csv"), "--sim", "x.toml"]) == 3
    assert main(["gap", "--measured", "a", "--sim", "b", "--effects", "wings"]) == 2


def test_gap_bench_is_blind_and_scored_from_labels(tmp_path):
    result = run_bench(3, seed=4, workdir=tmp_path, design=FAST_DESIGN, jobs=2, boot=10)
    labels = json.loads((tmp_path / "labels" / "labels.json").read_text())
    assert sorted(labels) == ["c000", "c001", "c002"]
    for name in labels:  # the diagnosis saw no truth: it lives outside the campaign folder
        assert not (tmp_path / name / "truth").exists()
        assert (tmp_path / "labels" / name / "truth").is_dir()
        assert (tmp_path / name / "gap.json").is_file()
    assert result["n"] == 3 and sum(v["n"] for v in result["by_class"].values()) == 3
    assert result == {**score(tmp_path / "labels" / "labels.json", tmp_path),
                      "timing_s": result["timing_s"]}
    rows = {r["campaign"]: r for r in result["campaigns"]}
    assert [rows[n]["hidden"] for n in sorted(rows)] == [labels[n]["effects"]
                                                         for n in sorted(labels)]
