"""Read-back: one row per run with conditions, stable window and results (swtlab results)."""

from __future__ import annotations

import pandas as pd
from sqlalchemy import func, select
from sqlalchemy.orm import Session

from swtlab_base.domain.replicates import with_repeatability
from swtlab_base.domain.results import (COLUMNS, budget_columns, check_results, not_measured_text,
                                   wheel_columns)

from traceability.models import (Campaign, RawFile, Run, RunQuantity, RunResult,
                                 RunUncertainty, Soil, StableWindow, TestCondition, Wheel)

STATS = ("mean", "std", "se")


def latest_results(session: Session) -> pd.DataFrame:
    """Newest result of the current raw-file version of every run, one row per run (the
    newest version, or an older one its file was reverted to).

    Columns are documented in docs/results.md: identifiers, conditions, status and
    flags, the stable window, ``<quantity>_mean|_std|_se`` per quantity, its uncertainty
    budget ``<quantity>_u|_u95|_k|_dof|_correction|_u_<term>``, and the grouser oscillation.
    """
    newest_result = (select(RunResult.raw_file_id, func.max(RunResult.id).label("result_id"))
                     .group_by(RunResult.raw_file_id).subquery())
    rows = session.execute(
        select(Campaign.name.label("campaign"), Run.run_id, Run.started_at, RawFile.version,
               RawFile.path, RawFile.sha256, RawFile.missing_since, Wheel,
               Soil.name.label("soil"), TestCondition, RunResult, StableWindow)
        .join(Run.campaign).join(Run.condition).join(TestCondition.wheel)
        .join(TestCondition.soil)
        .join(RawFile, (RawFile.run_pk == Run.id) & (RawFile.version == Run.current_version))
        .join(newest_result, newest_result.c.raw_file_id == RawFile.id)
        .join(RunResult, RunResult.id == newest_result.c.result_id)
        .join(StableWindow, StableWindow.id == RunResult.stable_window_id)
        .order_by(Campaign.name, Run.run_id)).all()
    result_ids = [row.RunResult.id for row in rows]
    quantities = session.execute(select(RunQuantity).where(
        RunQuantity.run_result_id.in_(result_ids))).scalars().all() if result_ids else []
    by_result: dict[int, dict[str, float | None]] = {}
    for q in quantities:
        by_result.setdefault(q.run_result_id, {}).update(
            {f"{q.quantity}_{stat}": getattr(q, stat) for stat in STATS})
    budgets = session.execute(select(RunUncertainty).where(
        RunUncertainty.run_result_id.in_(result_ids))).scalars().all() if result_ids else []
    missing: dict[int, list[str]] = {}
    for b in budgets:
        by_result.setdefault(b.run_result_id, {}).update(budget_columns(b.quantity, {
            c.key: getattr(b, c.key) for c in RunUncertainty.__table__.columns}))
        missing.setdefault(b.run_result_id, []).extend(b.not_measured or [])
    records = []
    for row in rows:
        cond, result, window = row.TestCondition.to_domain(), row.RunResult, row.StableWindow
        records.append({
            "campaign": row.campaign, "run_id": row.run_id,
            "started_at": None if row.started_at is None else row.started_at.isoformat(),
            "raw_file_version": row.version,
            "raw_file_path": row.path, "raw_file_sha256": row.sha256,
            "raw_file_missing": row.missing_since is not None,
            **wheel_columns(row.Wheel), "soil": row.soil, "mode": cond.mode,
            "multipass": cond.multipass,
            "load_set_n": cond.load_set_n, "slip_setpoint": cond.slip_setpoint,
            "velocity_set_mps": cond.velocity_set_mps, "gravity_mps2": cond.gravity_mps2,
            "steer_deg": cond.steer_deg, "status": result.status,
            "flags": "; ".join(result.flags), "window_found": window.found,
            "window_start_s": window.start_s, "window_end_s": window.end_s,
            "window_method": window.method, "no_window_reason": window.reason,
            "not_measured": not_measured_text(missing.get(result.id, [])),
            **by_result.get(result.id, {}), **result.oscillation,
            "result_id": result.id})
    return check_results(with_repeatability(pd.DataFrame.from_records(
        records, columns=None if records else list(COLUMNS))))
