"""Accuracy of the soil calibration on held-out slips: calibrate with one slip band left
out at a time and predict the band (leave-one-band-out cross-validation)."""

from __future__ import annotations

import numpy as np
import pandas as pd

import terramechanics as tm
from sim_gap.calibrate import calibrate_soil

#: held-out slip bands (left-closed, the last closed): locked to heavy skid, light skid,
#: and three driving bands
HOLDOUT_BAND_EDGES = (-1.0, -0.5, 0.0, 0.3, 0.6, 1.0)


def band_index(slip: np.ndarray, edges=HOLDOUT_BAND_EDGES) -> np.ndarray:
    idx = np.searchsorted(np.asarray(edges), np.asarray(slip, dtype=float), side="right") - 1
    return np.clip(idx, 0, len(edges) - 2)


def holdout_dp(points: pd.DataFrame, model: tm.WheelModel, edges=HOLDOUT_BAND_EDGES,
               **calibrate_kwargs) -> pd.DataFrame:
    """Per point: the held-out band, measured and predicted DP (N) and the status of the
    calibration without that band (``calibrate_kwargs`` go to ``calibrate_soil``)."""
    bands = band_index(points["slip"].to_numpy(float), edges)
    rows = []
    for band in np.unique(bands):
        train = points[bands != band]
        train.attrs.update(points.attrs)
        cal = calibrate_soil(train, model, **calibrate_kwargs)
        test = points[bands == band]
        dp = cal.model.curves(test["wheel_load_n"].to_numpy(float),
                              test["slip"].to_numpy(float))["dp_n"]
        rows.append(pd.DataFrame({"band": band, "slip": test["slip"].to_numpy(float),
                                  "dp_measured_n": test["dp_n"].to_numpy(float),
                                  "dp_predicted_n": dp, "status": cal.status}))
    return pd.concat(rows, ignore_index=True)


def holdout_summary(table: pd.DataFrame) -> dict[str, float]:
    """Held-out DP RMSE (N) over every point, the measured DP range (N), their ratio, and
    the RMSE of each band."""
    err = table["dp_predicted_n"] - table["dp_measured_n"]
    rmse = float(np.sqrt(np.mean(err ** 2)))
    span = float(np.ptp(table["dp_measured_n"]))
    per_band = {f"band_{b}_rmse_n": float(np.sqrt(np.mean(e ** 2)))
                for b, e in err.groupby(table["band"])}
    return {"heldout_dp_rmse_n": rmse, "dp_range_n": span, "rmse_over_range": rmse / span,
            **per_band}
