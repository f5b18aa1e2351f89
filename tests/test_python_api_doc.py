"""docs/python-api.md runs as written: every ```python block, in order, in one namespace, in a
scratch folder holding the checkout's sample data and models (so its files land there). The
numbers it prints are then checked against the virtual testbed's truth."""

from __future__ import annotations

import contextlib
import io
import json
import os
import re
from pathlib import Path

import matplotlib
import pytest

pytestmark = pytest.mark.slow  # the page's whole pipeline: process, fit, export, gap, report

ROOT = Path(__file__).resolve().parents[1]
PAGE = ROOT / "docs" / "python-api.md"


def python_blocks(text: str) -> list[str]:
    return re.findall(r"^```python\n(.*?)^```$", text, flags=re.S | re.M)


@pytest.fixture(scope="module")
def walked(tmp_path_factory):
    """The page's namespace and printed output after running every block."""
    matplotlib.use("Agg")
    work = tmp_path_factory.mktemp("python_api")
    (work / "terramechanics").mkdir()
    (work / "sample_data").symlink_to(ROOT / "sample_data")
    (work / "terramechanics" / "models").symlink_to(ROOT / "terramechanics" / "models")
    blocks = python_blocks(PAGE.read_text())
    namespace: dict = {}
    out = io.StringIO()
    here = Path.cwd()
    os.chdir(work)
    try:
        for number, block in enumerate(blocks, start=1):
            with contextlib.redirect_stdout(out):
                exec(compile(block, f"{PAGE.name} block {number}", "exec"), namespace)
    finally:
        os.chdir(here)
        import matplotlib.pyplot as plt

        plt.close("all")
    return namespace, out.getvalue(), work, len(blocks)


def test_every_block_runs_and_writes_its_files(walked):
    namespace, out, work, n_blocks = walked
    assert n_blocks == PAGE.read_text().count("```python") == 9
    for name in ("dp_vs_slip.png", "wpm.csv", "gap.json", "gap.html", "swtlab.sqlite",
                 "report.html"):
        assert (work / name).stat().st_size > 0, name
    assert "16 runs: {'ok': 15, 'no_stable_phase': 1}" in out
    assert "verdict: []" in out
    assert "radius_m 0.125 vs 0.1 (tolerance 2 %)" in out   # the other wheel is refused


def test_the_printed_numbers_match_the_truth(walked):
    namespace = walked[0]
    truth = json.loads((ROOT / "sample_data" / "truth" / "L180_MP0_SC_s+020.json").read_text())
    row = namespace["results"].set_index("run_id").loc["L180_MP0_SC_s+020"]
    assert row["dp_n_mean"] == pytest.approx(truth["stable_means"]["dp_n"], abs=0.01 * 180)
    dp = namespace["curves"].get("dp_n", 180.0)
    assert dp.evaluate(0.2) == pytest.approx(truth["law_steady"]["dp_n"], abs=0.02 * 180)
    wheel = namespace["wpm"].wheel()
    assert (wheel.radius_m, wheel.grouser_count) == (truth["law"]["wheel.radius_m"],
                                                     truth["law"]["wheel.grouser_count"])
    # at 120 N, between the tested loads: the testbed's law (the bb2_sand model, the truth's
    # "law") gives 25 N of DP at the slip found, and the DP found at 20 % slip
    import terramechanics as tm
    from scipy.optimize import brentq

    law = tm.shipped_model("bb2_sand")
    slip = brentq(lambda s: float(law.curves(120.0, s)["dp_n"]) - 25.0, 0.0, 0.6)
    assert float(namespace["answer"].slip) == pytest.approx(slip, abs=0.01)
    assert float(namespace["at_20"]["dp_n"]) == pytest.approx(
        float(law.curves(120.0, 0.2)["dp_n"]), abs=0.01 * 120)
