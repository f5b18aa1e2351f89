"""Everything a campaign page shows, as one plain object: :class:`CampaignData`.

It comes from the database (:func:`gather`) or straight from in-memory pipeline results
(:func:`from_results`); the page is drawn from it alone. One :class:`CampaignData` per
campaign: its runs (conditions, status, flags, stable window, the decimated traces stored at
processing, the DP trace of runs with no stable phase), the one-row-per-run results table,
the curves (those of the newest WPM export that holds the campaign's runs, else fitted here
with :mod:`fitting`), the load-interpolation checks, and the data of the optional sections
(:mod:`campaign_report.extensions`). No raw file is read.
"""

from __future__ import annotations

import os
import warnings
from dataclasses import dataclass, field
from datetime import datetime
from pathlib import Path
from typing import Any

import pandas as pd
from sqlalchemy import select
from sqlalchemy.engine import make_url
from sqlalchemy.orm import Session

from campaign_report.extensions import gather_extras
from fitting import (CurveFit, FittingError, ValidationResult, fit_results, from_run_results,
                     validate_load_interpolation)
from run_results import RunResult as ProcessedRun
from run_results import results_table
from run_results.traces import Trace
from traceability.models import Campaign, RawFile, Run, RunResult, WpmExport
from traceability.queries import latest_results
from traceability.store_traces import traces_of, unpack_arrays

#: statuses whose runs the curves are fitted from when no export says otherwise
DEFAULT_STATUSES = ("ok",)
#: degree choice of the curves fitted here when no export exists (as ``swtlab export``)
DEFAULT_DEGREE = "loo"
SetKey = tuple[str, str, int]  # (wheel, soil, multipass)


@dataclass(frozen=True)
class RunRecord:
    """One run as the page lists it (the newest result of its newest raw-file version)."""

    run_id: str
    wheel: str
    soil: str
    mode: str
    multipass: int
    load_n: float
    slip_setpoint: float | None
    velocity_mps: float
    status: str
    flags: tuple[str, ...]
    window_start_s: float | None
    window_end_s: float | None
    dp_trace: dict | None
    traces: dict[str, Trace] | None  # None: not stored (processed before migration 0006)
    means: dict[str, float] = field(default_factory=dict)
    #: quantity -> combined standard uncertainty of the mean (the run's budget, GUM)
    u: dict[str, float] = field(default_factory=dict)
    #: quantity -> 95 % expanded uncertainty of the mean (the run's budget)
    u95: dict[str, float] = field(default_factory=dict)
    #: quantity -> the re-zeroing correction the budget added to the mean (the zero at the
    #: rests, at the window's middle; the stored traces are before it)
    corrections: dict[str, float] = field(default_factory=dict)

    @classmethod
    def from_result(cls, result: ProcessedRun) -> RunRecord:
        """The record of an in-memory ``run_results.RunResult`` (``process_run``)."""
        c, w = result.condition, result.window
        return cls(run_id=result.run_id, wheel=result.wheel.name, soil=result.soil,
                   mode=c.mode, multipass=c.multipass, load_n=float(c.load_set_n),
                   slip_setpoint=_none_if_nan(c.slip_setpoint),
                   velocity_mps=float(c.velocity_set_mps), status=result.status,
                   flags=tuple(result.flags),
                   window_start_s=_none_if_nan(w.start_s) if w.found else None,
                   window_end_s=_none_if_nan(w.end_s) if w.found else None,
                   dp_trace=result.dp_trace, traces=dict(result.traces),
                   means={k: float(q.mean) for k, q in result.quantities.items()
                          if _none_if_nan(q.mean) is not None},
                   u={k: float(b.u) for k, b in result.uncertainty.items()
                      if _none_if_nan(b.u) is not None},
                   u95={k: float(b.u95) for k, b in result.uncertainty.items()
                        if _none_if_nan(b.u95) is not None},
                   corrections={k: float(b.correction) for k, b in result.uncertainty.items()
                                if _none_if_nan(b.correction) is not None})


@dataclass(frozen=True)
class CurveSource:
    """Where the curves come from: a WPM export (path, hashes, time, options) or a fit here."""

    export_path: str | None
    file_sha256: str | None
    created_at: datetime | None
    degree: int | str
    statuses: tuple[str, ...]
    stale: bool  # the export was fitted from results older than the newest ones

    @property
    def exported(self) -> bool:
        return self.export_path is not None


@dataclass
class CampaignData:
    """A campaign's runs, results table, curves, interpolation checks and optional data.

    ``results``: one row per run (docs/results.md columns); ``points``: the same in the
    fitting columns (load_n, slip, dp_n, dp_n_se, ...); ``provenance``: (label, value) of
    where the data comes from, printed in the page header; ``extras``: optional section name
    -> its data (:mod:`campaign_report.extensions`)."""

    name: str
    runs: list[RunRecord]
    results: pd.DataFrame
    points: pd.DataFrame
    fits: list[CurveFit]
    source: CurveSource
    validation: dict[SetKey, tuple[float, list[ValidationResult]]]
    provenance: tuple[str, str]
    extras: dict[str, Any] = field(default_factory=dict)
    #: runs of the campaign's folder that failed: (run id or file name, stage, reason)
    failed: list[tuple[str, str, str]] = field(default_factory=list)

    @property
    def loads(self) -> list[float]:
        return sorted({r.load_n for r in self.runs})

    @property
    def multipasses(self) -> list[int]:
        return sorted({r.multipass for r in self.runs})

    def sets(self) -> list[SetKey]:
        """(wheel, soil, multipass) sets that have curves."""
        return sorted({(f.wheel, f.soil, f.multipass) for f in self.fits})

    def unfitted_groups(self) -> list[tuple[SetKey, float, int]]:
        """(set, load, number of distinct slips) of groups with usable runs but no curve."""
        fitted = {(f.wheel, f.soil, f.multipass, f.load_n) for f in self.fits}
        used = self.points[self.points["status"].isin(self.source.statuses)]
        out = []
        for (w, s, mp, load), rows in used.groupby(["wheel", "soil", "multipass", "load_n"]):
            if (w, s, int(mp), float(load)) not in fitted:
                out.append(((w, s, int(mp)), float(load), int(rows["slip"].nunique())))
        return out


def campaign_names(session: Session) -> list[str]:
    """Names of the campaigns that have processed runs, sorted."""
    return sorted(set(session.scalars(select(Campaign.name).join(Run, Run.campaign_id
                                                                  == Campaign.id))))


def _none_if_nan(value) -> float | None:
    return None if value is None or pd.isna(value) else float(value)


def _stored_traces(session: Session, ids: list[int]) -> dict[int, dict[str, Trace]]:
    out = {}
    for result_id, rows in traces_of(session, ids).items():
        out[result_id] = {}
        for row in rows:
            t_s, values = unpack_arrays(row.arrays)
            out[result_id][row.channel] = Trace(t_s=t_s, values=values, unit=row.unit,
                                                samples=row.samples, block=row.block)
    return out


def _run_records(session: Session, results: pd.DataFrame) -> list[RunRecord]:
    ids = [int(i) for i in results["result_id"]]
    extra = {row.id: row for row in session.execute(
        select(RunResult.id, RunResult.dp_trace, RunResult.flags).where(RunResult.id.in_(ids)))}
    traces = _stored_traces(session, ids)
    means = [c for c in results.columns if c.endswith("_mean")]
    runs = []
    for row in results.to_dict("records"):
        more = extra[int(row["result_id"])]
        runs.append(RunRecord(
            run_id=row["run_id"], wheel=row["wheel"], soil=row["soil"], mode=row["mode"],
            multipass=int(row["multipass"]), load_n=float(row["load_set_n"]),
            slip_setpoint=_none_if_nan(row["slip_setpoint"]),
            velocity_mps=float(row["velocity_set_mps"]), status=row["status"],
            flags=tuple(more.flags), window_start_s=_none_if_nan(row["window_start_s"]),
            window_end_s=_none_if_nan(row["window_end_s"]), dp_trace=more.dp_trace,
            traces=traces.get(int(row["result_id"])),
            means={c.removesuffix("_mean"): v for c in means
                   if (v := _none_if_nan(row[c])) is not None},
            u={c.removesuffix("_u"): v for c in row
               if c.endswith("_u") and (v := _none_if_nan(row[c])) is not None},
            u95={c.removesuffix("_u95"): v for c in row
                 if c.endswith("_u95") and (v := _none_if_nan(row[c])) is not None},
            corrections={c.removesuffix("_correction"): v for c in row
                         if c.endswith("_correction")
                         and (v := _none_if_nan(row[c])) is not None}))
    return runs


def _stored_float(value) -> float:
    """A number of a stored fit's diagnostics (strict JSON keeps NaN as null: unknown)."""
    return float("nan") if value is None else float(value)


def _from_export(row, latest_ids: set[int], campaign_ids: set[int]
                 ) -> tuple[list[CurveFit], CurveSource] | None:
    """The export's fits of this campaign as ``fitting.CurveFit``; None if it has none."""
    mine = [f for f in row.fits if any(r.id in campaign_ids for r in f.inputs)]
    if not mine:
        return None
    fits = []
    for f in mine:
        d = f.diagnostics
        fits.append(CurveFit(
            coefficients=tuple(float(a) for a in f.coefficients), slip_min=f.slip_min,
            slip_max=f.slip_max, quantity=f.quantity, unit=f.unit, wheel=f.wheel, soil=f.soil,
            multipass=f.multipass, load_n=f.load_n, n_points=f.n_points, rmse=f.rmse,
            r2=d["r2"], loo_rmse=d["loo_rmse"], condition_number=d["condition_number"],
            degree_choice=d["degree_choice"],
            degree_scores=tuple((int(k), v) for k, v in d["degree_scores"].items()),
            weighting=d["weighting"], oscillates=d["oscillates"],
            max_departure=d["max_departure"],
            step_below_zero=d.get("step_below_zero", 0.0),  # stored fits before the branch: 0
            slope_below_zero=d.get("slope_below_zero", 0.0),
            # the bands' inputs where the store keeps them (else unknown: no band)
            covariance=None if d.get("covariance") is None
            else tuple(tuple(_stored_float(v) for v in row) for row in d["covariance"]),
            scatter_sd=_stored_float(d.get("scatter_sd")), k95=_stored_float(d.get("k95"))))
    options = row.processing.parameters or {}
    stale = any(r.id not in latest_ids for f in mine for r in f.inputs)
    source = CurveSource(export_path=row.path, file_sha256=row.file_sha256,
                         created_at=row.processing.created_at,
                         degree=options.get("degree", DEFAULT_DEGREE),
                         statuses=tuple(options.get("statuses", DEFAULT_STATUSES)), stale=stale)
    return sorted(fits, key=lambda f: (f.wheel, f.soil, f.multipass, f.load_n)), source


def _curves(session: Session, campaign_id: int, results: pd.DataFrame
            ) -> tuple[list[CurveFit], CurveSource]:
    """Curves of the newest export holding this campaign's runs, else fitted here."""
    campaign_ids = set(session.scalars(
        select(RunResult.id).join(RawFile, RawFile.id == RunResult.raw_file_id)
        .join(Run, Run.id == RawFile.run_pk).where(Run.campaign_id == campaign_id)))
    latest_ids = {int(i) for i in results["result_id"]}
    for row in session.scalars(select(WpmExport).order_by(WpmExport.id.desc())):
        found = _from_export(row, latest_ids, campaign_ids)
        if found:
            return found
    return _fitted_here(results)


def _fitted_here(results: pd.DataFrame) -> tuple[list[CurveFit], CurveSource]:
    """Curves fitted as ``swtlab export`` would, when no export holds the campaign's runs."""
    table = from_run_results(results, statuses=DEFAULT_STATUSES)
    fits = fit_results(table, degree=DEFAULT_DEGREE, too_few=[]) if len(table) else []
    return fits, CurveSource(None, None, None, DEFAULT_DEGREE, DEFAULT_STATUSES, stale=False)


def validation_loads(points: pd.DataFrame, fits: list[CurveFit], key: SetKey) -> list[float]:
    """Loads of a (wheel, soil, multipass) set that have runs but no curve and lie strictly
    between loads with curves: the runs kept aside to check the load interpolation."""
    fitted = sorted({f.load_n for f in fits if (f.wheel, f.soil, f.multipass) == key})
    mine = points[(points["wheel"] == key[0]) & (points["soil"] == key[1])
                  & (points["multipass"] == key[2])]
    return sorted(load for load in set(mine["load_n"].astype(float))
                  if load not in fitted and len(fitted) >= 2 and fitted[0] < load < fitted[-1])


def _validation(points: pd.DataFrame, fits: list[CurveFit], source: CurveSource
                ) -> dict[SetKey, tuple[float, list[ValidationResult]]]:
    used = points[points["status"].isin(source.statuses)]
    out = {}
    for key in sorted({(f.wheel, f.soil, f.multipass) for f in fits}):
        loads = validation_loads(used, fits, key)
        if not loads:
            continue
        table = used[(used["wheel"] == key[0]) & (used["soil"] == key[1])
                     & (used["multipass"] == key[2])]
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            try:
                out[key] = (loads[0], validate_load_interpolation(table, loads[0],
                                                                  degree=source.degree))
            except FittingError:
                continue
    return out


def campaign_data(name: str, results: pd.DataFrame, runs: list[RunRecord],
                  curves: tuple[list[CurveFit], CurveSource] | None = None,
                  provenance: tuple[str, str] = ("source", "in-memory results"),
                  extras: dict[str, Any] | None = None) -> CampaignData:
    """A page's data from a one-row-per-run ``results`` table and the runs' records;
    ``curves`` (fits and where they come from) default to fits made here."""
    if results.empty:
        raise LookupError(f"no processed runs of campaign {name!r}")
    results = results.reset_index(drop=True)
    fits, source = curves if curves is not None else _fitted_here(results)
    points = from_run_results(results, statuses=("ok", "flagged"))
    return CampaignData(name=name, runs=runs, results=results, points=points, fits=fits,
                        source=source, validation=_validation(points, fits, source),
                        provenance=provenance, extras=dict(extras or {}))


def from_results(name: str, results: list[ProcessedRun],
                 provenance: tuple[str, str] = ("source", "in-memory pipeline results"),
                 extras: dict[str, Any] | None = None) -> CampaignData:
    """A page's data straight from ``process_run`` results, without a database (curves
    fitted here; ``extras``: optional sections' data, e.g. none)."""
    return campaign_data(name, results_table(results),
                         [RunRecord.from_result(r) for r in results], provenance=provenance,
                         extras=extras)


def gather(session: Session, name: str, db_url: str | None = None) -> CampaignData:
    """Everything the page of campaign ``name`` shows, from the database (``db_url`` is
    printed, password hidden). Raises ``LookupError`` when the database has no processed
    run of that campaign."""
    campaign = session.scalars(select(Campaign).filter_by(name=name)).first()
    results = latest_results(session)
    results = results[results["campaign"] == name] if len(results) else results
    if campaign is None or results.empty:
        raise LookupError(f"no processed runs of campaign {name!r}")
    results = results.reset_index(drop=True)
    where = make_url(db_url).render_as_string(hide_password=True) if db_url else "?"
    data = campaign_data(name, results, _run_records(session, results),
                         curves=_curves(session, campaign.id, results),
                         provenance=("database", where))
    data.extras = gather_extras(session, data)
    data.failed = failed_runs(session, results)
    return data


def failed_runs(session: Session, results: pd.DataFrame) -> list[tuple[str, str, str]]:
    """The failed runs (newest outcome a failure) whose file lies in the campaign's folder
    (the folder holding all its raw files): (run id or file name, stage, reason)."""
    from traceability.store_failures import current_failures

    folders = {str(Path(p).parent) for p in results["raw_file_path"]}
    root = Path(os.path.commonpath(sorted(folders))) if folders else None
    return [(f.run_id or Path(f.path).name, f.stage, f.error) for f in current_failures(session)
            if root is not None and Path(f.path).is_relative_to(root)]
