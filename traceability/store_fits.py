"""Persist curve fits with the run results they come from, and every WPM CSV export."""

from __future__ import annotations

import hashlib
import json
from pathlib import Path
from typing import Any

import pandas as pd
from sqlalchemy import select
from sqlalchemy.orm import Session

from swtlab_base.plain_json import jsonable
from traceability.models import CurveFit, RunResult, WpmExport
from traceability.provenance import swtlab_version
from traceability.store import new_processing_record

GROUP_COLUMNS = ("wheel", "soil", "multipass", "load_n")
ROW_ID = "result_id"


def _group_rows(table: pd.DataFrame, fit: Any) -> pd.DataFrame:
    """Rows of ``table`` in the fit's (wheel, soil, multipass, load) group with a value."""
    rows = table[(table["wheel"] == fit.wheel) & (table["soil"] == fit.soil)
                 & (table["multipass"] == fit.multipass) & (table["load_n"] == fit.load_n)]
    source = "dp_n" if fit.quantity == "dp_over_w" else fit.quantity
    return rows[rows[source].notna() & rows["slip"].notna()]


def _fit_sha256(result_ids: list[int], fit: Any, options: dict[str, Any]) -> str:
    """Same run results (immutable rows), same quantity and options: the same fit."""
    payload = {"swtlab": swtlab_version(), "quantity": fit.quantity, "options": options,
               "group": [fit.wheel, fit.soil, int(fit.multipass), float(fit.load_n)],
               "run_results": sorted(result_ids)}
    return hashlib.sha256(json.dumps(payload, sort_keys=True).encode()).hexdigest()


def store_fits(session: Session, table: pd.DataFrame, fits: list[Any],
               options: dict[str, Any]) -> list[CurveFit]:
    """Store each ``fitting.CurveFit`` (reusing an identical stored one) linked to its run results.

    ``table`` is the fitted results table (``fitting.from_run_results`` of
    ``latest_results``), whose ``result_id`` column names the run results.
    """
    record = None
    rows_out = []
    for fit in fits:
        result_ids = [int(i) for i in _group_rows(table, fit)[ROW_ID]]
        key = _fit_sha256(result_ids, fit, options)
        stored = session.scalars(select(CurveFit).filter_by(fit_sha256=key)).first()
        if stored is None:
            record = record or new_processing_record(session, "fit", options)
            d = jsonable(fit.to_dict())
            stored = CurveFit(
                fit_sha256=key, wheel=fit.wheel, soil=fit.soil, multipass=int(fit.multipass),
                load_n=float(fit.load_n), quantity=fit.quantity, unit=fit.unit,
                degree=fit.degree, coefficients=d["coefficients"], slip_min=fit.slip_min,
                slip_max=fit.slip_max, n_points=fit.n_points, rmse=fit.rmse,
                diagnostics={k: d[k] for k in ("r2", "loo_rmse", "condition_number",
                                               "degree_choice", "degree_scores", "weighting",
                                               "oscillates", "max_departure",
                                               "step_below_zero", "slope_below_zero",
                                               "step_se", "slope_se", "branch_choice",
                                               "branch_scores", "covariance", "scatter_sd",
                                               "k95") if k in d},
                processing=record,
                inputs=list(session.scalars(select(RunResult).where(
                    RunResult.id.in_(result_ids)))))
            session.add(stored)
        rows_out.append(stored)
    session.flush()
    return rows_out


def store_export(session: Session, path: Path, file_sha256: str, inputs_sha256: str,
                 format_version: str, fits: list[CurveFit], options: dict[str, Any]) -> WpmExport:
    """Record one written WPM CSV and the stored fits it holds."""
    export = WpmExport(path=str(Path(path).resolve()), file_sha256=file_sha256,
                       inputs_sha256=inputs_sha256, format_version=format_version,
                       processing=new_processing_record(session, "export", options), fits=fits)
    session.add(export)
    session.flush()
    return export
