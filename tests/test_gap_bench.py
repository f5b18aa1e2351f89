"""The blind gap bench (``validation.gap_bench.run_bench``, ``swtlab gap-bench``) end to end,
on the second rig's signal model (written apart from the virtual testbed): campaigns with
hidden truths, the diagnosis blind to them, scored through the labels file; and the first
campaign made, processed and diagnosed again on a two-worker ``dask.distributed.LocalCluster``,
giving the local run's files. The virtual testbed's bench with the smooth wheel:
tests/test_gap_bench_smooth_wheel.py.

A bench run processes and diagnoses whole campaigns, so the local run is one module fixture
that every test here reads."""

from __future__ import annotations

import itertools
import json

import numpy as np
import pytest

import terramechanics as tm
from validation.gap_bench import (MARS_GRAVITY_MPS2, Design, base_model, diagnosis_laws,
                                  draw_truth, laws_option, run_bench, score, truth_law)
from virtual_testbed.rig import BB2_WHEEL

pytestmark = [pytest.mark.slow,  # three whole campaigns generated, processed, diagnosed
              pytest.mark.slow_campaign, pytest.mark.slow_diagnosis]

#: 8 runs: every contrast the bench needs (load, slip, multipass, gravity) once
TINY = Design(loads_n=(80.0, 250.0), slips=(0.2, 0.6), multipass=(0, 1),
              gravity_mps2=(MARS_GRAVITY_MPS2,), duration_s=50.0)
SEED = 5
#: two campaigns: each published law of every family is the truth's (held out) once
#: (``truth_law`` takes campaign i's law as the i-th of its family, modulo its size)
N = 2


@pytest.fixture(scope="module")
def bench(tmp_path_factory):
    """Two campaigns of the second rig's signal model, held out: (work folder, score)."""
    work = tmp_path_factory.mktemp("bench")
    result = run_bench(N, SEED, work, TINY, jobs=2, boot=5, truth_laws="held-out",
                       signal_model="second")
    return work, result


def _seen(folder) -> set[str]:
    """What the diagnosis of a campaign had: every file under its folder."""
    return {p.relative_to(folder).as_posix() for p in folder.rglob("*") if p.is_file()}


def test_gap_bench_is_blind_and_scored_from_labels(bench):
    """Held-out truth laws: each family without the truth's law (and its extensions)."""
    work, result = bench
    labels = json.loads((work / "labels" / "labels.json").read_text())
    assert sorted(labels) == [f"c{i:03d}" for i in range(N)]
    for effect in tm.PUBLISHED_LAWS:  # both published laws of each family were held out
        assert {truth_law(i, effect) for i in range(N)} == set(
            tm.PUBLISHED_LAWS[effect])
    for i, name in enumerate(sorted(labels)):  # the diagnosis saw no truth: it lives outside
        assert not (work / name / "truth").exists()
        assert (work / "labels" / name / "truth").is_dir()
        report = json.loads((work / name / "gap-held-out.json").read_text())
        allowed = report["settings"]["laws"]  # every family lost the truth's law
        assert sorted(allowed) == sorted(tm.LAWS)
        for effect, options in allowed.items():
            assert sorted(options + [law for law in tm.LAWS[effect]
                                    if tm.published_law(effect, law) == truth_law(i, effect)]
                          ) == sorted(tm.LAWS[effect])
        for effect, law in labels[name]["laws"].items():
            assert law == truth_law(i, effect) and law not in allowed[effect]
            assert labels[name]["truth_laws"] == "held-out"
    assert result["n"] == N
    assert sum(v["n"] for v in result["by_class"].values()) == N
    assert result == {**score(work / "labels" / "labels.json", work, "held-out"),
                      "truth_laws": "held-out", "timing_s": result["timing_s"]}
    rows = {r["campaign"]: r for r in result["campaigns"]}
    assert [rows[n]["hidden"] for n in sorted(rows)] == [labels[n]["effects"]
                                                         for n in sorted(labels)]


def test_second_rig_bench_is_blind_and_scored(bench):
    work, result = bench
    labels = json.loads((work / "labels" / "labels.json").read_text())
    # the hidden truths are gap_bench's own draws for this seed, labelled with the rig
    rng = np.random.default_rng(SEED)
    expected = [draw_truth(rng, i)[1] for i in range(N)]
    assert labels == {f"c{i:03d}": {**json.loads(json.dumps(label)), "truth_laws": "held-out",
                                    "signal_model": "second"}
                      for i, label in enumerate(expected)}
    # blind: the diagnosis' folder holds the raw runs, the laws it may use, its database and
    # its report only
    assert _seen(work / "c000") == ({f"campaign/r{i:03d}.mcap" for i in range(8)}
                                    | {"laws-held-out.txt", "swtlab.sqlite",
                                       "gap-held-out.json"})
    assert (work / "c000" / "laws-held-out.txt").read_text().strip() == laws_option(
        diagnosis_laws(0, "held-out"))
    truth_files = sorted((work / "labels" / "c000" / "truth").glob("*.json"))
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
    report = json.loads((work / "c000" / "gap-held-out.json").read_text())
    assert report["n_points"] == 8
    # scoring: gap_bench's score of the labels against the written report
    assert result == {**score(work / "labels" / "labels.json", work, "held-out"),
                      "truth_laws": "held-out", "timing_s": result["timing_s"]}
    row = result["campaigns"][0]
    assert row["hidden"] == label["effects"]
    called = None if report["verdict"] == "inconclusive" else report["verdict"]
    assert row["exact"] == (called is not None and sorted(called) == sorted(label["effects"]))


def _files(folder) -> dict:
    """Every file under ``folder`` (relative path: bytes, ``folder`` itself named WORK), the
    databases and the scores (they hold when each was made) left out."""
    return {str(p.relative_to(folder)): p.read_bytes().replace(str(folder).encode(), b"WORK")
            for p in sorted(folder.rglob("*"))
            if p.is_file() and p.suffix != ".sqlite" and not p.name.startswith("score-")}


@pytest.mark.slow_workers  # a two-worker LocalCluster started
def test_a_gap_bench_campaign_on_the_cluster_is_the_local_one(bench, tmp_path):
    """The bench's first campaign (8 runs; held-out laws: one law per family, the fastest
    diagnosis) made, processed and diagnosed again in a task on the cluster: every file (raw
    runs, truth, label, laws, the gap report) and its score are the local run's."""
    distributed = pytest.importorskip("distributed")
    here_dir, here = bench
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                                  dashboard_address=None) as cluster:
        with distributed.Client(cluster) as client:
            there = run_bench(1, SEED, tmp_path / "there", TINY, boot=5,
                              truth_laws="held-out", signal_model="second", client=client)
    labels = "labels/labels.json"
    files = {k: v for k, v in _files(here_dir).items()
             if k != labels and not k.startswith(("c001", "labels/c001"))}
    assert len([f for f in files if f.endswith(".mcap")]) == 8
    assert b"sqlite:///WORK/c000/swtlab.sqlite" in files["c000/gap-held-out.json"]
    got = _files(tmp_path / "there")
    assert json.loads(got.pop(labels)) == {"c000": json.loads(_files(here_dir)[labels])["c000"]}
    assert got == files
    assert there["timing_s"]["jobs"] == 2 and there["n"] == 1
    assert there["campaigns"] == here["campaigns"][:1]
