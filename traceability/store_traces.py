"""Persist a run result's decimated channel traces (``run_results.traces``), and read them
back: what the report's time series draw instead of the raw file."""

from __future__ import annotations

import io
from collections.abc import Iterable, Mapping
from typing import Any

import numpy as np
from sqlalchemy import select
from sqlalchemy.orm import Session

from traceability.models import RunResult, RunTrace


def pack_arrays(t_s: np.ndarray, values: np.ndarray) -> bytes:
    """Compressed npz bytes of ``t_s`` (float64) and ``values`` (float32)."""
    out = io.BytesIO()
    np.savez_compressed(out, t_s=np.asarray(t_s, np.float64),
                        values=np.asarray(values, np.float32))
    return out.getvalue()


def unpack_arrays(blob: bytes) -> tuple[np.ndarray, np.ndarray]:
    """``(t_s, values)`` of :func:`pack_arrays` bytes."""
    with np.load(io.BytesIO(blob), allow_pickle=False) as arrays:
        return arrays["t_s"], arrays["values"]


def store_traces(session: Session, result: RunResult, traces: Mapping[str, Any]) -> None:
    """Store ``traces`` (channel -> ``run_results.traces.Trace``) with ``result``."""
    for channel, trace in traces.items():
        session.add(RunTrace(result=result, channel=channel, unit=trace.unit,
                             samples=trace.samples, block=trace.block, points=len(trace.t_s),
                             arrays=pack_arrays(trace.t_s, trace.values)))
    session.flush()


def traces_of(session: Session, result_ids: Iterable[int]) -> dict[int, list[RunTrace]]:
    """The stored traces of each result id that has any (results processed before the
    traces were stored, migration 0006, have none and are absent)."""
    out: dict[int, list[RunTrace]] = {}
    ids = [int(i) for i in result_ids]
    if not ids:
        return out
    for row in session.scalars(select(RunTrace).where(RunTrace.run_result_id.in_(ids))
                               .order_by(RunTrace.id)):
        out.setdefault(row.run_result_id, []).append(row)
    return out
