"""Campaigns: runs at any depth; a batch never stops on one bad run."""

from __future__ import annotations

import ingest


def test_campaign_collects_runs_and_failures(tmp_path, ingest_tools, ingest_spec):
    root = tmp_path / "campaign"
    (root / "day1" / "deep").mkdir(parents=True)
    good = ingest_tools.write_mcap(root / "day1" / "a.mcap", ingest_spec)
    folder = ingest_tools.write_csv_run(root / "day1" / "deep" / "b", ingest_spec.topics,
                                        ingest_spec.records)
    bad = root / "c.mcap"
    bad.write_bytes(good.read_bytes()[:1000])
    ingest_spec.records = ingest_tools.records(run={"mode": "sideways"})
    wrong_mode = ingest_tools.write_mcap(root / "day1" / "d.mcap", ingest_spec)
    (root / "notes.txt").write_text("not a run")

    assert ingest.find_runs(root) == sorted([good, folder, bad, wrong_mode])
    result = ingest.read_campaign(root)
    assert sorted(r.source for r in result.runs) == sorted([good, folder])
    assert sorted(e.path for e in result.failures) == sorted([bad, wrong_mode])
    by_path = {e.path: e for e in result.failures}
    assert "truncated" in by_path[bad].problem
    assert by_path[wrong_mode].channel == "swt.run.mode"


def test_find_runs_with_a_delimited_map(ingest_cmu_root):
    runs = ingest.find_runs(ingest_cmu_root, "cmu_3d_terramechanics")
    assert len(runs) == 27 and all(p.suffix == ".txt" for p in runs)
