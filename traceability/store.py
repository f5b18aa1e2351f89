"""Persist ingested runs: campaign, wheel, soil, condition, run, raw-file version, calibration.

Storing an unchanged file again changes nothing; a changed file (new sha256)
becomes a new version of its run and the earlier versions stay.
"""

from __future__ import annotations

import enum
import json
from datetime import datetime, timezone
from pathlib import Path
from typing import Any

from sqlalchemy import func, select
from sqlalchemy.orm import Session

from traceability.hashing import content_sha256
from traceability.provenance import lock_sha256, swtlab_version
from traceability.models import (Calibration, Campaign, ProcessingRecord, RawFile, Run, Soil,
                                 TestCondition, Wheel)


class StoreOutcome(enum.Enum):
    NEW_RUN = "new run"
    NEW_VERSION = "new version"
    UNCHANGED = "unchanged"


def new_processing_record(session: Session, stage: str,
                          parameters: dict[str, Any]) -> ProcessingRecord:
    record = ProcessingRecord(swtlab_version=swtlab_version(), lock_sha256=lock_sha256(),
                              stage=stage,
                              parameters=json.loads(json.dumps(parameters, default=str)),
                              created_at=datetime.now(timezone.utc))
    session.add(record)
    return record


def _get_or_create(session: Session, model: type, **values: Any) -> Any:
    row = session.scalars(select(model).filter_by(**values)).first()
    if row is None:
        row = model(**values)
        session.add(row)
        session.flush()
    return row


def _condition(session: Session, campaign: Campaign, meta: Any) -> TestCondition:
    w = meta.wheel
    wheel = _get_or_create(session, Wheel, name=meta.run.wheel, radius_m=w.radius_m,
                           width_m=w.width_m, grouser_count=w.grouser_count,
                           grouser_height_m=w.grouser_height_m,
                           stiffness_n_per_mm=w.stiffness_n_per_mm)
    if wheel.mass_kg is None and w.mass_kg is not None:
        wheel.mass_kg = w.mass_kg
    soil = _get_or_create(session, Soil, name=meta.run.soil)
    r = meta.run
    return _get_or_create(session, TestCondition, campaign_id=campaign.id, wheel_id=wheel.id,
                          soil_id=soil.id, mode=r.mode, multipass=r.multipass, load_n=r.load_n,
                          slip_setpoint=r.slip_setpoint, velocity_mps=r.velocity_mps,
                          gravity_mps2=r.gravity_mps2, steer_deg=r.steer_deg)


def _calibrations(meta: Any) -> list[Calibration]:
    rows = [Calibration(kind="gain_offset", topic=topic, field=field, gain=gain, offset=offset)
            for (topic, field), (gain, offset) in sorted(meta.calibration.items())]
    rows += [Calibration(kind="zero", topic="/hub/wrench", field=field, gain=1.0, offset=-value)
             for field, value in sorted(meta.zero.items())]
    return rows


def _file_format(run: Any) -> str:
    """``mcap``, ``csv`` (spec run folder), or the name of the channel map that read it."""
    if run.channel_map != "spec":
        return f"map:{run.channel_map}"
    return "mcap" if Path(run.source).suffix == ".mcap" else "csv"


def store_ingested_run(session: Session, run: Any, channel_summary: dict[str, Any],
                       parameters: dict[str, Any]) -> tuple[RawFile, StoreOutcome]:
    """Record ``run`` (an ``ingest.Run``) and its raw file; return the raw-file row and the
    outcome.

    ``parameters`` (channel map, derivation methods) go into the processing record
    written with a new raw-file version; an unchanged file writes nothing.
    """
    meta = run.metadata
    sha256, size_bytes = content_sha256(Path(run.source))
    campaign = _get_or_create(session, Campaign, name=meta.run.campaign)
    db_run = session.scalars(select(Run).filter_by(campaign_id=campaign.id,
                                                   run_id=meta.run.run_id)).first()
    outcome = StoreOutcome.NEW_RUN
    if db_run is not None:
        same = session.scalars(select(RawFile).filter_by(run_pk=db_run.id, sha256=sha256)).first()
        if same is not None:
            return same, StoreOutcome.UNCHANGED
        outcome = StoreOutcome.NEW_VERSION
    condition = _condition(session, campaign, meta)
    if db_run is None:
        db_run = Run(campaign_id=campaign.id, run_id=meta.run.run_id, condition_id=condition.id,
                     started_at=meta.run.started_at)
        session.add(db_run)
        session.flush()
    last_version = session.scalar(select(func.max(RawFile.version)).filter_by(run_pk=db_run.id))
    raw_file = RawFile(run_pk=db_run.id, version=(last_version or 0) + 1,
                       path=str(Path(run.source).resolve()), size_bytes=size_bytes, sha256=sha256,
                       file_format=_file_format(run), channel_summary=channel_summary,
                       problems=[p.to_dict() for p in run.problems],
                       processing=new_processing_record(session, "ingest", parameters),
                       calibrations=_calibrations(meta))
    session.add(raw_file)
    session.flush()
    return raw_file, outcome
