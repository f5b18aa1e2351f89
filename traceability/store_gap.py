"""Persist a sim-to-real gap report (docs/gap-report.md) in the database it was measured from."""

from __future__ import annotations

from typing import Any

from sqlalchemy.orm import Session

from traceability.models import GapReport
from traceability.store import new_processing_record
from traceability.store_results import jsonable


def store_gap_report(session: Session, report: dict[str, Any]) -> GapReport:
    """Record ``report`` (``sim_gap`` JSON) with a processing record of its settings."""
    row = GapReport(sim_source=str(report["simulated"]), verdict=jsonable(report["verdict"]),
                    report=jsonable(report),
                    processing=new_processing_record(session, "gap",
                                                     {"settings": report.get("settings")}))
    session.add(row)
    session.flush()
    return row
