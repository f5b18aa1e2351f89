"""Held-out scoring: leave one load out (two or more loads), leave one multipass level out
and one gravity level out (three or more levels); with none of these, leave one slip band
out.

A two-level multipass or gravity factor is never held out: the strength of the multipass
or reduced-gravity effect could not be learned from the one level left, so such a fold
would score the lack of a contrast, not the effect. The two levels still enter every
training set, where they identify those effects (scored on held-out loads).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pandas as pd

from sim_gap.candidates import Candidate
from sim_gap.fit import FitResult, fit_candidate, standardised_residuals
from sim_gap.simulated import Simulated
from sim_gap.vocabulary import slip_band

FACTORS = (("load_set_n", "load"), ("multipass", "multipass"), ("gravity_mps2", "gravity"))
#: fewest levels for a factor to be held out one level at a time
MIN_LEVELS = {"load": 2, "multipass": 3, "gravity": 3}


def folds(points: pd.DataFrame) -> list[tuple[str, np.ndarray]]:
    """``(name, held-out mask)`` per fold."""
    out = []
    for column, label in FACTORS:
        levels = np.unique(points[column].round(6))
        if len(levels) >= MIN_LEVELS[label]:
            out += [(f"{label}={v:g}", points[column].round(6).to_numpy() == v) for v in levels]
    if not out:
        band = slip_band(points["slip"].to_numpy(float))
        out = [(f"slip band {b}", band == b) for b in np.unique(band)]
    return [(name, mask) for name, mask in out if mask.sum() >= 1 and (~mask).sum() >= 3]


def contrasts(points: pd.DataFrame) -> dict[str, int]:
    """Number of levels of each factor (what the campaign can reveal)."""
    return {label: int(points[column].round(6).nunique()) for column, label in FACTORS}


#: one fold's name, held-out mask, held-out standardised residuals and fitted values
Fold = tuple[str, np.ndarray, np.ndarray, dict[str, float]]


@dataclass(frozen=True)
class CrossValidated:
    """The full-data fit and, per fold, the held-out standardised residuals."""

    full: FitResult
    held_out: list[Fold]

    def run_losses(self, n_points: int) -> np.ndarray:
        """Per point (run): mean held-out squared standardised residual over its folds and
        quantities."""
        total, count = np.zeros(n_points), np.zeros(n_points)
        for _, mask, r, _ in self.held_out:
            sq = np.where(np.isfinite(r), r ** 2, 0.0)
            total[mask] += sq.sum(axis=1)
            count[mask] += np.isfinite(r).sum(axis=1)
        return total / np.maximum(count, 1)


def held_out_predictions(sim: Simulated, points: pd.DataFrame, held: list[Fold]
                         ) -> list[tuple[np.ndarray, dict[str, np.ndarray]]]:
    """Per fold: held-out mask and the fold fit's predictions there."""
    return [(mask, sim.predict(points[mask].reset_index(drop=True), values))
            for _, mask, _, values in held]


def cross_validate(sim: Simulated, c: Candidate, points: pd.DataFrame,
                   sigma: dict[str, np.ndarray], start: dict[str, float] | None = None,
                   max_nfev: int = 40, fold_nfev: int = 15) -> CrossValidated:
    """Fit on all points, then each fold (:func:`held_out`)."""
    return CrossValidated(fit_candidate(sim, c, points, sigma, start, max_nfev),
                          held_out(sim, c, points, sigma, start, fold_nfev))


def held_out(sim: Simulated, c: Candidate, points: pd.DataFrame,
             sigma: dict[str, np.ndarray], start: dict[str, float] | None = None,
             fold_nfev: int = 15) -> list[Fold]:
    """Refit on each fold's training points from ``start`` (never from a full fit, which
    has seen the held-out points) and keep the standardised residuals of the held-out
    points."""
    held = []
    for name, mask in folds(points):
        train = _subset(points, ~mask)
        test = _subset(points, mask)
        fit = fit_candidate(sim, c, train, {q: s[~mask] for q, s in sigma.items()},
                            start, fold_nfev)
        r = standardised_residuals(test, sim.predict(test, fit.values),
                                   {q: s[mask] for q, s in sigma.items()})
        held.append((name, mask, r, fit.values))
    return held


def _subset(points: pd.DataFrame, mask: np.ndarray) -> pd.DataFrame:
    out = points[mask].reset_index(drop=True)
    out.attrs = dict(points.attrs)
    return out
