"""The gap bench's smooth-wheel design (``Design.smooth_wheel``): every condition run again by
a smooth wheel of the same size on the same hidden soil, both wheels diagnosed together as
two measured sources (what separates the soil's slip-sinkage from the lugs')."""

from __future__ import annotations

import json
from dataclasses import replace

import numpy as np
import pytest

from validation.gap_bench import MARS_GRAVITY_MPS2, Design, base_model, run_bench, smooth_wheel
from virtual_testbed.rig import BB2_WHEEL

TINY = Design(loads_n=(80.0, 250.0), slips=(0.2, 0.6), multipass=(0, 1),
              gravity_mps2=(MARS_GRAVITY_MPS2,), duration_s=50.0, smooth_wheel=True)
SEED = 5


@pytest.mark.slow  # 16 runs processed and diagnosed as two sources
@pytest.mark.slow_campaign
@pytest.mark.slow_diagnosis
def test_smooth_wheel_runs_on_the_same_hidden_soil_and_is_diagnosed_with_the_lugged(tmp_path):
    run_bench(1, SEED, tmp_path, TINY, jobs=1, boot=5, truth_laws="held-out")
    label = json.loads((tmp_path / "labels" / "labels.json").read_text())["c000"]
    model = base_model().with_soil(**label["soil"]).with_effects(
        **{e: {"law": label["laws"][e], **label["parameters"][e]} for e in label["effects"]})
    # the diagnosis sees two raw folders and their databases, not the truths
    seen = {p.relative_to(tmp_path / "c000").as_posix()
            for p in (tmp_path / "c000").rglob("*") if p.is_file()}
    runs = {f"r{i:03d}.mcap" for i in range(8)}
    assert seen == ({f"campaign/{r}" for r in runs} | {f"smooth/campaign/{r}" for r in runs}
                    | {"laws-held-out.txt", "swtlab.sqlite", "smooth.sqlite",
                       "gap-held-out.json"})
    # each smooth run's steady values: the hidden model's curves without the grousers
    for path in sorted((tmp_path / "labels" / "c000" / "smooth" / "truth").glob("*.json")):
        doc = json.loads(path.read_text())
        c = doc["condition"]
        assert doc["law"]["wheel.grouser_count"] == 0
        expected = model.with_wheel(grouser_count=0, grouser_height_m=0.0).curves(
            c["load_n"], c["slip_setpoint"], c["multipass"], c["gravity_mps2"])
        assert np.isclose(doc["law_steady"]["dp_n"], float(expected["dp_n"]), rtol=1e-9)
    report = json.loads((tmp_path / "c000" / "gap-held-out.json").read_text())
    assert report["n_points"] == 16
    wheels = {s["wheel"]["name"]: s["wheel"]["grouser_count"] for s in report["sources"]}
    assert wheels == {BB2_WHEEL.name: BB2_WHEEL.grouser_count, smooth_wheel().name: 0}
    assert replace(smooth_wheel(), name=BB2_WHEEL.name, grouser_count=BB2_WHEEL.grouser_count,
                   grouser_height_m=BB2_WHEEL.grouser_height_m) == BB2_WHEEL
