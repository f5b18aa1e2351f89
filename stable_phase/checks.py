"""Checks of a candidate window: slope test and split-window R statistic."""

from __future__ import annotations

import numpy as np
from scipy.special import stdtr

from stable_phase.autocorr import statistical_inefficiency


def slope_test(t_s: np.ndarray, y: np.ndarray) -> dict:
    """OLS trend of ``y`` over the window, its SE inflated by the residuals' statistical
    inefficiency (autocorrelated residuals), a two-sided p value and the change over the window.
    """
    ok = np.isfinite(y)
    t, y = t_s[ok], y[ok]
    if t.size < 8:
        return {"slope_per_s": float("nan"), "p": float("nan"), "change": float("nan")}
    tc = t - t.mean()
    slope = float(np.dot(tc, y - y.mean()) / np.dot(tc, tc))
    resid = y - y.mean() - slope * tc
    g = statistical_inefficiency(resid)
    se = float(np.sqrt(g * np.var(resid, ddof=2) / np.dot(tc, tc)))
    n_eff = max(t.size / g, 3.0)
    p = float(2.0 * stdtr(n_eff - 2, -abs(slope) / se)) if se > 0 else 0.0
    return {"slope_per_s": slope, "slope_se_per_s": se, "p": p,
            "change": slope * float(t[-1] - t[0])}


def split_r_hat(y: np.ndarray) -> float:
    """Gelman-Rubin potential scale reduction of the window's two halves (split R-hat,
    Gelman & Rubin 1992; Vehtari et al. 2021): near 1 when both halves share one level."""
    y = np.asarray(y, float)
    y = y[np.isfinite(y)]
    n = y.size // 2
    if n < 4:
        return float("nan")
    halves = np.stack([y[:n], y[-n:]])
    within = float(np.mean(np.var(halves, axis=1, ddof=1)))
    between = float(n * np.var(halves.mean(axis=1), ddof=1))
    if within <= 0:
        return float("nan")
    return float(np.sqrt(((n - 1) / n * within + between / n) / within))


def half_change(y: np.ndarray) -> float:
    """Mean of the window's second half minus its first half's (the halves of
    :func:`split_r_hat`): the size of the level shift that a large R statistic detects."""
    y = np.asarray(y, float)
    y = y[np.isfinite(y)]
    n = y.size // 2
    if n < 4:
        return float("nan")
    return float(np.mean(y[-n:]) - np.mean(y[:n]))
