"""Persist ingested runs: campaign, wheel, soil, condition, run, raw-file version, calibration.

Storing an unchanged file again changes nothing; a changed file (new sha256) becomes the
current version of its run (its condition too) and the earlier versions stay; a file reverted
to stored bytes makes that version current again (docs/results.md, "Versions").
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
from traceability.text import TextRefused, checked_name
from traceability.models import (Calibration, Campaign, ProcessingRecord, RawFile, Run, Soil,
                                 TestCondition, Wheel, condition_columns)
from swtlab_base.errors import InputError


class StoreOutcome(enum.Enum):
    NEW_RUN = "new run"
    NEW_VERSION = "new version"
    REVERTED = "reverted to a stored version"
    UNCHANGED = "unchanged"


class RunIdClaimed(InputError, ValueError):
    """A file claims the run_id of a run stored from another file."""


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
    return _get_or_create(session, TestCondition, campaign_id=campaign.id, wheel_id=wheel.id,
                          soil_id=soil.id, **condition_columns(meta.run.condition))


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


def _found_at(raw_file: RawFile, path: str) -> None:
    """The content of ``raw_file`` is at ``path`` now: follow a moved file (the stored path
    is gone), clear its missing mark."""
    if raw_file.path != path and not Path(raw_file.path).exists():
        raw_file.path = path
    if raw_file.path == path:
        raw_file.missing_since = None


def _current(db_run: Run) -> RawFile:
    return next(f for f in db_run.raw_files if f.version == db_run.current_version)


def _claimed(db_run: Run, path: str, campaign: str) -> RunIdClaimed:
    return RunIdClaimed(
        f"{path}: claims run_id {db_run.run_id!r} of campaign {campaign!r}, already stored "
        f"from {_current(db_run).path}; give one of them another run_id, or pass "
        "allow_run_id_reuse=True to store this file as that run's new version")


def store_ingested_run(session: Session, run: Any, channel_summary: list[dict[str, Any]],
                       parameters: dict[str, Any], *, allow_run_id_reuse: bool = False,
                       content: tuple[str, int] | None = None) -> tuple[RawFile, StoreOutcome]:
    """Record ``run`` (an ``ingest.Run``) and its raw file; return the raw-file row and the
    outcome.

    A run is found by its content first (a stored file moved or renamed, with or without a
    run_id, is the same run), then by (campaign, run_id). A changed file is a new version
    and becomes current, its condition the run's; the current file reverted to stored bytes
    (or gone, with an older version's file still there) makes that version current again; an
    old version's file lying beside the current one changes nothing. Another file claiming a
    stored run_id raises :class:`RunIdClaimed` unless ``allow_run_id_reuse``; a name the
    database cannot hold raises ``TextRefused``. ``parameters`` (channel map, derivation
    methods) go into the processing record of a new version; an unchanged file writes
    nothing. ``content``: the file's (sha256, size in bytes) when the caller hashed it
    already (``traceability.hashing.content_sha256``), else it is hashed here."""
    meta = run.metadata
    path = str(Path(run.source).resolve())
    calibrations = _calibrations(meta)
    names = [("campaign", meta.run.campaign), ("run_id", meta.run.run_id),
             ("wheel", meta.run.wheel), ("soil", meta.run.soil)]
    names += [(what, getattr(row, what)) for row in calibrations for what in ("topic", "field")]
    try:
        for what, name in names:
            checked_name(what, name)
    except TextRefused as error:
        raise TextRefused(f"{path}: {error}") from None
    sha256, size_bytes = content or content_sha256(Path(run.source))
    campaign = _get_or_create(session, Campaign, name=meta.run.campaign)
    known = session.scalars(select(RawFile).join(Run, Run.id == RawFile.run_pk).where(
        Run.campaign_id == campaign.id, RawFile.sha256 == sha256).order_by(RawFile.id)).first()
    if known is not None:
        db_run = known.run
        current = _current(db_run)
        _found_at(known, path)
        if known is current or (current.path != path and Path(current.path).exists()):
            return known, StoreOutcome.UNCHANGED  # the current one, or an old copy beside it
        db_run.current_version = known.version  # the current file went back to these bytes
        db_run.condition_id = _condition(session, campaign, meta).id
        db_run.started_at = meta.run.started_at
        return known, StoreOutcome.REVERTED
    db_run = session.scalars(select(Run).filter_by(campaign_id=campaign.id,
                                                   run_id=meta.run.run_id)).first()
    if db_run is not None and not allow_run_id_reuse and path not in {
            f.path for f in db_run.raw_files}:
        raise _claimed(db_run, path, meta.run.campaign)
    condition = _condition(session, campaign, meta)
    outcome = StoreOutcome.NEW_VERSION
    if db_run is None:
        outcome = StoreOutcome.NEW_RUN
        db_run = Run(campaign_id=campaign.id, run_id=meta.run.run_id, condition_id=condition.id,
                     started_at=meta.run.started_at, current_version=1)
        session.add(db_run)
        session.flush()
    version = (session.scalar(select(func.max(RawFile.version)).filter_by(run_pk=db_run.id))
               or 0) + 1
    raw_file = RawFile(run_pk=db_run.id, version=version, path=path, size_bytes=size_bytes,
                       sha256=sha256, file_format=_file_format(run),
                       channel_summary=channel_summary,
                       problems=[p.to_dict() for p in run.problems],
                       processing=new_processing_record(session, "ingest", parameters),
                       calibrations=calibrations)
    session.add(raw_file)
    db_run.current_version, db_run.condition_id = version, condition.id
    db_run.started_at = meta.run.started_at
    session.flush()
    return raw_file, outcome


def mark_missing(session: Session, folder: Path) -> list[RawFile]:
    """The current raw files stored from under ``folder`` that are gone, each marked with
    the time it was first found missing (a file found again is unmarked)."""
    prefix = str(Path(folder).resolve()).rstrip("/") + "/"
    rows = session.scalars(
        select(RawFile).join(Run, (Run.id == RawFile.run_pk)
                             & (Run.current_version == RawFile.version))
        .where(RawFile.path.startswith(prefix, autoescape=True)).order_by(RawFile.path)).all()
    missing = []
    for row in rows:
        if Path(row.path).exists():
            row.missing_since = None
            continue
        row.missing_since = row.missing_since or datetime.now(timezone.utc)
        missing.append(row)
    return missing
