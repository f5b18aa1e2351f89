"""Generate runs and campaigns: raw files in ``<out>/campaign/``, truth in ``<out>/truth/``."""

from __future__ import annotations

import json
import zlib
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field, replace
from datetime import datetime, timedelta, timezone
from pathlib import Path

import numpy as np

from swtlab_base.atomic import write_atomically
from virtual_testbed.conditions import RunCondition
from virtual_testbed.lateral import LateralLaw
from virtual_testbed.law import PerformanceLaw, bb2_sand_law
from virtual_testbed.measure import RawRun, measure
from virtual_testbed.rig import BB2_WHEEL, Suspension, Timeline, Wheel
from virtual_testbed.sensors import Rates, SensorModel
from virtual_testbed.side_camera import SIDE_TOPIC, SideCamera, camera_record, side_frames
from virtual_testbed.simulate import Dynamics, simulate_true_run
from virtual_testbed.track_photos import TRACK_TOPIC, photo_seed, track_photos
from virtual_testbed.truth import truth_record
from virtual_testbed.write_csv import write_csv
from virtual_testbed.write_mcap import write_mcap

FORMS = ("mcap", "csv")


@dataclass(frozen=True)
class Testbed:
    """Everything fixed across a campaign: the law, the rig, the sensors and the run timeline."""

    law: PerformanceLaw = field(default_factory=bb2_sand_law)
    lateral: LateralLaw = LateralLaw()
    #: ground scale of the track photos (px per m at the image centre)
    track_px_per_m: float = 700.0
    #: the side camera of runs with ``side_camera_frames``
    side_camera: SideCamera = SideCamera()
    wheel: Wheel = BB2_WHEEL
    suspension: Suspension = Suspension()
    timeline: Timeline = Timeline()
    rates: Rates = Rates()
    sensors: SensorModel = SensorModel()
    dynamics: Dynamics = Dynamics()
    campaign: str = "virtual"
    soil: str = "sand"


def run_rng(seed: int, run_id: str) -> np.random.Generator:
    """Per-run generator: a run's bytes depend on the seed and its id, not on campaign order."""
    return np.random.default_rng([seed, zlib.crc32(run_id.encode())])


def started_at(seed: int, index: int) -> str:
    """Deterministic start: first day from the seed, 24 runs a day from 08:00, 25 min apart."""
    first_day = datetime(2026, 1, 1, 8, 0, tzinfo=timezone.utc) + timedelta(days=seed % 365)
    start = first_day + timedelta(days=index // 24, minutes=25 * (index % 24))
    return start.strftime("%Y-%m-%dT%H:%M:%SZ")


def run_metadata(condition: RunCondition, testbed: Testbed, start: str) -> dict[str, dict]:
    """The spec's ``swt.run``, ``swt.wheel`` and ``swt.suspension`` records (typed values)."""
    c, w = condition, testbed.wheel
    run = {"run_id": c.run_id, "campaign": testbed.campaign, "wheel": w.name, "soil": testbed.soil,
           "multipass": c.multipass, "mode": c.mode, "load_N": float(c.load_set_n)}
    if c.slip_setpoint is not None:
        run["slip_setpoint"] = float(c.slip_setpoint)
    if c.steer_deg is not None:
        run["steer_deg"] = float(c.steer_deg)
    run.update({"velocity_mps": float(c.velocity_set_mps), "gravity_mps2": float(c.gravity_mps2),
                "started_at": start})
    wheel = {"radius_m": w.radius_m, "width_m": w.width_m, "grouser_count": w.grouser_count,
             "grouser_height_m": w.grouser_height_m}
    if w.stiffness_n_per_mm is not None:
        wheel["stiffness_N_per_mm"] = w.stiffness_n_per_mm
    if w.mass_kg is not None:
        wheel["mass_kg"] = w.mass_kg
    suspension = {"arm_length_m": testbed.suspension.arm_length_m,
                  "angle_zero_rad": testbed.suspension.angle_zero_rad}
    return {"run": run, "wheel": wheel, "suspension": suspension}


def make_run(condition: RunCondition, seed: int, start: str, testbed: Testbed,
             form: str = "mcap") -> tuple[RawRun, dict]:
    """Simulate one run: the raw run to write and its truth record."""
    rng = run_rng(seed, condition.run_id)
    tb = testbed
    true_run = simulate_true_run(condition, tb.law, tb.wheel, tb.timeline, tb.dynamics,
                                 phase_rad=float(rng.uniform(0.0, 2.0 * np.pi)),
                                 lateral=tb.lateral)
    measurement = measure(true_run, tb.wheel, tb.suspension, tb.rates, tb.sensors, rng,
                          run_metadata(condition, tb, start))
    raw = measurement.raw
    photos_truth = None
    if condition.track_photos:
        end_ns = int(round(tb.timeline.duration_s * 1e9))
        photos = track_photos(true_run.steady["slip"], tb.wheel, condition.track_photos,
                              tb.track_px_per_m, end_ns, photo_seed(rng))
        raw = replace(raw, images={TRACK_TOPIC: photos},
                      metadata={**raw.metadata, "camera_track": {"px_per_m": tb.track_px_per_m}})
        photos_truth = {"count": len(photos), "px_per_m": tb.track_px_per_m,
                        "slip": true_run.steady["slip"], "t_ns": [p.t_ns for p in photos]}
    side_truth = None
    if condition.side_camera_frames:
        frames, side_truth = side_frames(true_run, tb.wheel, tb.side_camera,
                                         condition.side_camera_frames, photo_seed(rng))
        raw = replace(raw, images={**raw.images, SIDE_TOPIC: frames},
                      metadata={**raw.metadata, "camera": camera_record(tb.side_camera)})
    truth = truth_record(true_run, radius_m=tb.wheel.radius_m, grouser_count=tb.wheel.grouser_count,
                         raw_file=raw_name(condition.run_id, form), form=form, seed=seed,
                         law_parameters=tb.law.parameters(), dynamics=tb.dynamics,
                         sensors=tb.sensors, rates=tb.rates, measurement_record=measurement.record)
    if photos_truth:
        truth["track_photos"] = photos_truth
    if side_truth:
        truth["side_camera"] = side_truth
    return raw, truth


def raw_name(run_id: str, form: str) -> str:
    """Path of a run's raw file or folder relative to the output folder."""
    if form not in FORMS:
        raise ValueError(f"form {form!r} not in {FORMS}")
    return f"campaign/{run_id}.mcap" if form == "mcap" else f"campaign/{run_id}"


def write_run(raw: RawRun, truth: dict, out_dir: Path) -> Path:
    """Write the raw run (form from the truth) and its truth JSON; return the raw path."""
    path = Path(out_dir) / truth["raw_file"]
    path.parent.mkdir(parents=True, exist_ok=True)
    (write_mcap if truth["form"] == "mcap" else write_csv)(raw, path)
    truth_path = Path(out_dir) / "truth" / f"{raw.run_id}.json"
    truth_path.parent.mkdir(parents=True, exist_ok=True)
    write_atomically(truth_path, json.dumps(truth) + "\n")
    return path


def generate_campaign(out_dir: str | Path, conditions: Sequence[RunCondition], seed: int, *,
                      rates: Rates | None = None, duration_s: float | None = None,
                      form: str | Mapping[str, str] = "mcap",
                      testbed: Testbed | None = None) -> list[Path]:
    """Write a whole campaign; ``form`` is one form for all or a ``run_id -> form`` map.

    ``rates`` and ``duration_s`` override the testbed's (the stable phase
    stretches or shrinks to the duration). Same arguments, same bytes.
    """
    tb = testbed or Testbed()
    if rates is not None:
        tb = replace(tb, rates=rates)
    if duration_s is not None:
        tb = replace(tb, timeline=tb.timeline.with_duration(duration_s))
    ids = [c.run_id for c in conditions]
    if len(set(ids)) != len(ids):
        raise ValueError("run_id values must be unique")
    paths = []
    for index, condition in enumerate(conditions):  # one iteration per run
        run_form = form if isinstance(form, str) else form[condition.run_id]
        raw, truth = make_run(condition, seed, started_at(seed, index), tb, run_form)
        paths.append(write_run(raw, truth, Path(out_dir)))
    return paths
