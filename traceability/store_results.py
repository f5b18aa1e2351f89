"""Persist stable windows and run results, once per (raw-file version, processing parameters)."""

from __future__ import annotations

import hashlib
import json
from pathlib import Path
from typing import Any

from sqlalchemy import select
from sqlalchemy.orm import Session

from swtlab_base.plain_json import jsonable
from swtlab_base.domain.results import UNCERTAINTY_TERMS
from traceability.provenance import swtlab_version
from traceability.models import RawFile, Run, RunQuantity, RunResult, RunUncertainty, StableWindow
from traceability.store import new_processing_record
from traceability.store_traces import store_traces


def params_sha256(parameters: dict[str, Any]) -> str:
    """Hash of the processing parameters and the swtlab version (canonical JSON)."""
    text = json.dumps({"swtlab": swtlab_version(), **parameters}, sort_keys=True, default=str)
    return hashlib.sha256(text.encode()).hexdigest()


def find_result(session: Session, raw_file: RawFile, params_hash: str) -> RunResult | None:
    return session.scalars(select(RunResult).filter_by(raw_file_id=raw_file.id,
                                                       params_sha256=params_hash)).first()


def processed_file(session: Session, path: Path, sha256: str, params_hash: str) -> bool:
    """Whether this exact file content at this path is its run's current version and has a
    result for these parameters (a file reverted to an older version is not)."""
    return session.scalars(
        select(RunResult.id).join(RawFile, RawFile.id == RunResult.raw_file_id)
        .join(Run, (Run.id == RawFile.run_pk) & (Run.current_version == RawFile.version))
        .where(RawFile.path == str(path.resolve()), RawFile.sha256 == sha256,
               RunResult.params_sha256 == params_hash)).first() is not None


def store_run_result(session: Session, raw_file: RawFile, result: Any,
                     parameters: dict[str, Any]) -> RunResult:
    """Store ``result`` (a ``run_results.RunResult``), its window and its decimated traces,
    one processing record."""
    record = new_processing_record(session, "process", parameters)
    w = result.window
    window = StableWindow(raw_file_id=raw_file.id, found=w.found, start_s=w.start_s,
                          end_s=w.end_s, method=w.method, parameters=jsonable(w.parameters),
                          diagnostics=jsonable(w.diagnostics), reason=w.reason, processing=record)
    row = RunResult(raw_file=raw_file, window=window, params_sha256=params_sha256(parameters),
                    status=result.status, flags=list(result.flags),
                    oscillation=jsonable(result.oscillation),
                    corrections=jsonable(result.corrections),
                    dp_trace=jsonable(result.dp_trace), processing=record,
                    quantities=[RunQuantity(quantity=name, unit=q.unit, mean=_num(q.mean),
                                            std=_num(q.std), se=_num(q.se), n=q.n,
                                            n_eff=_num(q.n_eff))
                                for name, q in result.quantities.items()])
    session.add(row)
    session.flush()
    store_traces(session, row, result.traces)
    store_uncertainty(session, row, getattr(result, "uncertainty", {}))
    return row


def replace_uncertainty(session: Session, path: Path, sha256: str, params_hash: str,
                        budgets: dict) -> bool:
    """Replace the stored budgets of the result of this file content and parameters (after
    the campaign's drift diffusion was pooled); whether there was such a result."""
    raw_file = session.scalars(select(RawFile).filter_by(path=str(Path(path).resolve()),
                                                         sha256=sha256)).first()
    row = None if raw_file is None else find_result(session, raw_file, params_hash)
    if row is None:
        return False
    for old in session.scalars(select(RunUncertainty).filter_by(run_result_id=row.id)).all():
        session.delete(old)
    session.flush()
    store_uncertainty(session, row, budgets)
    return True


def store_uncertainty(session: Session, row: RunResult, budgets: dict) -> None:
    """One ``RunUncertainty`` per quantity budget (``QuantityBudget``) of the result."""
    for name, budget in budgets.items():
        d = budget.to_dict()
        session.add(RunUncertainty(
            run_result_id=row.id, quantity=name, unit=d["unit"],
            not_measured=list(d["not_measured"]),
            **{k: _num(d[k]) for k in ("correction", *(f"u_{t}" for t in UNCERTAINTY_TERMS),
                                       "u", "dof", "k", "u95")}))


def _num(value: Any) -> float | None:
    """A finite float, or None for NaN/inf (JSON and every SQL backend accept NULL)."""
    if value is None:
        return None
    value = float(value)
    return value if value == value and abs(value) != float("inf") else None
