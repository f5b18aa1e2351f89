"""Check the load interpolation against runs at a load that was not used to make it.

RUAG WPAT validated its interpolation "by comparing the result of test data at a wheel load
of 120N with the data interpolation based on the measured load test": here the runs at
``validation_load_n`` are set aside, curves are fitted at the other loads, interpolated to
the validation load (:mod:`fitting.load_interp`) and compared with the set-aside means.
"""

from __future__ import annotations

import warnings
from dataclasses import asdict, dataclass

import numpy as np
import pandas as pd

from fitting.band import band
from fitting.errors import FittingError, OutsideSlipRangeWarning
from fitting.load_interp import interpolate_load
from fitting.table import KEY_COLUMNS, curves_by_load, fit_results, with_dp_over_w


@dataclass(frozen=True)
class ValidationResult:
    """Interpolated curve vs measurements of one quantity at the validation load.

    ``rmse`` over the validation points inside the interpolated curve's slip range (the
    others would be extrapolated in slip: counted in ``n_outside_slip_range``, included only in
    ``rmse_all``); ``rmse_pct_of_range`` = 100 x ``rmse`` / range of the measured values
    (for ``dp_n`` the literature's figure: % of the measured DP range).
    ``n_inside_band`` of the ``n_points - n_outside_slip_range`` points inside the slip range
    lie within the interpolated curve's 95 % prediction band (:func:`fitting.band.band`);
    ``fraction_inside_band`` is that share (NaN without points or without uncertainty).
    """

    wheel: str
    soil: str
    multipass: int
    quantity: str
    validation_load_n: float
    tested_loads_n: tuple[float, ...]
    method: str
    n_points: int
    n_outside_slip_range: int
    measured_range: float
    rmse: float
    rmse_pct_of_range: float
    max_abs_error: float
    rmse_all: float
    n_inside_band: int = 0
    fraction_inside_band: float = float("nan")

    def to_dict(self) -> dict:
        return asdict(self)


def validate_load_interpolation(results_table: pd.DataFrame, validation_load_n: float = 120.0,
                                *, degree: int | str = "loo", method: str = "auto",
                                quantities=None, branch: int | str = "auto"
                                ) -> list[ValidationResult]:
    """One :class:`ValidationResult` per (wheel, soil, multipass) with runs at
    ``validation_load_n`` and per quantity (``degree``, ``branch``: as
    :func:`fitting.fit.fit_curve`). Raises :class:`FittingError` when no run is at
    that load or a set has runs only there, :class:`LoadRangeError` when the other loads do
    not bracket it."""
    at_load = np.isclose(results_table["load_n"].astype(float), validation_load_n)
    if not at_load.any():
        raise FittingError(f"no runs at the validation load {validation_load_n:g} N")
    by_set = curves_by_load(fit_results(results_table[~at_load], degree, quantities,
                                        branch=branch))
    measured = with_dp_over_w(results_table[at_load])
    out = []
    for (wheel, soil, multipass, _), rows in measured.groupby(list(KEY_COLUMNS), sort=True):
        sets = {k: v for k, v in by_set.items()
                if k[:3] == (str(wheel), str(soil), int(multipass))}
        if not sets:
            raise FittingError(f"{wheel}/{soil} multipass {multipass}: runs at "
                               f"{validation_load_n:g} N but none at other loads")
        for (w, s, mp, q), curves in sets.items():
            ok = rows[np.isfinite(rows[q].astype(float))]
            slip, value = ok["slip"].to_numpy(float), ok[q].to_numpy(float)
            curve = interpolate_load(curves, validation_load_n, method=method)
            with warnings.catch_warnings():
                warnings.simplefilter("ignore", OutsideSlipRangeWarning)
                error = curve.evaluate(slip) - value
            inside = ~curve.outside_range(slip)
            _, _, pred_half95 = band(curve, slip)
            in_band = inside & (np.abs(error) <= pred_half95)
            known = inside.any() and bool(np.all(np.isfinite(pred_half95[inside])))
            rmse = float(np.sqrt(np.mean(error[inside] ** 2))) if inside.any() else float("nan")
            spread = float(np.ptp(value)) if value.size else float("nan")
            out.append(ValidationResult(
                wheel=w, soil=s, multipass=mp, quantity=q,
                validation_load_n=float(validation_load_n), tested_loads_n=curve.tested_loads_n,
                method=curve.method, n_points=int(value.size),
                n_outside_slip_range=int((~inside).sum()), measured_range=spread, rmse=rmse,
                rmse_pct_of_range=100.0 * rmse / spread if spread > 0 else float("nan"),
                max_abs_error=float(np.max(np.abs(error[inside]))) if inside.any()
                else float("nan"),
                rmse_all=float(np.sqrt(np.mean(error ** 2))) if error.size else float("nan"),
                n_inside_band=int(in_band.sum()),
                fraction_inside_band=float(in_band.sum() / inside.sum()) if known
                else float("nan")))
    return out
