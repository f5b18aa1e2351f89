"""The gap bench on the second rig's signal model (``make_campaigns(signal_model="second")``):
gap_bench's hidden truths and layout, the diagnosis blind to them, scoring end to end."""

from __future__ import annotations

import itertools
import json

import numpy as np

from validation.gap_bench import (MARS_GRAVITY_MPS2, Design, base_model, diagnosis_laws,
                                  draw_truth, laws_option, run_bench, score)
from virtual_testbed.rig import BB2_WHEEL

#: 8 runs: every contrast the bench needs (load, slip, multipass, gravity) once
TINY = Design(loads_n=(80.0, 250.0), slips=(0.2, 0.6), multipass=(0, 1),
              gravity_mps2=(MARS_GRAVITY_MPS2,), duration_s=50.0)
SEED = 5


def test_second_rig_bench_is_blind_and_scored(tmp_path):
    # held out: one law per effect left to the diagnosis, which keeps the fit count small
    result = run_bench(1, SEED, tmp_path, TINY, jobs=1, boot=5, truth_laws="held-out",
                       signal_model="second")
    labels = json.loads((tmp_path / "labels" / "labels.json").read_text())
    # the hidden truths are gap_bench's own draws for this seed, labelled with the rig
    _, expected = draw_truth(np.random.default_rng(SEED), 0)
    assert labels == {"c000": {**json.loads(json.dumps(expected)), "truth_laws": "held-out",
                               "signal_model": "second"}}
    # blind: the diagnosis' folder holds the raw runs, the laws it may use, its database and
    # its report only
    seen = {p.relative_to(tmp_path / "c000").as_posix()
            for p in (tmp_path / "c000").rglob("*") if p.is_file()}
    assert seen == ({f"campaign/r{i:03d}.mcap" for i in range(8)}
                    | {"laws-held-out.txt", "swtlab.sqlite", "gap-held-out.json"})
    assert (tmp_path / "c000" / "laws-held-out.txt").read_text().strip() == laws_option(
        diagnosis_laws(0, "held-out"))
    truth_files = sorted((tmp_path / "labels" / "c000" / "truth").glob("*.json"))
    assert [p.stem for p in truth_files] == [f"r{i:03d}" for i in range(8)]
    # the runs are the design's conditions on the testbed's wheel, their steady values the
    # labelled model's curves (each effect under its labelled law)
    label = labels["c000"]
    model = base_model().with_soil(**label["soil"]).with_effects(
        **{e: {"law": label["laws"][e], **label["parameters"][e]} for e in label["effects"]})
    cells = set()
    for p in truth_files:
        doc = json.loads(p.read_text())
        c = doc["condition"]
        assert {k: c["wheel"][k] for k in ("name", "radius_m", "stiffness_n_per_mm")} == {
            "name": BB2_WHEEL.name, "radius_m": BB2_WHEEL.radius_m,
            "stiffness_n_per_mm": BB2_WHEEL.stiffness_n_per_mm}
        cells.add((c["load_n"], c["slip_setpoint"], c["multipass"], c["gravity_mps2"]))
        curves = model.curves(c["load_n"], c["slip_setpoint"], c["multipass"], c["gravity_mps2"])
        assert np.isclose(doc["steady"]["dp_n"], float(curves["dp_n"]), rtol=1e-9)
        assert np.isclose(doc["steady"]["sinkage_m"], float(curves["sinkage_m"]), rtol=1e-9)
    assert cells == set(itertools.product(TINY.loads_n, TINY.slips, TINY.multipass,
                                          TINY.gravity_mps2))
    # every run went through `swtlab process` into the diagnosis
    report = json.loads((tmp_path / "c000" / "gap-held-out.json").read_text())
    assert report["n_points"] == 8
    # scoring: gap_bench's score of the labels against the written report
    assert result == {**score(tmp_path / "labels" / "labels.json", tmp_path, "held-out"),
                      "truth_laws": "held-out", "timing_s": result["timing_s"]}
    row = result["campaigns"][0]
    assert row["hidden"] == label["effects"]
    called = None if report["verdict"] == "inconclusive" else report["verdict"]
    assert row["exact"] == (called is not None and sorted(called) == sorted(label["effects"]))
