"""The gap bench on the second rig's signal model: gap_bench's hidden truths and layout, the
diagnosis blind to them, scoring end to end."""

from __future__ import annotations

import itertools
import json

import numpy as np

from validation.gap_bench import MARS_GRAVITY_MPS2, Design, base_model, draw_truth, score
from validation.gap_bench_second import run_bench_second

#: 8 runs: every contrast the bench needs (load, slip, multipass, gravity) once
TINY = Design(loads_n=(80.0, 250.0), slips=(0.2, 0.6), multipass=(0, 1),
              gravity_mps2=(MARS_GRAVITY_MPS2,), duration_s=50.0)
SEED = 5


def test_second_rig_bench_is_blind_and_scored(tmp_path):
    result = run_bench_second(1, SEED, tmp_path, TINY, jobs=1, boot=5)
    labels = json.loads((tmp_path / "labels" / "labels.json").read_text())
    # the hidden truths are gap_bench's own draws for this seed
    _, expected = draw_truth(np.random.default_rng(SEED))
    assert labels == {"c000": json.loads(json.dumps(expected))}
    # blind: the diagnosis' folder holds the raw runs, its database and its report only
    seen = {p.relative_to(tmp_path / "c000").as_posix()
            for p in (tmp_path / "c000").rglob("*") if p.is_file()}
    assert seen == {f"campaign/r{i:03d}.mcap" for i in range(8)} | {"swtlab.sqlite", "gap.json"}
    truth_files = sorted((tmp_path / "labels" / "c000" / "truth").glob("*.json"))
    assert [p.stem for p in truth_files] == [f"r{i:03d}" for i in range(8)]
    # the runs are the design's conditions, their steady values the labelled model's curves
    label = labels["c000"]
    model = base_model().with_soil(**label["soil"]).with_effects(**label["parameters"])
    cells = set()
    for p in truth_files:
        doc = json.loads(p.read_text())
        c = doc["condition"]
        cells.add((c["load_n"], c["slip_setpoint"], c["multipass"], c["gravity_mps2"]))
        curves = model.curves(c["load_n"], c["slip_setpoint"], c["multipass"], c["gravity_mps2"])
        assert np.isclose(doc["steady"]["dp_n"], float(curves["dp_n"]), rtol=1e-9)
        assert np.isclose(doc["steady"]["sinkage_m"], float(curves["sinkage_m"]), rtol=1e-9)
    assert cells == set(itertools.product(TINY.loads_n, TINY.slips, TINY.multipass,
                                          TINY.gravity_mps2))
    # every run went through `swtlab process` into the diagnosis
    report = json.loads((tmp_path / "c000" / "gap.json").read_text())
    assert report["n_points"] == 8
    # scoring: gap_bench's score of the labels against the written report
    assert result == {**score(tmp_path / "labels" / "labels.json", tmp_path),
                      "timing_s": result["timing_s"], "signal_model": "second_rig"}
    row = result["campaigns"][0]
    assert row["hidden"] == label["effects"]
    called = None if report["verdict"] == "inconclusive" else report["verdict"]
    assert row["exact"] == (called is not None and sorted(called) == sorted(label["effects"]))
