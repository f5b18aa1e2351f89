"""How far the gap shrinks: held-out RMSE (physical units) before (soil-only recalibration)
and after (the chosen candidate), per quantity and slip band, with percentile bootstrap
intervals over runs (Efron & Tibshirani 1993, An Introduction to the Bootstrap, ch. 13)."""

from __future__ import annotations

import numpy as np
import pandas as pd

from sim_gap.crossval import Fold, held_out_predictions
from sim_gap.fit import quantities_of
from sim_gap.simulated import Simulated
from sim_gap.vocabulary import slip_band, slip_band_labels


def _squared_sums(sim: Simulated, points: pd.DataFrame, held: list[Fold]
                  ) -> dict[str, tuple[np.ndarray, np.ndarray]]:
    """Per quantity: per point, the sum of squared held-out residuals over its folds and
    their count."""
    n = len(points)
    out = {q: (np.zeros(n), np.zeros(n)) for q in quantities_of(points)}
    for mask, pred in held_out_predictions(sim, points, held):
        for q in out:
            r = points[q].to_numpy(float)[mask] - pred[q]
            if q == "sinkage_m" and points.attrs.get("sinkage_relative"):
                r = r - np.nanmean(r)
            ok = np.isfinite(r)
            idx = np.flatnonzero(mask)[ok]
            out[q][0][idx] += r[ok] ** 2
            out[q][1][idx] += 1
    return out


def _rmse(weights: np.ndarray, sums: np.ndarray, counts: np.ndarray) -> np.ndarray:
    return np.sqrt((weights @ sums) / np.maximum(weights @ counts, 1e-300))


def shrink(sim: Simulated, points: pd.DataFrame, before: list[Fold], after: list[Fold],
           n_boot: int = 200, seed: int = 0) -> dict:
    """``held_out_rmse_before``/``_after`` and ``shrink_pct`` per quantity (with 95 %
    bootstrap intervals) and the same per slip band."""
    n = len(points)
    rng = np.random.default_rng(seed)
    weights = rng.multinomial(n, np.full(n, 1.0 / n), size=n_boot).astype(float)
    sb, sa = _squared_sums(sim, points, before), _squared_sums(sim, points, after)
    band = slip_band(points["slip"].to_numpy(float))
    labels = slip_band_labels()

    def table(select: np.ndarray) -> dict:
        out = {}
        for q in sb:
            if not np.any(sb[q][1][select]):
                continue
            w = np.vstack([np.ones(n), weights]) * select
            rb, ra = _rmse(w, *sb[q]), _rmse(w, *sa[q])
            pct = 100.0 * (1.0 - ra / np.where(rb > 0, rb, np.nan))
            lo, hi = np.nanpercentile(pct[1:], [2.5, 97.5]) if n_boot else (np.nan, np.nan)
            out[q] = {"before": float(rb[0]), "after": float(ra[0]),
                      "shrink_pct": float(pct[0]), "shrink_pct_ci95": [float(lo), float(hi)],
                      "before_ci95": np.percentile(rb[1:], [2.5, 97.5]).tolist() if n_boot else [],
                      "after_ci95": np.percentile(ra[1:], [2.5, 97.5]).tolist() if n_boot else []}
        return out

    overall = table(np.ones(n, bool))
    return {
        "held_out_rmse_before": {q: v["before"] for q, v in overall.items()},
        "held_out_rmse_after": {q: v["after"] for q, v in overall.items()},
        "shrink_pct": {q: v["shrink_pct"] for q, v in overall.items()},
        "per_quantity": overall,
        "per_slip_band": {labels[b]: table(band == b) for b in np.unique(band)},
        "n_boot": n_boot,
    }
