"""The blind gap-bench: campaigns from the model with a hidden effect set, diagnosed through
the full chain by separate processes that never see the labels, then scored.

Layout of the work folder::

    sim.toml                      the simulation given to every diagnosis (base model)
    c000/campaign/...             raw runs of campaign 0 (all a diagnosis can read)
    c000/laws-held-out.txt        the laws the diagnosis may use (``swtlab gap --laws``),
                                  one file per mode (``in-family``, ``held-out``)
    c000/swtlab.sqlite            `swtlab process` output
    c000/smooth/campaign/...      with ``Design.smooth_wheel``: the same conditions run by a
    c000/smooth.sqlite            smooth wheel of the same size on the same soil
    c000/gap-held-out.json        `swtlab gap` report of that mode (a failed step:
    c000/failure-held-out.txt     its one-line error instead); diagnosing under the other
                                  mode writes its own files and keeps these
    labels/labels.json            hidden effect sets, laws and strengths (only the scorer)
    labels/c000/truth/...         the signal model's per-run truth, moved out of the campaign

Each campaign: loads x slips x multipass {0, 1} x gravity {g0, Mars}, so that every effect
has the contrast it needs (docs/gap-report.md, "Identifiability").

Laws of the truth (``truth_laws``): campaign i makes each of its effects with law
``i mod n`` of the effect's family (``terramechanics.LAWS``, sorted by name), the same in
both modes, so the two modes see the same raw data. ``in-family``: the diagnosis may use
every law. ``held-out``: that law is removed, for every family (not only the truth's
effects, which would give them away), and the diagnosis gets the remaining laws.

Signal models (``signal_model``): ``testbed`` (``virtual_testbed``) or ``second``
(``validation.second_rig``, written apart from the testbed: other transients, noise,
drift; the testbed's BB2 wheel with its stiffness, the design's run length), through
``validation.gap_bench_second.write_second_campaign``.
"""

from __future__ import annotations

import json
import shutil
import subprocess
import sys
import time
from concurrent.futures import ProcessPoolExecutor, ThreadPoolExecutor
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np

import terramechanics as tm
from sim_gap.vocabulary import EFFECT_NAMES
from swtlab_base.atomic import write_atomically
from swtlab_base.domain.gravity import G0_MPS2, MARS_GRAVITY_MPS2

TRUTH_LAWS = ("in-family", "held-out")
SIGNAL_MODELS = ("testbed", "second")


@dataclass(frozen=True)
class ModeFiles:
    """A campaign's files of one diagnosis mode (``truth_laws``): the laws it may use, its
    report, and, where the processing or the diagnosis failed, the step and its one-line
    error. Each mode has its own, so diagnosing again under the other loses nothing."""

    laws: Path
    gap: Path
    failure: Path

    @classmethod
    def of(cls, folder: Path, truth_laws: str) -> ModeFiles:
        return cls(folder / f"laws-{truth_laws}.txt", folder / f"gap-{truth_laws}.json",
                   folder / f"failure-{truth_laws}.txt")
#: hidden effect strengths, per law, drawn uniformly in these ranges; the ranges of the
#: second law of each family give about the same RMS standardised change over the bench
#: design as the first law's (0.8-2 sigma for multipass up to 5-14 for slip-sinkage), but
#: Rankine bulldozing, far weaker than Bekker's, stays near its formula (x 2-5: 1.3-3 sigma)
STRENGTHS = {
    "grousers": {"bekker1956": {"shear_radius_factor": (0.3, 1.0)},
                 "ding2011": {"shear_radius_factor": (0.3, 1.0),
                              "lug_sinkage_gain": (1.0, 4.0)}},
    "slip_sinkage": {"ding2011": {"n1": (0.3, 0.8)},
                     "lyasko2010": {"coefficient": (0.4, 1.0)}},
    "reduced_gravity": {"wong_kobayashi2012": {"bearing_exponent": (0.6, 1.5)},
                        "reece1965": {"bearing_exponent": (0.6, 1.5)}},
    "wheel_flexibility": {"wong2010": {"radial_stiffness_n_m": (15e3, 60e3),
                                       "hysteresis_coefficient": (0.015, 0.04)},
                          "bekker1969": {"ground_pressure_pa": (15e3, 35e3)}},
    "multipass": {"wong2010": {"stiffness_gain_per_pass": (0.15, 0.5)},
                  # K_e as a multiple of the truth's k_phi (SCM needs K_e > k_phi)
                  "krenn_hirzinger2009": {"elastic_stiffness_pa_m": (1.2, 1.7)}},
    "bulldozing": {"bekker1969": {"coefficient": (0.05, 0.5)},
                   "rankine_terzaghi1943": {"coefficient": (2.0, 5.0)}},
}
#: strengths drawn as a multiple of the truth soil's k_phi
KPHI_RELATIVE = {("multipass", "krenn_hirzinger2009"): "elastic_stiffness_pa_m"}


@dataclass(frozen=True)
class Design:
    """Conditions of every bench campaign; ``duration_s`` of each run."""

    loads_n: tuple[float, ...] = (80.0, 180.0, 300.0)
    slips: tuple[float, ...] = (0.1, 0.25, 0.4, 0.55, 0.7)
    multipass: tuple[int, ...] = (0, 1)
    gravity_mps2: tuple[float, ...] = (G0_MPS2, MARS_GRAVITY_MPS2)
    duration_s: float = 60.0
    #: also run every condition with :data:`SMOOTH_WHEEL` on the same soil, diagnosed as a
    #: second measured source: the design that tells the soil's slip-sinkage from the lugs'
    #: (their contrast, sim_gap.siblings; Ding et al. 2011 ran a smooth and a lugged wheel)
    smooth_wheel: bool = False


FAST_DESIGN = Design(loads_n=(80.0, 250.0), slips=(0.15, 0.4, 0.65), duration_s=50.0)


def smooth_wheel():
    """The testbed's BB2-like wheel without its grousers (same radius, width, stiffness)."""
    from virtual_testbed.rig import BB2_WHEEL

    return replace(BB2_WHEEL, name=f"{BB2_WHEEL.name} smooth", grouser_count=0,
                   grouser_height_m=0.0)


def base_model() -> tm.WheelModel:
    """The simulation every diagnosis gets: the shipped bb2_sand wheel and soil, no effects."""
    model = tm.shipped_model("bb2_sand")
    return model.with_effects(**{name: False for name in tm.EFFECTS})


def truth_law(campaign: int, effect: str) -> str:
    """The published law campaign ``campaign`` makes ``effect`` with (and, held out,
    removes with the laws that extend it)."""
    laws = sorted(tm.PUBLISHED_LAWS[effect])
    return laws[campaign % len(laws)]


def diagnosis_laws(campaign: int, truth_laws: str) -> dict[str, tuple[str, ...]] | None:
    """The laws the diagnosis of campaign ``campaign`` may use: all (``None``) in family;
    held out, every family without the law of :func:`truth_law` and the laws that extend it
    (its ``~load`` form holds it at a load exponent of 0)."""
    if truth_laws not in TRUTH_LAWS:
        raise ValueError(f"truth_laws must be one of {TRUTH_LAWS}, not {truth_laws!r}")
    if truth_laws == "in-family":
        return None
    return {e: tuple(law for law in sorted(tm.LAWS[e])
                     if tm.published_law(e, law) != truth_law(campaign, e))
            for e in EFFECT_NAMES}


def draw_truth(rng: np.random.Generator, campaign: int = 0) -> tuple[tm.WheelModel, dict]:
    """A hidden truth: soil perturbed (k_phi x lognormal 25 %, friction angle +-1.5 deg
    normal, K x lognormal 20 %) and none, one or two effects (a third each), each under its
    law of :func:`truth_law`, at random strengths. Returns the model and its label."""
    n_effects = int(rng.integers(0, 3))
    effects = sorted(rng.choice(EFFECT_NAMES, size=n_effects, replace=False).tolist(),
                     key=EFFECT_NAMES.index)
    soil = base_model().soil
    soil_values = {"kphi": soil.kphi * float(np.exp(rng.normal(0, 0.25))),
                   "friction_angle_deg": soil.friction_angle_deg + float(rng.normal(0, 1.5)),
                   "shear_modulus_m": soil.shear_modulus_m * float(np.exp(rng.normal(0, 0.2)))}
    laws = {e: truth_law(campaign, e) for e in effects}
    params = {}
    for e in effects:
        params[e] = {k: float(rng.uniform(*r)) for k, r in STRENGTHS[e][laws[e]].items()}
        scaled = KPHI_RELATIVE.get((e, laws[e]))
        if scaled:
            params[e][scaled] *= soil_values["kphi"]
    model = base_model().with_soil(**soil_values).with_effects(
        **{e: {"law": laws[e], **params[e]} for e in effects})
    return model, {"effects": effects, "laws": laws, "parameters": params, "soil": soil_values}


def conditions(design: Design, seed: int | None = None):
    """The design's runs; in a random order drawn from ``seed`` where given (the run order
    a lab should use, docs/gap-report.md: runs blocked by multipass or gravity level would
    let a soil that drifts through the campaign pass for the level's effect)."""
    from virtual_testbed import RunCondition

    out = []
    for g in design.gravity_mps2:
        for mp in design.multipass:
            for load in design.loads_n:
                for s in design.slips:
                    out.append(RunCondition.of(f"r{len(out):03d}", "speed_control", load, mp, s,
                                               gravity_mps2=g))
    if seed is not None:
        out = [out[i] for i in np.random.default_rng(seed).permutation(len(out))]
    return out


def _generate(job) -> None:
    """One campaign's raw runs; its truth folder is moved out of the campaign."""
    from virtual_testbed import Testbed, generate_campaign

    from virtual_testbed.rig import BB2_WHEEL

    workdir, name, truth, seed, design, signal_model = job
    wheels = [("", BB2_WHEEL, truth)]
    if design.smooth_wheel:
        smooth = smooth_wheel()
        wheels.append(("smooth", smooth, truth.with_wheel(grouser_count=0,
                                                          grouser_height_m=0.0)))
    for part, wheel, wheel_truth in wheels:
        out = workdir / name / part
        if signal_model == "second":
            from validation.gap_bench_second import write_second_campaign

            write_second_campaign(out, conditions(design, seed), wheel_truth, seed, name,
                                  design.duration_s, wheel)
        else:
            generate_campaign(out, conditions(design, seed), seed=seed,
                              duration_s=design.duration_s,
                              testbed=Testbed(law=tm.ModelLaw(wheel_truth), campaign=name,
                                              wheel=wheel))
        labels = workdir / "labels" / name / part
        labels.mkdir(parents=True, exist_ok=True)
        shutil.move(str(out / "truth"), str(labels / "truth"))


def laws_option(laws: dict[str, tuple[str, ...]] | None) -> str:
    """``swtlab gap --laws`` text of ``laws`` (empty: every law)."""
    return ",".join(f"{e}={law}" for e, options in (laws or {}).items() for law in options)


def make_campaigns(n: int, seed: int, workdir: Path, design: Design = Design(),
                   workers: int = 2, truth_laws: str = "in-family",
                   signal_model: str = "testbed", client=None) -> Path:
    """Write ``n`` campaigns (``workers`` at a time, or on the workers of the
    ``dask.distributed`` ``client``), the laws each diagnosis may use and the labels file;
    return the labels path."""
    if signal_model not in SIGNAL_MODELS:
        raise ValueError(f"signal_model must be one of {SIGNAL_MODELS}, not {signal_model!r}")
    workdir.mkdir(parents=True, exist_ok=True)
    tm.save_model(base_model(), workdir / "sim.toml")
    rng = np.random.default_rng(seed)
    truths = [draw_truth(rng, i) for i in range(n)]
    jobs = [(workdir, f"c{i:03d}", truth, seed * 1000 + i, design, signal_model)
            for i, (truth, _) in enumerate(truths)]
    if client is not None:
        from swtlab.pipeline.process import limit_threads
        from swtlab_base.cluster import map_in_order

        list(map_in_order(client, _generate, jobs, limit=limit_threads))
    else:
        with ProcessPoolExecutor(workers) as pool:
            list(pool.map(_generate, jobs))
    for i in range(n):
        write_atomically(ModeFiles.of(workdir / f"c{i:03d}", truth_laws).laws,
                         laws_option(diagnosis_laws(i, truth_laws)) + "\n")
    labels = {f"c{i:03d}": {**label, "truth_laws": truth_laws, "signal_model": signal_model}
              for i, (_, label) in enumerate(truths)}
    path = workdir / "labels" / "labels.json"
    write_atomically(path, json.dumps(labels, indent=1) + "\n")
    return path


def diagnose_campaign(workdir: Path, name: str, boot: int, process: bool = True,
                      jobs: int | None = None, truth_laws: str = "in-family") -> float:
    """``swtlab process`` (unless ``process`` is False: the database is there; ``--jobs
    jobs`` when given) then ``swtlab gap`` in separate processes that are given the raw
    campaign folder, the database, the simulation and the laws they may use only (the
    ``truth_laws`` mode's :class:`ModeFiles`). Returns the seconds taken. A step that
    fails does not stop the bench: its one-line error goes to the mode's failure file
    (and the mode's report of an earlier diagnosis is removed), and the campaign is
    scored as failed."""
    start = time.perf_counter()
    files = ModeFiles.of(workdir / name, truth_laws)
    files.failure.unlink(missing_ok=True)
    try:
        _process_and_diagnose(workdir, name, boot, process, jobs, files)
    except subprocess.CalledProcessError as e:
        files.gap.unlink(missing_ok=True)
        lines = (e.stderr or b"").decode(errors="replace").strip().splitlines()
        write_atomically(files.failure,
                         f"{' '.join(e.cmd[3:5])}: {lines[-1] if lines else 'no message'}\n")
    return time.perf_counter() - start


def _process_and_diagnose(workdir: Path, name: str, boot: int, process: bool,
                          jobs: int | None, files: ModeFiles) -> None:
    dbs = [(workdir / name / "campaign", f"sqlite:///{workdir / name / 'swtlab.sqlite'}")]
    if (workdir / name / "smooth" / "campaign").is_dir():
        dbs.append((workdir / name / "smooth" / "campaign",
                    f"sqlite:///{workdir / name / 'smooth.sqlite'}"))
    cli = [sys.executable, "-m", "swtlab_cli.main"]
    if process:
        for folder, db in dbs:
            subprocess.run(cli + ["process", str(folder), "--db", db, "--quiet"]
                           + (["--jobs", str(jobs)] if jobs else []), check=True,
                           capture_output=True)
    laws = files.laws.read_text().strip()
    measured = [arg for _, db in dbs for arg in ("--measured", db)]
    subprocess.run(cli + ["gap", *measured, "--sim", str(workdir / "sim.toml"),
                          "--json", str(files.gap), "--boot", str(boot)]
                   + (["--laws", laws] if laws else []), check=True, capture_output=True)


def _label(effects) -> str:
    if isinstance(effects, str):
        return effects
    return "+".join(effects) if effects else "none"


def score(labels_path: Path, workdir: Path, truth_laws: str = "in-family") -> dict:
    """Compare each campaign's verdict under the ``truth_laws`` mode with its hidden label
    (the only reader of labels)."""
    labels = json.loads(Path(labels_path).read_text())
    rows = []
    for name, label in sorted(labels.items()):
        hidden = label["effects"]
        files = ModeFiles.of(workdir / name, truth_laws)
        if files.failure.exists():
            rows.append({"campaign": name, "hidden": hidden, "hidden_laws": label["laws"],
                         "allowed_laws": files.laws.read_text().strip(),
                         "probability": None, "called": None, "failed":
                         files.failure.read_text().strip(), "class": ("none", "single", "pair")[
                             len(hidden)], "exact": False, "confident_wrong": False,
                         "mean_shrink_pct": None})
            continue
        report = json.loads(files.gap.read_text())
        verdict = report["verdict"]
        # "outside_candidates" is a call too: every hidden effect here is a candidate
        called = (None if verdict == "inconclusive" else verdict if isinstance(verdict, str)
                  else sorted(verdict, key=EFFECT_NAMES.index))
        shrink = report["shrink_pct"]
        rows.append({"campaign": name, "hidden": hidden, "hidden_laws": label["laws"],
                     "allowed_laws": files.laws.read_text().strip(),
                     "probability": report.get("probability"),
                     "called": called, "failed": None,
                     "class": ("none", "single", "pair")[len(hidden)],
                     "exact": called == hidden,
                     "confident_wrong": called is not None and called != hidden,
                     "mean_shrink_pct": float(np.mean(list(shrink.values()))) if shrink else None})
    out = {"n": len(rows), "by_class": {}, "per_effect": {}, "confusion": {}}
    for cls in ("none", "single", "pair"):
        sub = [r for r in rows if r["class"] == cls]
        out["by_class"][cls] = {"n": len(sub), "exact": sum(r["exact"] for r in sub),
                                "exact_share": (sum(r["exact"] for r in sub) / len(sub))
                                if sub else None,
                                "inconclusive": sum(r["called"] is None and not r["failed"]
                                                    for r in sub),
                                "failed": sum(bool(r["failed"]) for r in sub),
                                "confident_wrong": sum(r["confident_wrong"] for r in sub)}
    for e in EFFECT_NAMES:
        tp = sum(r["called"] is not None and e in r["called"] and e in r["hidden"] for r in rows)
        fp = sum(r["called"] is not None and e in r["called"] and e not in r["hidden"]
                 for r in rows)
        fn = sum(e in r["hidden"] and (r["called"] is None or e not in r["called"]) for r in rows)
        out["per_effect"][e] = {"tp": tp, "fp": fp, "fn": fn,
                                "precision": tp / (tp + fp) if tp + fp else None,
                                "recall": tp / (tp + fn) if tp + fn else None}
    for r in rows:
        called = ("failed" if r["failed"] else "inconclusive") if r["called"] is None \
            else _label(r["called"])
        row = out["confusion"].setdefault(_label(r["hidden"]), {})
        row[called] = row.get(called, 0) + 1
    effect_rows = [r for r in rows if r["called"] and r["mean_shrink_pct"] is not None]
    out.update({
        "exact_share": sum(r["exact"] for r in rows) / max(len(rows), 1),
        "inconclusive_share": sum(r["called"] is None and not r["failed"] for r in rows)
        / max(len(rows), 1),
        "failed": [f"{r['campaign']}: {r['failed']}" for r in rows if r["failed"]],
        "confident_wrong_share": sum(r["confident_wrong"] for r in rows) / max(len(rows), 1),
        "outside_called": sum(r["called"] == "outside_candidates" for r in rows),
        "mean_shrink_pct": float(np.mean([r["mean_shrink_pct"] for r in effect_rows]))
        if effect_rows else None,
        "campaigns": rows})
    return out


def format_score(s: dict) -> str:
    lines = [f"campaigns: {s['n']} (truth laws {s.get('truth_laws', 'in-family')})"]
    for cls, v in s["by_class"].items():
        share = "n/a" if v["exact_share"] is None else f"{100 * v['exact_share']:.0f} %"
        lines.append(f"  {cls:6s} n={v['n']:3d} exact {share:>6s}  inconclusive "
                     f"{v['inconclusive']}  confident-wrong {v['confident_wrong']}  "
                     f"failed {v['failed']}")
    lines.append(f"exact-set accuracy {100 * s['exact_share']:.0f} %, inconclusive "
                 f"{100 * s['inconclusive_share']:.0f} %, confident wrong "
                 f"{100 * s['confident_wrong_share']:.0f} %; called outside the candidates: "
                 f"{s['outside_called']}")
    lines += [f"failed (scored as not exact): {f}" for f in s["failed"]]
    shrink = s["mean_shrink_pct"]
    lines.append("mean shrink (confident effect calls): "
                 + ("n/a" if shrink is None else f"{shrink:.1f} %"))
    lines.append("per effect: precision / recall")
    for e, v in s["per_effect"].items():
        fmt = lambda x: "n/a" if x is None else f"{x:.2f}"  # noqa: E731
        lines.append(f"  {e:18s} {fmt(v['precision'])} / {fmt(v['recall'])}  "
                     f"(tp {v['tp']} fp {v['fp']} fn {v['fn']})")
    lines.append("confusion (hidden -> called: count):")
    for hidden, called in sorted(s["confusion"].items()):
        lines.append(f"  {hidden}: " + ", ".join(f"{k} {v}" for k, v in sorted(called.items())))
    return "\n".join(lines)


def run_bench(n: int, seed: int, workdir: Path, design: Design = Design(), jobs: int = 2,
              boot: int = 50, truth_laws: str = "in-family", signal_model: str = "testbed",
              client=None) -> dict:
    """Generate, diagnose (``jobs`` campaigns at a time, each in its own processes; or one
    task per campaign on the workers of the ``dask.distributed`` ``client``, which must see
    ``workdir`` at the same path), score."""
    t0 = time.perf_counter()
    labels = make_campaigns(n, seed, workdir, design, jobs, truth_laws, signal_model, client)
    t1 = time.perf_counter()
    return _diagnose_and_score(labels, workdir, n, jobs, boot, True, truth_laws, t1 - t0,
                               client)


def rediagnose(workdir: Path, truth_laws: str, jobs: int = 2, boot: int = 50,
               client=None) -> dict:
    """Diagnose the processed campaigns of ``workdir`` again under the other ``truth_laws``
    mode (same raw data, same truths: only the laws given to the diagnosis change), score;
    ``jobs``, ``client``: as in :func:`run_bench`."""
    labels = workdir / "labels" / "labels.json"
    n = len(json.loads(labels.read_text()))
    for i in range(n):
        write_atomically(ModeFiles.of(workdir / f"c{i:03d}", truth_laws).laws,
                         laws_option(diagnosis_laws(i, truth_laws)) + "\n")
    return _diagnose_and_score(labels, workdir, n, jobs, boot, False, truth_laws, 0.0, client)


def _diagnose_and_score(labels: Path, workdir: Path, n: int, jobs: int, boot: int,
                        process: bool, truth_laws: str, generate_s: float,
                        client=None) -> dict:
    t1 = time.perf_counter()
    names = [f"c{i:03d}" for i in range(n)]
    if client is not None:  # one task, one core per campaign: its runs in one process
        from swtlab.pipeline.process import limit_threads
        from swtlab_base.cluster import map_in_order, task_slots

        jobs = sum(task_slots(client).values())
        seconds = list(map_in_order(client, diagnose_campaign, [workdir] * n, names,
                                    [boot] * n, [process] * n, [1] * n, [truth_laws] * n,
                                    limit=limit_threads))
    else:
        with ThreadPoolExecutor(jobs) as pool:
            seconds = list(pool.map(lambda name: diagnose_campaign(
                workdir, name, boot, process, truth_laws=truth_laws), names))
    t2 = time.perf_counter()
    out = {**score(labels, workdir, truth_laws), "truth_laws": truth_laws}
    out["timing_s"] = {"generate": generate_s, "process_and_diagnose": t2 - t1,
                       "per_campaign_mean": float(np.mean(seconds)), "jobs": jobs}
    write_atomically(workdir / f"score-{truth_laws}.json", json.dumps(out, indent=1) + "\n")
    return out
