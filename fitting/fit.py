"""Fit one curve: weighted least squares in slip, degree set (3-7) or chosen, braked branch
(step and slope below zero slip) set or chosen, diagnostics.

Method: RUAG's Wheel Parametric Analytical Tool (WPAT) -- "a least-squares polynomial curve
fit is computed to obtain a continuous function. The degree ... can be specified by the user
... polynomials of degrees n = 3 ... 7 provide adequate results". Weights 1/SE^2 of each
run's mean. The braked branch ``[slip < 0] (J + K slip)``: Wong & Reece (1967) give the
driven wheel (part I, J. Terramech. 4(1)) and the braked/towed wheel (part II,
J. Terramech. 4(2)) different stress laws and slip definitions, which meet at zero slip with
a jump and a change of slope that no polynomial follows. Two terms rather than the step
alone: on the model's noise-free 120 N check a cubic with the step alone still misses
sinkage by 7.0 % and resistance by 10.8 % of their ranges (their braked sides slope the other
way), with step and slope by 0.67 % and 0.69 % (docs/fitting.md, "The join at zero slip").
"""

from __future__ import annotations

import numpy as np
from scipy import special

from fitting.curve import DEGREES, QUANTITY_UNITS, CurveFit
from fitting.degree import (CRITERIA, branch_fits, branch_loo_residuals, candidate_degrees,
                            choose, score)
from fitting.errors import DegreeError, FittingError, TooFewPointsError
from fitting.oscillation import check_oscillation
from fitting.polynomial import BRANCH_TERMS, weighted_lstsq

Z95 = 1.959963984540054  # two-sided 95 % normal quantile

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


def fit_curve(slip, value, se=None, *, degree: int | str = "loo", branch: int | str = "auto",
              quantity: str = "dp_n", wheel: str = "", soil: str = "", multipass: int = 0,
              load_n: float = float("nan")) -> CurveFit:
    """Fit ``value`` against ``slip`` (fractions) with weights 1/``se``^2.

    ``degree``: 3-7, or ``"loo"`` / ``"aicc"`` to choose (see :mod:`fitting.degree`) among
    the candidates that do not oscillate (among all, flagged, if every one does).
    ``branch``: braked-branch terms, ``"auto"`` to choose among none, the step J and the
    step and slope J, K where the slips allow them (:func:`fitting.degree.branch_fits`), by
    the degree criterion (by ``"loo"`` for a set degree); 0, 1 or 2 to set (an error where
    the slips do not allow it). Raises :class:`DegreeError`, :class:`TooFewPointsError`
    (fewer than degree + 2 distinct slips) or :class:`FittingError` (non-finite input, a
    bad ``branch``), naming group and quantity.
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
        degrees = candidate_degrees(degree, slip.size, n_distinct)
        if not degrees:
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
        degrees = [degree]
    criterion = degree if isinstance(degree, str) else "loo"  # a set degree: LOO on the branch
    candidates = _candidates(degrees, branch, slip, 2 if isinstance(degree, str) else 1,
                             criterion, label)
    lo, hi = float(slip.min()), float(slip.max())
    fits = {c: weighted_lstsq(slip, value, weights, c[0], lo, hi, c[1]) for c in candidates}
    rmse = {c: float(np.sqrt(np.mean((value - ls.fitted) ** 2))) for c, ls in fits.items()}
    shape = {c: check_oscillation(ls.coefficients, slip, rmse[c], *ls.below_zero)
             for c, ls in fits.items()}
    loo = {c: branch_loo_residuals(ls, slip, value, weights, lo, hi) for c, ls in fits.items()}
    scores = {c: score(criterion, ls, value, weights, loo[c]) for c, ls in fits.items()} \
        if len(candidates) > 1 or isinstance(degree, str) else {}
    smooth = [c for c in scores if not shape[c][0]] or list(scores)
    chosen = choose({c: scores[c] for c in smooth}) if scores else candidates[0]
    ls, (oscillates, departure) = fits[chosen], shape[chosen]
    resid = value - ls.fitted
    mean_w = np.sum(weights * value) / np.sum(weights)
    total = np.sum(weights * (value - mean_w) ** 2)
    step_se, slope_se = _branch_se(ls, resid, weights, weighting.startswith("1/SE^2"))
    covariance, scatter_sd, k95 = fit_uncertainty(ls, resid, weights,
                                                  weighting.startswith("1/SE^2"))
    return CurveFit(
        coefficients=tuple(float(a) for a in ls.coefficients), slip_min=lo, slip_max=hi,
        step_below_zero=float(ls.below_zero[0]), slope_below_zero=float(ls.below_zero[1]),
        quantity=quantity, unit=QUANTITY_UNITS[quantity], wheel=wheel, soil=soil,
        multipass=int(multipass), load_n=float(load_n), n_points=int(slip.size),
        rmse=rmse[chosen],
        r2=float(1.0 - np.sum(weights * resid ** 2) / total) if total > 0 else float("nan"),
        loo_rmse=float(np.sqrt(np.mean(loo[chosen] ** 2))),
        condition_number=ls.condition_number,
        degree_choice="user" if isinstance(degree, int) else degree,
        degree_scores=tuple((d, float(v[0])) for (d, b), v in sorted(scores.items())
                            if not b and isinstance(degree, str)),
        weighting=weighting, oscillates=oscillates, max_departure=departure,
        branch_choice="user" if isinstance(branch, int) else criterion,
        branch_scores=tuple((d, b, float(v[0])) for (d, b), v in sorted(scores.items()) if b),
        step_se=step_se, slope_se=slope_se, covariance=covariance, scatter_sd=scatter_sd,
        k95=k95)


def _candidates(degrees: list[int], branch: int | str, slip: np.ndarray, spare: int,
                criterion: str, label: str) -> list[tuple[int, int]]:
    """(degree, branch terms) pairs to fit: every degree with each number of branch terms
    that ``branch`` asks for and the slips allow."""
    if isinstance(branch, bool) or branch not in ("auto", *BRANCH_TERMS):
        raise FittingError(f"{label}: branch {branch!r}: give 'auto', 0, 1 or 2")
    wanted = BRANCH_TERMS if branch == "auto" else (branch,)
    out = [(d, b) for b in wanted for d in degrees
           if b == 0 or branch_fits(d, b, slip, spare, criterion)]
    if not out:
        raise TooFewPointsError(
            f"{label}: no degree in {degrees} can be fitted with {branch} braked-branch "
            f"term(s): they need 2 distinct slips below zero, degree + 1 at or above zero and "
            f"degree + {1 + branch + spare} in all")
    return out


def _branch_se(ls, resid: np.ndarray, weights: np.ndarray, from_se: bool) -> tuple[float, float]:
    """Standard errors of J and K: ``sqrt([(X^T W X)^-1]_kk)`` with weights 1/SE^2, times the
    root weighted residual variance ``WRSS / (n - p)`` when the weights are not from standard
    errors (Seber & Lee 2003, Linear Regression Analysis, 2nd ed., sec. 3.3); NaN for a term
    not fitted."""
    dof = resid.size - ls.n_parameters
    scale = 1.0 if from_se else float(np.sum(weights * resid ** 2)) / dof if dof > 0 \
        else float("nan")
    step_se, slope_se = ls.below_zero_se * np.sqrt(scale)
    return float(step_se), float(slope_se)


def _chi2_quantile(q: float, dof: int) -> float:
    """The ``q`` quantile of chi^2 with ``dof`` > 0 degrees of freedom: the function
    ``scipy.stats.chi2.ppf`` evaluates, without importing scipy.stats (a second of a
    report's start-up)."""
    return float(2.0 * special.gammaincinv(dof / 2, q))


def _t_quantile(q: float, dof: int) -> float:
    """The ``q`` quantile of Student's t with ``dof`` > 0 degrees of freedom (what
    ``scipy.stats.t.ppf`` evaluates)."""
    return float(special.stdtrit(dof, q))


def fit_uncertainty(ls, resid: np.ndarray, weights: np.ndarray, from_se: bool
                    ) -> tuple[tuple[tuple[float, ...], ...], float, float]:
    """(covariance of ``(a_0 ... a_n, J, K)``, run-to-run SD, 95 % factor) of a fit
    (docs/fitting.md, "Bands"). With weights 1/sigma^2: ``(X^T W X)^-1``, scatter the RMS
    sigma, factor 1.96, while chi^2 = WRSS is consistent with the sigmas (below its 95 %
    quantile for dof); else all scaled by the Birge ratio ``chi^2/dof`` (Birge 1932,
    Phys. Rev. 40:207; the Particle Data Group's scale factor) with factor Student's
    t(0.975, dof). Without sigmas: scaled by ``WRSS/dof``, scatter its root, factor t."""
    dof = resid.size - ls.n_parameters
    wrss = float(np.sum(weights * resid ** 2))
    ratio = wrss / dof if dof > 0 else float("nan")
    if from_se:
        trusted = not dof > 0 or wrss <= _chi2_quantile(0.95, dof)
        scale = 1.0 if trusted else ratio
        scatter = float(np.sqrt(scale * np.mean(1.0 / weights)))
    else:
        trusted, scale = False, ratio
        scatter = float(np.sqrt(ratio))
    k95 = Z95 if trusted else _t_quantile(0.975, dof) if dof > 0 else float("nan")
    covariance = ls.covariance * scale
    return tuple(tuple(float(v) for v in row) for row in covariance), scatter, k95
