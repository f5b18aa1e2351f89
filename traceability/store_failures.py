"""Failed runs: record a file that could not be processed, and list the files whose newest
outcome is a failure (``swtlab results`` and the report show them as ``failed``)."""

from __future__ import annotations

from pathlib import Path
from typing import Any

from sqlalchemy import func, select
from sqlalchemy.orm import Session

from traceability.models import IngestFailure, RawFile, RunResult
from traceability.store import new_processing_record
from traceability.text import TextRefused, checked_name, message


def _newest_result_record(session: Session, path: str) -> int | None:
    """Processing-record id of the newest result of any raw file at ``path``."""
    return session.scalar(select(func.max(RunResult.processing_id))
                          .join(RawFile, RawFile.id == RunResult.raw_file_id)
                          .where(RawFile.path == path))


def store_failure(session: Session, path: Path, sha256: str, stage: str, error_type: str,
                  error: str, parameters: dict[str, Any], run_id: str | None = None) -> None:
    """Record that ``path`` (content ``sha256``) failed at ``stage``; nothing new when its
    newest outcome is already this failure (a rerun of an unchanged bad file)."""
    where, error = str(Path(path).resolve()), message(error)
    try:
        run_id = None if run_id is None else checked_name("run_id", run_id)
    except TextRefused:
        run_id = None  # the refused run id itself: the file names the failure
    last = session.scalars(select(IngestFailure).filter_by(path=where)
                           .order_by(IngestFailure.processing_id.desc())).first()
    newer_result = _newest_result_record(session, where)
    if (last is not None and (last.sha256, last.stage, last.error) == (sha256, stage, error)
            and (newer_result is None or newer_result < last.processing_id)):
        return
    session.add(IngestFailure(path=where, sha256=sha256, error=error, stage=stage,
                              error_type=error_type, run_id=run_id,
                              processing=new_processing_record(session, stage, parameters)))
    session.flush()


def current_failures(session: Session) -> list[IngestFailure]:
    """The newest failure of every file whose newest outcome is a failure (no result stored
    for that path since), ordered by path."""
    newest = (select(IngestFailure.path, func.max(IngestFailure.processing_id).label("pid"))
              .group_by(IngestFailure.path).subquery())
    rows = session.scalars(select(IngestFailure).join(
        newest, (newest.c.path == IngestFailure.path)
        & (newest.c.pid == IngestFailure.processing_id)).order_by(IngestFailure.path)).all()
    return [row for row in rows
            if (_newest_result_record(session, row.path) or -1) < row.processing_id]
