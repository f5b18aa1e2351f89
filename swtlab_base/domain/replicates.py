"""Replicate runs: runs of one campaign table with the same test condition (wheel, soil,
mode, passes, set load, set slip, set velocity, gravity, steering). Their spread is the
run-to-run repeatability labs judge a campaign by (ISO 5725-1: repeatability conditions);
it is set beside each run's own uncertainty, and a fit's sigma for a run is the larger of
the two (:func:`fit_sigma`).
"""

from __future__ import annotations

from collections.abc import Iterable
from typing import TYPE_CHECKING

import numpy as np
import pandas as pd

from swtlab_base.domain.results import not_measured_text

if TYPE_CHECKING:
    from pandas.core.groupby import DataFrameGroupBy

#: the columns that make two runs replicates of one condition
REPLICATE_KEY = ("wheel", "soil", "mode", "multipass", "load_set_n", "slip_setpoint",
                 "velocity_set_mps", "gravity_mps2", "steer_deg")
QUANTITIES = ("slip", "dp_n", "torque_nm", "wheel_load_n", "sinkage_m", "resistance_n",
              "travel_velocity_mps")
NO_REPLICATES = ("no replicate runs (no two runs share a test condition): run-to-run "
                 "repeatability not measured; only the within-run uncertainty is known")


#: ``not_measured`` item of a run whose condition has no replicate in its table
SINGLE_RUN = ("run-to-run repeatability (one run of this condition: no replicate spread "
              "beside the within-run budget)")


def with_repeatability(table: pd.DataFrame) -> pd.DataFrame:
    """``table`` with :data:`SINGLE_RUN` added to the ``not_measured`` column of every run
    with a stable phase that no other run of the table replicates (:data:`REPLICATE_KEY`)."""
    groups = _groups(table)
    if groups is None or table.empty or "not_measured" not in table:
        return table
    size = groups["run_id"].transform("size").reindex(table.index)
    single = size.eq(1)
    out = table.copy()
    out.loc[single, "not_measured"] = [
        not_measured_text([*filter(None, str(v or "").split("; ")), SINGLE_RUN])
        for v in out.loc[single, "not_measured"]]
    return out


def _within_u(table: pd.DataFrame, quantity: str) -> pd.Series:
    """Each run's own standard uncertainty: ``<q>_u`` (the budget), else ``<q>_se``."""
    u = table.get(f"{quantity}_u")
    se = table.get(f"{quantity}_se")
    if u is None:
        return se.astype(float) if se is not None else pd.Series(np.nan, index=table.index)
    return u.astype(float).fillna(se.astype(float)) if se is not None else u.astype(float)


def _groups(table: pd.DataFrame) -> DataFrameGroupBy | None:
    """The runs with a stable phase grouped by condition; None when the table lacks a column
    of :data:`REPLICATE_KEY` (then no two runs can be told to be replicates)."""
    if any(c not in table for c in REPLICATE_KEY):
        return None
    usable = table[table["status"] != "no_stable_phase"] if "status" in table else table
    return usable.groupby(list(REPLICATE_KEY), dropna=False, sort=True)


def replicate_spread(table: pd.DataFrame, quantities: Iterable[str] = QUANTITIES
                     ) -> pd.DataFrame:
    """One row per (condition with >= 2 runs with a stable phase, quantity): the condition,
    ``runs``, ``run_ids``, ``mean`` of the runs' means, ``replicate_sd`` (their sample
    standard deviation), ``within_u`` (RMS of the runs' own uncertainties), ``ratio``
    (``replicate_sd / within_u``: about 1 when the budget holds what varies between runs) and
    ``larger`` (``replicates`` or ``within_run``). Empty: no replicates (:data:`NO_REPLICATES`)."""
    groups, key = _groups(table), list(REPLICATE_KEY)
    rows = []
    for values, group in groups if groups is not None else ():
        if len(group) < 2:
            continue
        for q in quantities:
            if f"{q}_mean" not in group:
                continue
            means = group[f"{q}_mean"].astype(float)
            ok = means.notna()
            if ok.sum() < 2:
                continue
            sd = float(means[ok].std(ddof=1))
            within = float(np.sqrt(np.nanmean(_within_u(group, q)[ok] ** 2)))
            rows.append({**dict(zip(key, values)),
                         "quantity": q, "runs": int(ok.sum()),
                         "run_ids": list(group.loc[ok, "run_id"]), "mean": float(means[ok].mean()),
                         "replicate_sd": sd, "within_u": within,
                         "ratio": sd / within if within > 0 else float("inf"),
                         "larger": "replicates" if sd > within else "within_run"})
    return pd.DataFrame(rows, columns=None if rows else [*key, "quantity", "runs", "run_ids",
                                                         "mean", "replicate_sd", "within_u",
                                                         "ratio", "larger"])


def fit_sigma(table: pd.DataFrame, quantity: str) -> pd.Series:
    """Each run's sigma for a fit: the larger of its own uncertainty and the replicate spread
    of its condition (the own uncertainty where the condition has no replicate)."""
    within = _within_u(table, quantity)
    groups = _groups(table)
    if f"{quantity}_mean" not in table or groups is None:
        return within
    spread = groups[f"{quantity}_mean"].transform(lambda m: m.astype(float).std(ddof=1))
    spread = spread.reindex(table.index)
    return pd.concat([within, spread], axis=1).max(axis=1, skipna=True).where(within.notna()
                                                                                | spread.notna())
