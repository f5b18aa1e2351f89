"""One campaign of the apart testbed: draw its truth and plan, write what a lab would have, and
keep the truth beside it.

Layout under ``out``::

    cNNN/campaign/<run_id>.mcap         raw runs of the test wheel (validation.second_rig)
    cNNN/smooth/campaign/<run_id>.mcap  a lugged wheel's smooth twin on the same bin (some)
    cNNN/sim.toml                       the lab's nominal simulation (docs/model-file.md):
                                        its wheel, a published soil, no effect
    truth/cNNN.json                     the hidden truth (effects, drawn shapes, soil, runs)
    truth/cNNN/rig/, truth/cNNN/rig-smooth/   the rig's per-run truth files

The truth: none, one or two of the six effects (a quarter, 45 %, 30 %), and in a quarter of
the campaigns one effect outside the six (soil drift, a rig artefact on one channel, a rate
effect) with none or one of the six. The soil: a published set (the lab's guess, written in
``sim.toml``) moved per campaign (moduli and cohesion lognormal 30 %, friction angle normal
2 deg, shear displacement to the peak lognormal 30 %, residual ratio 0.75-1) and scattered
per run (moduli lognormal 4-15 %, friction angle 0.3-1.2 deg, the sizes drawn per campaign:
the preparation repeatability of a lab). A campaign whose wheel would sink deeper than a
quarter of its radius at some condition (:data:`MAX_SINKAGE_RATIO`) is drawn again: a lab
chooses loads its wheel can carry on its soil.
"""

from __future__ import annotations

import json
import math
import os
import shutil
import tempfile
from datetime import UTC, datetime, timedelta
from pathlib import Path

import numpy as np

from testbeds.apart import effects as fx
from testbeds.apart.design import Plan, draw_plan
from testbeds.apart.soil import PUBLISHED, PublishedSoil, ReeceSoil, from_published
from testbeds.apart.solver import NoEquilibrium
from testbeds.apart.truth import RunSpec, Truth, WheelSpec
from validation.second_rig import (Rig, RunCondition, SensorModel, Timeline, WheelGeometry,
                                   write_campaign)

TRUTH_SCHEMA = "swtlab.testbeds.apart.truth/1"
#: short runs: 3 s rest, transients settled in 14 s, steady for STEADY_S, 1.5 s stop, 3 s rest
SETTLE_S = 14.0
STEADY_S = 14.5
#: a lugged wheel runs steady for this many grouser periods at least (at its slowest run):
#: the chain refuses a window under 2 periods and cuts its start (docs/stable-phase.md)
STEADY_GROUSER_PERIODS = 4
#: time between the starts of two consecutive runs beyond the run itself: the bin raked,
#: levelled and the wheel reset, min
RESET_MIN = 12.0
SIX_COUNT_PROBABILITY = (0.25, 0.45, 0.30)
OUTSIDE_PROBABILITY = 0.25
MAX_DRAWS = 50
MAX_SINKAGE_RATIO = 0.25


def draw_effects(rng: np.random.Generator) -> tuple[list[str], list[str]]:
    """``(six, outside)``: the effects of the six present (vocabulary order) and outside."""
    outside = []
    if rng.random() < OUTSIDE_PROBABILITY:
        outside = [str(rng.choice(fx.OUTSIDE))]
        count = int(rng.integers(0, 2))
    else:
        count = int(rng.choice(3, p=SIX_COUNT_PROBABILITY))
    chosen = set(rng.choice(fx.SIX, size=count, replace=False).tolist())
    return [e for e in fx.SIX if e in chosen], outside


def draw_soil(rng: np.random.Generator, published: PublishedSoil, width_m: float) -> ReeceSoil:
    """The campaign's true soil around the published set."""
    base = from_published(published, width_m)
    moduli = math.exp(rng.normal(0, 0.3))
    return base.with_(kc_prime=base.kc_prime * moduli, kphi_prime=base.kphi_prime * moduli,
                      cohesion_pa=base.cohesion_pa * math.exp(rng.normal(0, 0.3)),
                      friction_angle_deg=base.friction_angle_deg + rng.normal(0, 2.0),
                      shear_peak_m=base.shear_peak_m * math.exp(rng.normal(0, 0.3)),
                      residual_ratio=float(rng.uniform(0.75, 1.0)))


def draw_campaign(seed: int, index: int) -> dict:
    """Everything about campaign ``index`` of ``seed``, nothing written: ``truth`` (the
    :class:`Truth`), ``plan``, ``published`` (the lab's soil guess), per-run ``rows``."""
    name = f"c{index:03d}"
    rng = np.random.default_rng([int(seed), int(index)])
    six, outside = draw_effects(rng)
    present = set(six) | set(outside)
    for attempt in range(1, MAX_DRAWS + 1):
        plan = draw_plan(rng, name, present)
        published = PUBLISHED[int(rng.integers(len(PUBLISHED)))]
        soil = draw_soil(rng, published, plan.wheel.width_m)
        truth = Truth(soil, {e: fx.draw(e, rng) for e in [*six, *outside]},
                      reference_load_n=float(plan.loads_n[1]))
        scatter_sd = {"kphi_log_sd": float(rng.uniform(0.04, 0.15)),
                      "friction_sd_deg": float(rng.uniform(0.3, 1.2))}
        try:
            rows = [run_row(truth, source, run, scatter_sd, rng) for source, run in plan.runs]
        except NoEquilibrium:
            continue
        if max(r["steady"]["sinkage_m"] for r in rows) > MAX_SINKAGE_RATIO * plan.wheel.radius_m:
            continue
        return {"name": name, "seed": int(seed), "index": int(index), "attempts": attempt,
                "six": six, "outside": outside, "truth": truth, "plan": plan,
                "published": published, "scatter_sd": scatter_sd, "rows": rows}
    raise RuntimeError(f"{name} of seed {seed}: no campaign whose wheel sinks less than "
                       f"{MAX_SINKAGE_RATIO} of its radius in {MAX_DRAWS} draws")


def run_row(truth: Truth, source: str, run: RunSpec, scatter_sd: dict,
            rng: np.random.Generator) -> dict:
    """One run: its soil scatter, actual slip, steady values and rig readings."""
    scatter = {"kphi_factor": float(math.exp(rng.normal(0, scatter_sd["kphi_log_sd"]))),
               "friction_deg": float(rng.normal(0, scatter_sd["friction_sd_deg"]))}
    # the drives hold the set slip to about 0.003
    slip = float(np.clip(run.slip + rng.normal(0, 0.003), -0.95, 0.95))
    actual = RunSpec(**{**run.__dict__, "slip": slip})
    steady = truth.steady(actual, scatter)
    return {"source": source, "run": actual, "slip_setpoint": run.slip, "scatter": scatter,
            "steady": steady, "readings": truth.readings(actual, steady)}


def sim_toml(wheel: WheelSpec, soil: PublishedSoil) -> str:
    """The lab's nominal simulation: the project's model-file format (docs/model-file.md)."""
    return "\n".join([
        "# The lab's nominal simulation: its wheel and a published soil, no effect.",
        "# Written by testbeds.apart (docs/validation/gap-apart.md). Format: docs/model-file.md.",
        "", "[model]", "gravity_mps2 = 9.80665", "", "[wheel]",
        f"radius_m = {wheel.radius_m!r}", f"width_m = {wheel.width_m!r}",
        f"grouser_count = {wheel.grouser_count}", f"grouser_height_m = {wheel.grouser_height_m!r}",
        "", "[soil]", f'name = "{soil.name}"', f"source = {json.dumps(soil.source)}",
        f"kc = {soil.kc!r}", f"kphi = {soil.kphi!r}", f"n = {soil.n!r}",
        f"cohesion_pa = {soil.cohesion_pa!r}", f"friction_angle_deg = {soil.friction_angle_deg!r}",
        f"shear_modulus_m = {soil.shear_modulus_m!r}", f"density_kg_m3 = {soil.density_kg_m3!r}",
        ""])


def timeline(plan: Plan) -> Timeline:
    """Run length of the campaign: :data:`STEADY_S` steady, longer where a lugged wheel's
    slowest run needs :data:`STEADY_GROUSER_PERIODS` grouser periods."""
    steady = STEADY_S
    for _, run in plan.runs:
        w = run.wheel
        if w.grouser_count:
            surface = run.velocity_mps / (1 - run.slip) if run.slip >= 0 else \
                run.velocity_mps * (1 + run.slip)
            period = 2 * math.pi * w.radius_m / (w.grouser_count * surface)
            steady = max(steady, STEADY_GROUSER_PERIODS * period)
    tl = Timeline(settle_s=SETTLE_S)
    return Timeline(duration_s=math.ceil(tl.rest_before_s + SETTLE_S + steady + tl.decel_s
                                         + tl.rest_after_s), settle_s=SETTLE_S)


def _geometry(wheel: WheelSpec) -> WheelGeometry:
    return WheelGeometry(name=wheel.name, radius_m=wheel.radius_m, width_m=wheel.width_m,
                         grouser_count=wheel.grouser_count,
                         grouser_height_m=wheel.grouser_height_m,
                         stiffness_n_per_mm=wheel.stiffness_n_per_mm)


def write_text(path: Path, text: str) -> None:
    """``text`` to ``path`` atomically (world-readable)."""
    path.parent.mkdir(parents=True, exist_ok=True)
    with tempfile.NamedTemporaryFile("w", dir=path.parent, delete=False, suffix=".tmp") as f:
        f.write(text)
    os.chmod(f.name, 0o644)
    os.replace(f.name, path)


def truth_document(drawn: dict) -> dict:
    """The truth JSON (``swtlab.testbeds.apart.truth/1``)."""
    plan: Plan = drawn["plan"]
    truth: Truth = drawn["truth"]
    six = drawn["six"]
    return {"schema": TRUTH_SCHEMA, "campaign": drawn["name"], "seed": drawn["seed"],
            "index": drawn["index"], "draws": drawn["attempts"],
            "effects": six, "outside": drawn["outside"],
            "class": ("none", "single", "pair")[len(six)] if not drawn["outside"] else "outside",
            "laws": truth.effects, "soil": truth.soil.to_dict(),
            "published_soil": drawn["published"].__dict__, "scatter_sd": drawn["scatter_sd"],
            "reference_load_n": truth.reference_load_n, "plan": plan.to_dict(),
            "runs": [{"source": r["source"], "run_id": r["run"].run_id,
                      "slip_setpoint": r["slip_setpoint"], "slip": r["run"].slip,
                      "load_n": r["run"].load_n, "multipass": r["run"].multipass,
                      "gravity_mps2": r["run"].gravity_mps2,
                      "velocity_mps": r["run"].velocity_mps, "order": r["run"].order,
                      "scatter": r["scatter"], "steady": r["steady"], "readings": r["readings"]}
                     for r in drawn["rows"]]}


def rig_inputs(rows: list[dict], campaign: str) -> tuple[list[RunCondition], dict]:
    """The rig's conditions and per-run readings table of ``rows`` (:func:`draw_campaign`'s)
    for the campaign named ``campaign``."""
    conditions = [RunCondition(r["run"].run_id, "speed_control", r["run"].load_n,
                               r["slip_setpoint"], multipass=r["run"].multipass,
                               gravity_mps2=r["run"].gravity_mps2,
                               velocity_mps=r["run"].velocity_mps, soil="bin_sand",
                               campaign=campaign, wheel=_geometry(r["run"].wheel))
                  for r in rows]
    table = {r["run"].run_id: {"slip": r["run"].slip,
                               "travel_velocity_mps": r["run"].velocity_mps,
                               "wheel_load_n": r["run"].load_n, **r["readings"]}
             for r in rows}
    return conditions, table


def start_times(seed: int, index: int, plan: Plan, run_s: float) -> dict[str, str]:
    """When each run started (ISO 8601), in the plan's run order: one run after the other,
    ``run_s`` long and :data:`RESET_MIN` apart, from a morning drawn per campaign; what a
    lab's log holds and what shows a soil that drifts through the campaign."""
    day0 = datetime(2026, 3, 2, 8, 0, tzinfo=UTC) + timedelta(days=int(seed) % 200 + index)
    n = len(plan.runs)
    return {run.run_id: (day0 + timedelta(seconds=round(run.order * (n - 1))
                                          * (run_s + 60.0 * RESET_MIN))).isoformat()
            for _, run in plan.runs}


def campaign_names(name: str, plan: Plan) -> dict[str, str]:
    """The campaign name each source's runs carry (the main wheel's, its smooth twin's)."""
    return {"main": name + ("_lugged" if plan.wheel.grouser_count else ""),
            "smooth": f"{name}_smooth"}


def lab_rig(seed: int, index: int, plan: Plan) -> Rig:
    """The campaign's rig: its run length (:func:`timeline`) and whether it writes its
    calibration uncertainty (drawn per campaign)."""
    rng = np.random.default_rng([int(seed), int(index), 1])
    return Rig(timeline=timeline(plan),
               sensors=SensorModel(write_calibration_uncertainty=bool(rng.random() < 0.5)))


def write_campaign_folder(out: str | Path, seed: int, index: int) -> dict:
    """Draw campaign ``index`` of ``seed`` and write it under ``out``; return its truth
    document. Same seed and index, same files."""
    out = Path(out)
    drawn = draw_campaign(seed, index)
    name, plan = drawn["name"], drawn["plan"]
    folder = out / name
    if folder.exists():
        shutil.rmtree(folder)
    rig = lab_rig(seed, index, plan)
    campaign_of = campaign_names(name, plan)
    started = start_times(seed, index, plan, rig.timeline.duration_s)
    for source, part, rig_truth in (("main", folder, "rig"),
                                    ("smooth", folder / "smooth", "rig-smooth")):
        rows = [r for r in drawn["rows"] if r["source"] == source]
        if not rows:
            continue
        write_campaign(part, *rig_inputs(rows, campaign_of[source]), seed * 1000 + index,
                       rig=rig, started_at=started)
        target = out / "truth" / name / rig_truth
        if target.exists():
            shutil.rmtree(target)
        target.parent.mkdir(parents=True, exist_ok=True)
        shutil.move(str(part / "truth"), str(target))
    write_text(folder / "sim.toml", sim_toml(plan.wheel, drawn["published"]))
    document = truth_document(drawn)
    write_text(out / "truth" / f"{name}.json", json.dumps(document, indent=1) + "\n")
    return document
