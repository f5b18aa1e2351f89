"""Fit a results table: one row per run, one curve per (wheel, soil, multipass, load) group
and quantity (docs/fitting.md gives the columns)."""

from __future__ import annotations

from collections.abc import Iterable

import numpy as np
import pandas as pd

from fitting.curve import QUANTITY_UNITS, CurveFit
from fitting.errors import FittingError, TooFewPointsError
from fitting.fit import check_degree, fit_curve
from swtlab_base.domain.replicates import fit_sigma

KEY_COLUMNS = ("wheel", "soil", "multipass", "load_n")
MEASURED = ("dp_n", "torque_nm", "sinkage_m", "resistance_n")

CurveSetKey = tuple[str, str, int, str]  # (wheel, soil, multipass, quantity)


def from_run_results(results: pd.DataFrame, statuses: Iterable[str] = ("ok",)) -> pd.DataFrame:
    """The table of ``swtlab results`` (docs/results.md: ``load_set_n``, ``<q>_mean``,
    ``<q>_se``) in the columns the fits read: ``load_n`` and ``<q>``/``<q>_se`` for slip,
    wheel load and the measured quantities; only runs whose ``status`` is in ``statuses``
    (default: ``ok``) and that are not steered. Other columns (``run_id``,
    ``raw_file_sha256`` ...) are kept for the trace. ``<q>_se`` becomes the fit's sigma of
    each run: the larger of its uncertainty (``<q>_u`` of the budget, else its SE) and the
    spread of its replicates (``swtlab_base.domain.replicates.fit_sigma``)."""
    keep = results["status"].isin(list(statuses))
    if "mode" in results:
        keep &= results["mode"] != "steered"
    out = results[keep]
    out = out.assign(**{f"{q}_se": fit_sigma(out, q) for q in ("slip", "wheel_load_n") + MEASURED
                        if f"{q}_se" in out or f"{q}_u" in out})
    out = out.rename(columns={"load_set_n": "load_n"})
    for q in ("slip", "wheel_load_n") + MEASURED:
        if f"{q}_mean" in out:
            out = out.rename(columns={f"{q}_mean": q})
    return out.reset_index(drop=True)


def with_dp_over_w(table: pd.DataFrame) -> pd.DataFrame:
    """``table`` plus ``dp_over_w = dp_n / wheel_load_n`` (measured load) and its SE
    (``dp_n_se / W``, with ``dp_n * wheel_load_n_se / W^2`` added in quadrature when given)."""
    if "dp_n" not in table or "wheel_load_n" not in table:
        return table
    w = table["wheel_load_n"].astype(float)
    out = table.assign(dp_over_w=table["dp_n"] / w)
    if "dp_n_se" in table:
        var = (table["dp_n_se"] / w) ** 2
        if "wheel_load_n_se" in table:
            var = var + (table["dp_n"] * table["wheel_load_n_se"] / w ** 2) ** 2
        out["dp_over_w_se"] = np.sqrt(var)
    return out


def quantities_in(table: pd.DataFrame) -> list[str]:
    """The quantities a table can give, in the WPM order."""
    return [q for q in QUANTITY_UNITS if q in with_dp_over_w(table)]


def fit_results(table: pd.DataFrame, degree: int | str = "loo",
                quantities: Iterable[str] | None = None,
                too_few: list[TooFewPointsError] | None = None,
                branch: int | str = "auto") -> list[CurveFit]:
    """One :class:`CurveFit` per (wheel, soil, multipass, load_n) group and quantity, sorted by
    group then quantity. Rows whose value (or slip) is NaN are left out of that quantity's fit.
    ``degree``: 3-7, ``"loo"`` or ``"aicc"``; ``branch``: braked-branch terms, ``"auto"``
    or 0-2 (:func:`fitting.fit.fit_curve`). Raises :class:`FittingError` subclasses naming
    the group and quantity (missing column, too few points, bad degree); with a ``too_few``
    list, a group with too few points for the degree is appended there and left out instead
    (e.g. a validation series that is not fitted itself)."""
    check_degree(degree)
    missing = [c for c in KEY_COLUMNS + ("slip",) if c not in table]
    if missing:
        raise FittingError(f"results table lacks column(s) {missing}")
    data = with_dp_over_w(table)
    wanted = quantities_in(table) if quantities is None else list(quantities)
    for q in wanted:
        if q not in QUANTITY_UNITS:
            raise FittingError(f"unknown quantity {q!r}; known: {list(QUANTITY_UNITS)}")
        if q not in data:
            raise FittingError(f"results table lacks column {q!r}"
                               + (" (needs dp_n and wheel_load_n)" if q == "dp_over_w" else ""))
    fits = []
    for (wheel, soil, multipass, load_n), group in data.groupby(list(KEY_COLUMNS), sort=True):
        for q in wanted:
            rows = group[np.isfinite(group[q].astype(float)) & np.isfinite(group["slip"])]
            try:
                fits.append(fit_curve(rows["slip"], rows[q],
                                      rows[f"{q}_se"] if f"{q}_se" in rows else None,
                                      degree=degree, branch=branch, quantity=q,
                                      wheel=str(wheel),
                                      soil=str(soil), multipass=int(multipass),
                                      load_n=float(load_n)))
            except TooFewPointsError as error:
                if too_few is None:
                    raise
                too_few.append(error)
    return fits


def curves_by_load(fits: Iterable[CurveFit]) -> dict[CurveSetKey, dict[float, CurveFit]]:
    """Fits arranged for load interpolation: (wheel, soil, multipass, quantity) -> load -> fit."""
    out: dict[CurveSetKey, dict[float, CurveFit]] = {}
    for f in fits:
        out.setdefault((f.wheel, f.soil, f.multipass, f.quantity), {})[f.load_n] = f
    return out
