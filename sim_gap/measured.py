"""The measured side: one row per run (or curve sample) with its conditions, slip and each
quantity's mean and standard error.

Columns: ``run_id``, ``source`` (the campaign or curve set the row comes from), the wheel of
its source (``wheel_radius_m``, ``wheel_width_m``, ``grouser_count``, ``grouser_height_m``),
``load_set_n`` (set load: grouping), ``wheel_load_n`` (measured wheel load, used in the
model), ``multipass``, ``gravity_mps2``, ``slip`` and ``<q>``, ``<q>_se`` for the
quantities of :data:`sim_gap.vocabulary.QUANTITIES` that the source has, and
``<q>_repeat_sd`` where the source measured its repeatability (:func:`sim_gap.fit.sigmas`);
``velocity_set_mps`` (set travel velocity) and ``started_unix_h`` where the runs' set
velocities and start times are known (hours since 1970-01-01 UTC; only
differences between runs are used, also between sources).
``attrs``:
``source`` (text), ``wheels`` (source -> its :class:`swtlab_base.domain.Wheel`), ``wheel`` (the
one measured wheel, None when the sources have several), ``sinkage_relative`` (True when
only sinkage differences are known, e.g. a hub height without an absolute zero).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd

from fitting.polynomial import curve_value
from fitting.table import from_run_results
from sim_gap.points_csv import WHEEL_KEY, is_points_csv, read_points_csv, wheel_of
from sim_gap.vocabulary import QUANTITIES
from swtlab_base.domain import G0_MPS2, Wheel, check_results, wheels_of
from swtlab_base.domain.replicates import replicate_spread
from wpm_export import WheelPerformanceModule

#: the wheel of the CMU smooth runs: the shipped channel map's swt.wheel
CMU_CHANNEL_MAP = "cmu_3d_terramechanics"

#: slip grid on which WPM curves are sampled (inside each curve's range)
WPM_SLIP_POINTS = 9


def _finish(table: pd.DataFrame, source: str, wheel: Wheel,
            sinkage_relative: bool = False) -> pd.DataFrame:
    table = table.assign(source=source, **{c: getattr(wheel, c[6:] if c.startswith("wheel_")
                                                      else c) for c in WHEEL_KEY})
    cols = ["run_id", "source", *WHEEL_KEY, "load_set_n", "wheel_load_n", "multipass",
            "gravity_mps2", "slip"] + [c for c in ("velocity_set_mps", "started_unix_h")
                                       if c in table]
    for q in QUANTITIES:
        if q in table and table[q].notna().any():
            cols += [q, f"{q}_se"] + ([f"{q}_repeat_sd"] if f"{q}_repeat_sd" in table else [])
    out = table[cols].reset_index(drop=True)
    out["multipass"] = out["multipass"].astype(int)
    out.attrs.update(source=source, wheel=wheel, wheels={source: wheel},
                     sinkage_relative=sinkage_relative)
    return out


def combine(parts: list[pd.DataFrame]) -> pd.DataFrame:
    """Measured points of several sources (e.g. a smooth and a grousered wheel on the same
    prepared soil, or multipass and gravity series stored apart) as one table: the rows keep
    their source and its wheel; ``attrs['wheel']`` is the common wheel, None when the
    sources' wheels differ (docs/gap-report.md, "Several sources")."""
    if len(parts) == 1:
        return parts[0]
    wheels: dict[str, Wheel] = {}
    for part in parts:
        for name, wheel in part.attrs["wheels"].items():
            if name in wheels:
                raise ValueError(f"measured source {name!r} given twice; each source once")
            wheels[name] = wheel
    if any(part.attrs.get("sinkage_relative") for part in parts):
        relative = [p.attrs["source"] for p in parts if p.attrs.get("sinkage_relative")]
        raise ValueError(f"{', '.join(relative)}: a relative sinkage (unknown zero) cannot be "
                         "combined with other sources; diagnose it alone")
    out = pd.concat(parts, ignore_index=True)
    if out["run_id"].duplicated().any():
        out["run_id"] = out["source"].astype(str) + ":" + out["run_id"].astype(str)
    first = next(iter(wheels.values()))
    common = all(not w.mismatches(first) for w in wheels.values())
    out.attrs.update(source=" + ".join(p.attrs["source"] for p in parts),
                     wheel=first if common else None, wheels=wheels, sinkage_relative=False)
    return out


def from_points_csv(path: str | Path) -> pd.DataFrame:
    """The measured points of a points CSV (docs/points-csv.md), each of its sources with
    its own wheel."""
    table = read_points_csv(path)
    parts = [_finish(rows, str(name), wheel_of(rows.iloc[0]))
             for name, rows in table.groupby("source", sort=False)]
    return combine(parts)


def _one_wheel(wheels: dict[str, Wheel], source: str) -> Wheel:
    if len(wheels) != 1:
        raise ValueError(f"{source}: measured runs of {len(wheels)} wheels {sorted(wheels)}; "
                         "diagnose one wheel at a time")
    return next(iter(wheels.values()))


def from_results_table(results: pd.DataFrame, source: str = "results") -> pd.DataFrame:
    """Measured points from the table of ``latest_results`` / ``swtlab results`` (runs with
    status ``ok``, speed control, free sled or towed; docs/results.md). A run without a
    measured load is modelled at its set load."""
    table = from_run_results(check_results(results)) if len(results) else results
    table = table.assign(**pooled_repeatability(results)) if len(table) else table
    table = table.dropna(subset=["slip"]) if len(table) else table
    if table.empty:
        raise ValueError(f"{source}: no processed run with status ok")
    set_load = table["load_n"].astype(float)
    measured = table["wheel_load_n"] if "wheel_load_n" in table else set_load
    table = table.assign(load_set_n=set_load,
                         wheel_load_n=measured.astype(float).fillna(set_load))
    if "started_at" in table:
        table = table.assign(started_unix_h=unix_hours(table["started_at"]))
    return _finish(table, source, _one_wheel(wheels_of(table), source))


def unix_hours(started_at: pd.Series) -> np.ndarray:
    """Hours since 1970-01-01 UTC of ISO 8601 start times (as ``swtlab results`` gives them;
    a time without a zone is taken as UTC); NaN where a time is missing."""
    times = pd.to_datetime(started_at, utc=True, errors="coerce", format="ISO8601")
    return ((times - pd.Timestamp(0, tz="UTC")).dt.total_seconds() / 3600.0).to_numpy(float)


def pooled_repeatability(results: pd.DataFrame) -> dict[str, float]:
    """``<q>_repeat_sd``: the pooled standard deviation of the replicate runs of
    ``results`` per quantity, ``sqrt(sum (n_i - 1) s_i^2 / sum (n_i - 1))`` over its
    conditions with replicates (ISO 5725-2 repeatability); none without replicates."""
    spread = replicate_spread(results, QUANTITIES)
    out = {}
    for q, rows in spread.groupby("quantity") if len(spread) else ():
        dof = rows["runs"].to_numpy(float) - 1.0
        out[f"{q}_repeat_sd"] = float(np.sqrt(np.sum(dof * rows["replicate_sd"] ** 2)
                                              / np.sum(dof)))
    return out


def from_database(url: str) -> pd.DataFrame:
    """Measured points of every processed run in the swtlab database at ``url``."""
    from traceability import open_database
    from traceability.queries import latest_results

    with open_database(url, read_only=True)() as session:
        return from_results_table(latest_results(session), source=url)


def from_wpm(wpm: WheelPerformanceModule, gravity_mps2: float | None = None) -> pd.DataFrame:
    """Points sampled from WPM curves: each (soil, wheel, multipass, load) curve set at
    :data:`WPM_SLIP_POINTS` slips over its range; the curve's RMSE is the uncertainty.
    Gravity: ``gravity_mps2``, else the header key ``gravity_mps2``, else standard. The file
    must carry its wheel's geometry (one wheel)."""
    names = sorted({wheel for _, wheel, _ in wpm.sets()})
    if len(names) != 1:
        raise ValueError(f"{wpm.source}: curves of {len(names)} wheels {names}; diagnose one "
                         "wheel at a time")
    wheel = wpm.wheel(names[0], needed_for="the gap diagnosis")
    g = gravity_mps2 or float(wpm.header.get("gravity_mps2", G0_MPS2))
    rows = []
    for soil, name, mp in wpm.sets():
        by_q = wpm._sets[(soil, name, mp)]  # the reader's own index
        for load in sorted({load for curves in by_q.values() for load in curves}):
            curves = {q: by_q[q][load] for q in QUANTITIES if load in by_q.get(q, {})}
            lo = max(c.slip_min for c in curves.values())
            hi = min(c.slip_max for c in curves.values())
            for i, s in enumerate(np.linspace(lo, hi, WPM_SLIP_POINTS)):
                row = {"run_id": f"{soil}/{name}/mp{mp}/{load:g}N/{i}", "load_set_n": load,
                       "wheel_load_n": load, "multipass": mp, "gravity_mps2": g, "slip": s}
                for q, c in curves.items():
                    row[q] = float(curve_value(c.coefficients, s, c.step_below_zero,
                                               c.slope_below_zero))
                    row[f"{q}_se"] = max(c.rmse, 1e-9)
                rows.append(row)
    return _finish(pd.DataFrame(rows), wpm.source, wheel)


def from_wpm_csv(path: str | Path, gravity_mps2: float | None = None) -> pd.DataFrame:
    return from_wpm(WheelPerformanceModule.load(path), gravity_mps2)


def from_cmu_smooth_runs(path: str | Path) -> pd.DataFrame:
    """The CMU 3d-terramechanics ``smooth_runs.csv`` (Pavlov, CMU; see its README): the
    straight-driving rows (slip angle 0). Drawbar pull = ``tractive_force_n``, load =
    ``wheel_load_n``, sinkage = minus the hub height (``-hub_z_mm``/1000) and therefore
    **relative** (unknown zero; the diagnosis profiles out its offset).

    Noise is measured, not assumed: the file holds replicate runs of each set slip (two or
    three trials at the same wheel and carriage speeds), whose spread, pooled over the
    conditions (:func:`pooled_spread`, ISO 5725-2 repeatability), is each quantity's
    ``<q>_repeat_sd``. The file's per-run standard deviations are the spread of the samples in
    the 70-75 s window, not the standard error of the run's mean (the samples are strongly
    autocorrelated, and they vary with the wheel's rotation): they are not used, and
    ``<q>_se`` is NaN (unknown), so the repeatability alone is the points' noise
    (:func:`sim_gap.fit.sigmas`). The wheel is the one of the shipped channel map of those
    logs (``cmu_3d_terramechanics``)."""
    from ingest import load_channel_map

    raw = pd.read_csv(path)
    raw = raw[raw["slip_angle_deg"] == 0].reset_index(drop=True)
    table = pd.DataFrame({
        "run_id": raw["run_file"].astype(str), "load_set_n": raw["wheel_load_n"].mean(),
        "wheel_load_n": raw["wheel_load_n"], "multipass": 0, "gravity_mps2": G0_MPS2,
        "slip": raw["slip"], "dp_n": raw["tractive_force_n"], "dp_n_se": np.nan,
        "sinkage_m": -raw["hub_z_mm"] / 1000.0, "sinkage_m_se": np.nan})
    condition = raw["wheel_surface_speed_mm_s"].round(0).to_numpy()
    for q in ("dp_n", "sinkage_m"):
        table[f"{q}_repeat_sd"] = pooled_spread(table[q].to_numpy(float), condition)
    defaults = load_channel_map(CMU_CHANNEL_MAP).metadata_defaults
    wheel = Wheel(name=defaults["run"]["wheel"], **defaults["wheel"])
    return _finish(table, str(path), wheel, sinkage_relative=True)


def pooled_spread(values: np.ndarray, condition: np.ndarray) -> float:
    """Pooled standard deviation of ``values`` over the groups of equal ``condition`` with
    two or more members, ``sqrt(sum (n_i - 1) s_i^2 / sum (n_i - 1))`` (ISO 5725-2)."""
    frame = pd.DataFrame({"v": values, "c": condition})
    groups = frame.groupby("c")["v"]
    dof = groups.count() - 1
    keep = dof > 0
    if not keep.any():
        raise ValueError("no condition has replicate runs")
    return float(np.sqrt(np.sum(dof[keep] * groups.var(ddof=1)[keep]) / np.sum(dof[keep])))


#: the first bytes of every SQLite database file
SQLITE_MAGIC = b"SQLite format 3\x00"


def is_database(source: str) -> bool:
    """Whether ``source`` names a database: a URL (``scheme://...``) or a SQLite file."""
    if "://" in source:
        return True
    try:
        with open(source, "rb") as stream:
            return stream.read(len(SQLITE_MAGIC)) == SQLITE_MAGIC
    except OSError:
        return False


def load_measured(source: str) -> pd.DataFrame:
    """A database URL (``scheme://...``) or SQLite file, a WPM CSV, a points CSV or a CMU
    ``smooth_runs.csv``."""
    if is_database(source):
        return from_database(source)
    path = Path(source)
    if not path.exists():
        raise FileNotFoundError(f"{source}: no such file (expected a database URL or a CSV)")
    head = path.read_text(encoding="utf-8-sig")[:2000]
    if head.startswith("# format:"):
        return from_wpm_csv(path)
    if is_points_csv(path):
        return from_points_csv(path)
    if "tractive_force_n" in head.splitlines()[0]:
        return from_cmu_smooth_runs(path)
    raise ValueError(f"{source}: neither a WPM CSV, a points CSV (docs/points-csv.md) nor a "
                     "CMU smooth_runs.csv")
