"""Choice of the polynomial degree among 3-7: leave-one-out cross-validation or AICc.

- ``"loo"``: weighted RMS of the exact leave-one-out residuals ``e_i / (1 - h_ii)`` (hat
  matrix diagonal; Allen's PRESS), in the quantity's unit.
- ``"aicc"``: ``n ln(WRSS/n) + 2k + 2k(k+1)/(n-k-1)`` with ``k = degree + 2`` (coefficients
  and the residual scale; Hurvich & Tsai 1989, Biometrika 76:297); candidates also need
  ``n > k + 1``.

Candidates keep at least two residual degrees of freedom (degree + 3 distinct slips), so an
automatic choice never nearly interpolates its points. AICc: the lowest score wins. LOO: the
lowest degree whose score is within one standard error of the best (the one-standard-error
rule), since with a handful of points the LOO score itself is noisy. Scores of every
candidate are kept.
"""

from __future__ import annotations

import numpy as np

from fitting.curve import DEGREES
from fitting.polynomial import LeastSquares

CRITERIA = ("loo", "aicc")


def loo_residuals(ls: LeastSquares, value) -> np.ndarray:
    """Exact leave-one-out residuals of a linear least-squares fit."""
    keep = 1.0 - ls.leverage
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(keep > 1e-12, (np.asarray(value) - ls.fitted) / keep, np.inf)


def score(criterion: str, ls: LeastSquares, value, weights) -> tuple[float, float]:
    """The criterion's score of one fit (lower is better) and the score a simpler candidate
    may reach to be preferred (LOO: one standard error of the mean squared LOO residual
    above it; AICc: the score itself)."""
    w = np.asarray(weights, dtype=float)
    if criterion == "loo":
        e = loo_residuals(ls, value)
        terms = w * e * e / np.mean(w)
        mse = float(np.mean(terms))
        return np.sqrt(mse), np.sqrt(mse + float(np.std(terms, ddof=1)) / np.sqrt(terms.size))
    n, k = len(w), len(ls.coefficients) + 1
    wrss = float(np.sum(w * (np.asarray(value) - ls.fitted) ** 2))
    wrss = max(wrss, n * 1e-300)  # a noise-free fit: finite score, tie goes to the lower degree
    aicc = float(n * np.log(wrss / n) + 2 * k + 2 * k * (k + 1) / (n - k - 1))
    return aicc, aicc


def choose(scores: dict[int, tuple[float, float]]) -> int:
    """The lowest degree scoring within reach of the best (one-standard-error rule for LOO,
    Hastie, Tibshirani & Friedman 2009 sec. 7.10; plain minimum for AICc)."""
    best = min(scores, key=lambda d: (scores[d][0], d))
    return min(d for d in scores if scores[d][0] <= scores[best][1])


def candidate_degrees(criterion: str, n_points: int, n_distinct: int) -> list[int]:
    """Degrees 3-7 the criterion may consider with these points (degree + 3 distinct slips;
    AICc also ``n > degree + 3``)."""
    out = [d for d in DEGREES if n_distinct >= d + 3]
    return [d for d in out if n_points > d + 3] if criterion == "aicc" else out
