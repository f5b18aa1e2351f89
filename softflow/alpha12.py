"""``alpha1`` and ``alpha2`` of ``k = alpha1 / (eps_vol^P + alpha2)`` from (eps, k) pairs.

``1/k = eps / alpha1 + alpha2 / alpha1`` is a straight line in ``eps``: weighted
least squares of ``1/k`` on ``eps`` (weights from the CI of each ``k``:
``sigma_(1/k) = sigma_k / k^2``), covariance scaled by the residual scatter (so the
noise of ``eps`` shows up in it), 95 % CIs of ``alpha1 = 1/b`` and ``alpha2 = a/b``
by the delta method with ``t(0.975, n - 2)``. ``alpha2`` is the intercept at
``eps = 0`` divided by the slope: it is only as good as the spread of ``eps`` is wide
against its mean (``eps_range`` is reported). Pairs come from the beta bins of one
run (``fit_alpha12``) or of several runs pooled (``fit_alpha12_across_runs``): one
stable-phase frame range per slip, load or soil state.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from scipy.special import stdtrit

from softflow.decay_fit import DecayFit

MIN_R2 = 0.5  # k fits below this are not used (as for the grouser models)


def rates_and_sigmas(fits: Sequence[DecayFit | None]) -> tuple[np.ndarray, np.ndarray]:
    """``k`` and its standard error (from the 95 % CI) per bin; NaN where unusable."""
    k = np.full(len(fits), np.nan)
    sigma = np.full(len(fits), np.nan)
    for i, f in enumerate(fits):
        if f and f.r2 > MIN_R2 and f.rate_per_m > 0 and f.dof > 0:
            k[i] = f.rate_per_m
            half = (f.ci95_per_m[1] - f.ci95_per_m[0]) / 2
            sigma[i] = half / stdtrit(f.dof, 0.975)
    return k, sigma


def fit_alpha12(eps: np.ndarray, k_per_m: np.ndarray, k_sigma_per_m: np.ndarray) -> dict | None:
    """``alpha1_per_m``, ``alpha2``, ``bins_used``, their 95 % CIs and ``eps_range``; None
    with fewer than 3 usable pairs."""
    eps, k, sk = (np.asarray(a, np.float64) for a in (eps, k_per_m, k_sigma_per_m))
    ok = np.isfinite(eps) & np.isfinite(k) & np.isfinite(sk) & (k > 0)
    n = int(ok.sum())
    if n < 3:
        return None
    x, y = eps[ok], 1 / k[ok]
    w = 1 / np.maximum(sk[ok] / k[ok] ** 2, 1e-12 * y) ** 2
    design = np.stack([np.ones(n), x], -1)
    normal = design.T @ (w[:, None] * design)
    a, b = np.linalg.solve(normal, design.T @ (w * y))
    if b == 0:
        return None
    resid = y - a - b * x
    cov = np.linalg.inv(normal) * float(np.sum(w * resid ** 2)) / max(n - 2, 1)
    t = stdtrit(max(n - 2, 1), 0.975)
    alpha1, alpha2 = 1 / b, a / b
    sd1 = np.sqrt(cov[1, 1]) / b ** 2
    sd2 = np.sqrt(max(cov[0, 0] / b ** 2 + a ** 2 * cov[1, 1] / b ** 4
                      - 2 * a * cov[0, 1] / b ** 3, 0.0))
    return {"alpha1_per_m": float(alpha1), "alpha2": float(alpha2), "bins_used": n,
            "alpha1_ci95_per_m": [float(alpha1 - t * sd1), float(alpha1 + t * sd1)],
            "alpha2_ci95": [float(alpha2 - t * sd2), float(alpha2 + t * sd2)],
            "eps_range": [float(x.min()), float(x.max())]}


def fit_alpha12_across_runs(results: Sequence) -> dict | None:
    """One line through the (eps, k) bins of several ``FlowResult``s (with ``eps_vol_p``),
    over the bins whose ``eps`` is resolved (``FlowResult.resolved_eps``)."""
    eps, k, sigma = [], [], []
    for res in results:
        if res.eps_vol_p is None:
            continue
        rk, rs = rates_and_sigmas(res.radial)
        eps.append(np.asarray(res.resolved_eps(), np.float64))
        k.append(rk)
        sigma.append(rs)
    if not eps:
        return None
    fit = fit_alpha12(np.concatenate(eps), np.concatenate(k), np.concatenate(sigma))
    if fit:
        fit["runs"] = len(eps)
    return fit
