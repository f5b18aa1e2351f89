"""Everything a campaign page shows, gathered from the database into plain objects.

One :class:`CampaignData` per campaign: its runs (conditions, status, flags, stable window,
where the raw file is, the stored DP trace of runs with no stable phase), the results table
the fits read, the curves (those of the newest WPM export that holds the campaign's runs,
else fitted here with :mod:`fitting`), and the load-interpolation checks.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass, field
from datetime import datetime

import pandas as pd
from sqlalchemy import select
from sqlalchemy.orm import Session

from fitting import (CurveFit, FittingError, ValidationResult, fit_results, from_run_results,
                     validate_load_interpolation)
from ingest import IngestError, read_run
from traceability.models import Campaign, ProcessingRecord, RawFile, Run, RunResult, WpmExport
from traceability.queries import latest_results

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
    raw_path: str
    channel_map: str | None
    dp_trace: dict | None
    means: dict[str, float] = field(default_factory=dict)


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
    """A campaign's runs, results table, curves and interpolation checks."""

    name: str
    runs: list[RunRecord]
    points: pd.DataFrame  # fitting columns (load_n, slip, dp_n, dp_n_se, ...) + status, run_id
    fits: list[CurveFit]
    source: CurveSource
    validation: dict[SetKey, tuple[float, list[ValidationResult]]]

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


def _run_records(session: Session, results: pd.DataFrame) -> list[RunRecord]:
    ids = [int(i) for i in results["result_id"]]
    extra = {row.id: row for row in session.execute(
        select(RunResult.id, RunResult.dp_trace, RunResult.flags, ProcessingRecord.parameters)
        .join(ProcessingRecord, ProcessingRecord.id == RunResult.processing_id)
        .where(RunResult.id.in_(ids)))}
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
            window_end_s=_none_if_nan(row["window_end_s"]), raw_path=row["raw_file_path"],
            channel_map=(more.parameters or {}).get("channel_map"), dp_trace=more.dp_trace,
            means={c.removesuffix("_mean"): v for c in means
                   if (v := _none_if_nan(row[c])) is not None}))
    return runs


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
            max_departure=d["max_departure"]))
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


def gather(session: Session, name: str) -> CampaignData:
    """Everything the page of campaign ``name`` shows. Raises ``LookupError`` when the
    database has no processed run of that campaign."""
    campaign = session.scalars(select(Campaign).filter_by(name=name)).first()
    results = latest_results(session)
    results = results[results["campaign"] == name] if len(results) else results
    if campaign is None or results.empty:
        raise LookupError(f"no processed runs of campaign {name!r}")
    results = results.reset_index(drop=True)
    fits, source = _curves(session, campaign.id, results)
    points = from_run_results(results, statuses=("ok", "flagged"))
    return CampaignData(name=name, runs=_run_records(session, results), points=points,
                        fits=fits, source=source,
                        validation=_validation(points, fits, source))


def read_channels(run: RunRecord) -> tuple[pd.DataFrame | None, str | None]:
    """The run's channel table read again from its recorded raw file (with the channel map it
    was processed with), or None and the one-line reason when that file cannot be read."""
    try:
        return read_run(run.raw_path, run.channel_map).channels, None
    except (IngestError, OSError, ValueError) as error:
        return None, f"raw file {run.raw_path} not readable: {error}"
