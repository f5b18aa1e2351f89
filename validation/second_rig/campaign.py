"""Campaigns of the second rig: raw runs in ``<out>/campaign/``, their truth apart in
``<out>/truth/<run_id>.json`` (schema ``swtlab.second_rig.truth/1``), like a blind test.

Each run draws from its own generator, seeded by the campaign seed and a SHA-256 of its run
id, and its ``started_at`` comes from the seed and the run id, so a run's bytes do not depend on
the rest of the campaign; no wall-clock time goes in.
"""

from __future__ import annotations

import hashlib
import shutil
from collections.abc import Iterable, Mapping
from dataclasses import asdict, dataclass, field, replace
from datetime import UTC, datetime, timedelta
from pathlib import Path

import numpy as np

from validation.second_rig.condition import RunCondition, SecondRigError, Truth, steady_truth
from validation.second_rig.sensors import Rates, SensorModel, measure
from validation.second_rig.signals import SignalModel, Timeline, true_run, window_means
from validation.second_rig.writers import write_csv_folder, write_json, write_mcap

TRUTH_SCHEMA = "swtlab.second_rig.truth/1"
FORMS = ("mcap", "csv")


@dataclass(frozen=True)
class Rig:
    """Everything about the rig that is not the test condition."""

    timeline: Timeline = field(default_factory=Timeline)
    signals: SignalModel = field(default_factory=SignalModel)
    sensors: SensorModel = field(default_factory=SensorModel)
    rates: Rates = field(default_factory=Rates)


#: the low-speed coarse-encoder mode's encoders: a 14-bit wheel encoder and the sled
#: encoder logged at 500 Hz (the wheel turns about half a count per sample at 10 mm/s)
LOW_SPEED_WHEEL_COUNTS_PER_REV = 2**14
LOW_SPEED_ENCODER_HZ = 500.0


def low_speed_rig(rig: Rig | None = None) -> Rig:
    """``rig`` (default: the rig as it is) with the low-speed coarse-encoder mode's encoders
    (:data:`LOW_SPEED_WHEEL_COUNTS_PER_REV`, :data:`LOW_SPEED_ENCODER_HZ`): at a sled speed of
    a few mm/s each sample's change is zero or one count, the case where averaging per-sample
    ratios of differences is biased. The run's speed is the condition's ``velocity_mps``."""
    rig = rig or Rig()
    return replace(rig, sensors=replace(rig.sensors,
                                        wheel_counts_per_rev=LOW_SPEED_WHEEL_COUNTS_PER_REV),
                   rates=replace(rig.rates, wheel_encoder_hz=LOW_SPEED_ENCODER_HZ,
                                 sled_encoder_hz=LOW_SPEED_ENCODER_HZ))


def run_rng(seed: int, run_id: str) -> np.random.Generator:
    """The run's own generator: ``(seed, sha256(run_id))``."""
    digest = hashlib.sha256(run_id.encode()).digest()
    return np.random.default_rng([int(seed), *np.frombuffer(digest[:16], dtype=np.uint32)])


def run_records(condition: RunCondition, started_at: str) -> dict[str, dict]:
    """The ``swt.run`` and ``swt.wheel`` records (values as numbers where they are numbers)."""
    run = {"run_id": condition.run_id, "campaign": condition.campaign,
           "wheel": condition.wheel.name, "soil": condition.soil,
           "multipass": condition.multipass, "mode": condition.mode,
           "load_N": float(condition.load_n), "velocity_mps": float(condition.velocity_mps),
           "gravity_mps2": float(condition.gravity_mps2), "started_at": started_at}
    if condition.slip_setpoint is not None:
        run["slip_setpoint"] = float(condition.slip_setpoint)
    w = condition.wheel
    wheel = {"radius_m": w.radius_m, "width_m": w.width_m, "grouser_count": w.grouser_count,
             "grouser_height_m": w.grouser_height_m}
    if w.stiffness_n_per_mm is not None:
        wheel["stiffness_N_per_mm"] = w.stiffness_n_per_mm
    return {"run": run, "wheel": wheel}


def make_run(condition: RunCondition, truth: Truth, seed: int, started_at: str,
             rig: Rig | None = None) -> tuple[dict, dict, dict, np.random.Generator]:
    """``(topics, records, truth_document, rng)`` of one run, nothing written."""
    rig = rig or Rig()
    rng = run_rng(seed, condition.run_id)
    steady = steady_truth(truth, condition)
    run = true_run(condition, steady, rig.timeline, rig.signals, rng)
    tl = rig.timeline
    moving = (tl.motion_start_s, tl.decel_start_s + tl.decel_s)
    topics, sensor_records, meas = measure(condition, run, rig.rates, rig.sensors,
                                           tl.duration_s, moving, rng)
    records = {**run_records(condition, started_at), **sensor_records}
    document = {
        "schema": TRUTH_SCHEMA, "run_id": condition.run_id, "seed": int(seed),
        "condition": condition.to_dict(), "steady": steady,
        "window": {"start_s": run.window[0], "end_s": run.window[1]},
        "window_means": window_means(run, condition.wheel.radius_m),
        "timeline": {**asdict(tl), "motion_start_s": moving[0], "decel_start_s":
                     tl.decel_start_s, "motion_end_s": moving[1]},
        "signal_parameters": {**run.parameters, "model": asdict(rig.signals)},
        "measurement": meas,
    }
    return topics, records, document, rng


def write_campaign(out_dir: str | Path, conditions: Iterable[RunCondition], truth_fn: Truth,
                   seed: int, *, form: str | Mapping[str, str] = "mcap",
                   rig: Rig | None = None, started_at: Mapping[str, str] | None = None
                   ) -> list[str]:
    """Write every condition's raw run to ``<out_dir>/campaign/`` (``<run_id>.mcap`` or a
    ``<run_id>/`` CSV folder) and its truth to ``<out_dir>/truth/<run_id>.json``; return
    the run ids in order. ``truth_fn``: ``condition -> {TRUTH_KEYS}`` or a table
    ``{run_id: {...}}``; ``form``: one form for all runs or ``{run_id: form}``;
    ``started_at``: ``{run_id: ISO 8601 time}`` where the caller knows when each run started
    (default: a time drawn from the seed and the run id)."""
    conditions = list(conditions)
    ids = [c.run_id for c in conditions]
    if len(set(ids)) != len(ids):
        raise SecondRigError(f"duplicate run ids: {sorted({i for i in ids if ids.count(i) > 1})}")
    forms = {i: (form.get(i, "mcap") if isinstance(form, Mapping) else form) for i in ids}
    bad = {i: f for i, f in forms.items() if f not in FORMS}
    if bad:
        raise SecondRigError(f"unknown form(s) {bad}; forms: {FORMS}")
    out = Path(out_dir)
    campaign, truth_dir, staging = out / "campaign", out / "truth", out / ".staging"
    for folder in (campaign, truth_dir, staging):
        folder.mkdir(parents=True, exist_ok=True)
    day0 = datetime(2026, 3, 2, 8, 0, tzinfo=UTC) + timedelta(days=int(seed) % 200)
    try:
        for condition in conditions:
            minutes = int.from_bytes(hashlib.sha256(condition.run_id.encode()).digest()[:4])
            started = (started_at or {}).get(
                condition.run_id, (day0 + timedelta(minutes=minutes % 600)).isoformat())
            topics, records, document, rng = make_run(condition, truth_fn, seed, started, rig)
            name = condition.run_id + (".mcap" if forms[condition.run_id] == "mcap" else "")
            if forms[condition.run_id] == "mcap":
                write_mcap(campaign / name, topics, records, rng, staging)
            else:
                write_csv_folder(campaign / name, topics, records, staging)
            document.update(form=forms[condition.run_id], raw_file=f"campaign/{name}")
            write_json(truth_dir / f"{condition.run_id}.json", document, staging)
    finally:
        shutil.rmtree(staging, ignore_errors=True)
    return ids
