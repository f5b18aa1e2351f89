"""Fit one curve: weighted least squares in slip, degree set (3-7) or chosen, diagnostics.

Method: RUAG's Wheel Parametric Analytical Tool (WPAT) -- "a least-squares polynomial curve
fit is computed to obtain a continuous function. The degree ... can be specified by the user
... polynomials of degrees n = 3 ... 7 provide adequate results". Weights 1/SE^2 of each
run's mean.
"""

from __future__ import annotations

import numpy as np

from fitting.curve import DEGREES, QUANTITY_UNITS, CurveFit
from fitting.degree import CRITERIA, candidate_degrees, choose, loo_residuals, score
from fitting.errors import DegreeError, FittingError, TooFewPointsError
from fitting.oscillation import check_oscillation
from fitting.polynomial import weighted_lstsq

SE_FLOOR_FRACTION = 0.2  # SE floored at this fraction of the median SE: weight <= 25x median


def se_weights(se, n: int) -> tuple[np.ndarray, str]:
    """Weights 1/SE^2 and how they were made. A missing (NaN) SE takes the median SE; every
    SE is floored at 0.2 x the median, so no point outweighs the median one more than 25x;
    no positive SE at all gives equal weights."""
    se = np.full(n, np.nan) if se is None else np.asarray(se, dtype=float)
    positive = se[np.isfinite(se) & (se > 0)]
    if positive.size == 0:
        return np.ones(n), "equal weights (no standard errors)"
    median = float(np.median(positive))
    floored = np.maximum(np.where(np.isfinite(se), se, median), SE_FLOOR_FRACTION * median)
    return 1.0 / floored ** 2, (f"1/SE^2, SE floored at {SE_FLOOR_FRACTION:g} x median SE "
                                f"({SE_FLOOR_FRACTION * median:.4g}); missing SE = median")


def check_degree(degree: int | str) -> None:
    """Raise :class:`DegreeError` unless ``degree`` is 3-7 or a criterion name."""
    if isinstance(degree, str):
        if degree not in CRITERIA:
            raise DegreeError(f"degree {degree!r}: give 3-7 or one of {list(CRITERIA)}")
    elif isinstance(degree, bool) or not isinstance(degree, (int, np.integer)) \
            or degree not in DEGREES:
        raise DegreeError(f"degree {degree!r} outside 3-7 (RUAG WPAT: degrees 3 ... 7)")


def fit_curve(slip, value, se=None, *, degree: int | str = "loo", quantity: str = "dp_n",
              wheel: str = "", soil: str = "", multipass: int = 0,
              load_n: float = float("nan")) -> CurveFit:
    """Fit ``value`` against ``slip`` (fractions) with weights 1/``se``^2.

    ``degree``: 3-7, or ``"loo"`` / ``"aicc"`` to choose (see :mod:`fitting.degree`) among
    the candidates that do not oscillate (among all, flagged, if every one does).
    Raises :class:`DegreeError`, :class:`TooFewPointsError` (fewer than degree + 2 distinct
    slips) or :class:`FittingError` (non-finite input), naming group and quantity.
    """
    label = f"{wheel}/{soil} multipass {multipass} at {load_n:g} N, {quantity}"
    check_degree(degree)
    degree = degree if isinstance(degree, str) else int(degree)
    if quantity not in QUANTITY_UNITS:
        raise FittingError(f"{label}: unknown quantity; known: {list(QUANTITY_UNITS)}")
    slip, value = np.asarray(slip, dtype=float), np.asarray(value, dtype=float)
    if slip.shape != value.shape or not (np.all(np.isfinite(slip)) and np.all(np.isfinite(value))):
        raise FittingError(f"{label}: slip and value must be finite arrays of one length")
    weights, weighting = se_weights(se, slip.size)
    n_distinct = np.unique(slip).size
    if isinstance(degree, str):
        candidates = candidate_degrees(degree, slip.size, n_distinct)
        if not candidates:
            raise TooFewPointsError(
                f"{label}: {n_distinct} distinct slips ({slip.size} points), too few to choose "
                f"a degree by {degree}: degree 3 needs 6 distinct slips"
                + (" and more than 6 points" if degree == "aicc" else ""))
    elif n_distinct < degree + 2:
        raise TooFewPointsError(
            f"{label}: {n_distinct} distinct slips ({slip.size} points); degree {degree} needs "
            f"at least {degree + 2} (degree + 1 to determine it, one more for its "
            "leave-one-out error)")
    else:
        candidates = [degree]
    lo, hi = float(slip.min()), float(slip.max())
    fits = {d: weighted_lstsq(slip, value, weights, d, lo, hi) for d in candidates}
    rmse = {d: float(np.sqrt(np.mean((value - ls.fitted) ** 2))) for d, ls in fits.items()}
    shape = {d: check_oscillation(ls.coefficients, slip, rmse[d]) for d, ls in fits.items()}
    scores = {} if isinstance(degree, int) else {
        d: score(degree, ls, value, weights) for d, ls in fits.items()}
    smooth = [d for d in scores if not shape[d][0]] or list(scores)
    chosen = choose({d: scores[d] for d in smooth}) if scores else degree
    ls, (oscillates, departure) = fits[chosen], shape[chosen]
    resid = value - ls.fitted
    mean_w = np.sum(weights * value) / np.sum(weights)
    total = np.sum(weights * (value - mean_w) ** 2)
    return CurveFit(
        coefficients=tuple(float(a) for a in ls.coefficients), slip_min=lo, slip_max=hi,
        quantity=quantity, unit=QUANTITY_UNITS[quantity], wheel=wheel, soil=soil,
        multipass=int(multipass), load_n=float(load_n), n_points=int(slip.size),
        rmse=rmse[chosen],
        r2=float(1.0 - np.sum(weights * resid ** 2) / total) if total > 0 else float("nan"),
        loo_rmse=float(np.sqrt(np.mean(loo_residuals(ls, value) ** 2))),
        condition_number=ls.condition_number,
        degree_choice="user" if isinstance(degree, int) else degree,
        degree_scores=tuple((d, float(v[0])) for d, v in sorted(scores.items())),
        weighting=weighting, oscillates=oscillates, max_departure=departure)
