"""Choice of the polynomial degree among 3-7, and of the braked branch (none, the step J,
the step J and slope K below zero slip), by leave-one-out cross-validation or AICc.

A candidate is a ``(degree, branch)`` pair; its parameters are degree + 1 coefficients plus
``branch`` (0, 1 or 2) braked-branch terms.

- ``"loo"``: weighted RMS of the exact leave-one-out residuals ``e_i / (1 - h_ii)`` (hat
  matrix diagonal; Allen's PRESS), in the quantity's unit. Where leaving a point out leaves
  a branch term undetermined (two braked runs for J and K: leverage 1), the point is
  predicted by the fit of the other points with one branch term fewer (J alone), so every
  candidate is scored on every point.
- ``"aicc"``: ``n ln(WRSS/n) + 2k + 2k(k+1)/(n-k-1)`` with ``k`` = parameters + 1 (the
  residual scale; Hurvich & Tsai 1989, Biometrika 76:297); candidates also need
  ``n > k + 1``.

Candidates keep at least two residual degrees of freedom (parameters + 2 distinct slips), so
an automatic choice never nearly interpolates its points. AICc: the lowest score wins. LOO:
the candidate with the fewest parameters whose score is within one standard error of the
best (the one-standard-error rule), since with a handful of points the LOO score itself is
noisy; between two with as many parameters, the lower score. Scores of every candidate are
kept.
"""

from __future__ import annotations

import numpy as np

from fitting.curve import DEGREES
from fitting.polynomial import LeastSquares, curve_value, weighted_lstsq

CRITERIA = ("loo", "aicc")
LEVERAGE_ONE = 1e-12  # 1 - h_ii below this: the point determines a parameter alone

Candidate = tuple[int, int]  # (degree, braked-branch terms)


def loo_residuals(ls: LeastSquares, value) -> np.ndarray:
    """Exact leave-one-out residuals of a linear least-squares fit (inf where a point's
    leverage is 1: the fit without it is not determined)."""
    keep = 1.0 - ls.leverage
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(keep > LEVERAGE_ONE, (np.asarray(value) - ls.fitted) / keep, np.inf)


def branch_loo_residuals(ls: LeastSquares, slip, value, weights, slip_min: float,
                         slip_max: float) -> np.ndarray:
    """:func:`loo_residuals`, where a point's leverage is 1 predicted instead by the fit of the
    other points with one braked-branch term fewer (docstring of this module)."""
    slip, value, weights = (np.asarray(x, dtype=float) for x in (slip, value, weights))
    e = loo_residuals(ls, value)
    for i in np.flatnonzero(~np.isfinite(e)) if ls.branch else ():
        keep = np.arange(slip.size) != i
        reduced = weighted_lstsq(slip[keep], value[keep], weights[keep],
                                 len(ls.coefficients) - 1, slip_min, slip_max, ls.branch - 1)
        e[i] = value[i] - curve_value(reduced.coefficients, slip[i], *reduced.below_zero)
    return e


def score(criterion: str, ls: LeastSquares, value, weights, loo=None) -> tuple[float, float]:
    """The criterion's score of one fit (lower is better) and the score a simpler candidate
    may reach to be preferred (LOO: one standard error of the mean squared LOO residual
    above it; AICc: the score itself). ``loo``: the LOO residuals (default
    :func:`loo_residuals`)."""
    w = np.asarray(weights, dtype=float)
    if criterion == "loo":
        e = loo_residuals(ls, value) if loo is None else np.asarray(loo)
        terms = w * e * e / np.mean(w)
        mse = float(np.mean(terms))
        return np.sqrt(mse), np.sqrt(mse + float(np.std(terms, ddof=1)) / np.sqrt(terms.size))
    n, k = len(w), ls.n_parameters + 1
    wrss = float(np.sum(w * (np.asarray(value) - ls.fitted) ** 2))
    wrss = max(wrss, n * 1e-300)  # a noise-free fit: finite score, tie goes to the lower degree
    aicc = float(n * np.log(wrss / n) + 2 * k + 2 * k * (k + 1) / (n - k - 1))
    return aicc, aicc


def choose(scores: dict[Candidate, tuple[float, float]]) -> Candidate:
    """The candidate with the fewest parameters scoring within reach of the best
    (one-standard-error rule for LOO, Hastie, Tibshirani & Friedman 2009 sec. 7.10; plain
    minimum for AICc), the lower score between equals."""
    best = min(scores, key=lambda c: (scores[c][0], c[0] + c[1]))
    reach = [c for c in scores if scores[c][0] <= scores[best][1]]
    return min(reach, key=lambda c: (c[0] + c[1], scores[c][0]))


def candidate_degrees(criterion: str, n_points: int, n_distinct: int) -> list[int]:
    """Degrees 3-7 the criterion may consider with these points (degree + 3 distinct slips;
    AICc also ``n > degree + 3``)."""
    out = [d for d in DEGREES if n_distinct >= d + 3]
    return [d for d in out if n_points > d + 3] if criterion == "aicc" else out


def branch_fits(degree: int, branch: int, slip, spare: int = 2,
                criterion: str | None = None) -> bool:
    """Whether a degree-``degree`` polynomial plus ``branch`` (1 or 2) braked-branch terms is
    determined by these slips with ``spare`` residual degrees of freedom (2 for an automatic
    choice, 1 for a set degree): two distinct slips below zero at least (one braked run
    cannot tell a branch from the polynomial's extrapolation), degree + 1 at or above zero,
    degree + 1 + branch + ``spare`` in all (AICc also ``n > degree + branch + 3``)."""
    slip = np.asarray(slip, dtype=float)
    below, above = np.unique(slip[slip < 0]).size, np.unique(slip[slip >= 0]).size
    enough = below >= max(2, branch) and above >= degree + 1 \
        and below + above >= degree + 1 + branch + spare
    return enough and (criterion != "aicc" or slip.size > degree + branch + 3)
