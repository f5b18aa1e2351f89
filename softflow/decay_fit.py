"""Exponential decay fits ``v(rho) = A exp(-k rho)`` of velocity profiles, with their CIs.

``rho = r - R`` the distance from the rim (m). Weighted nonlinear least squares
(scipy ``curve_fit``, started from a log-linear fit); the 95 % confidence interval
of ``k`` is ``k +- t(0.975, n-2) * sigma_k`` from the scaled covariance; R² of the
weighted fit. That CI holds the scatter about one profile only;
:func:`softflow.field_analysis.jackknife_ci` replaces it by the scatter over frame pairs
(``ci_dof`` then the pairs less one). This gives ``alpha3(beta)`` (tangential) and ``k(beta) =
alpha1 / (eps_vol^P + alpha2)`` (radial) of the SOFT velocity-field model.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.optimize import curve_fit


@dataclass
class DecayFit:
    amplitude: float
    rate_per_m: float
    ci95_per_m: tuple[float, float]
    r2: float
    points: int
    ci_dof: int | None = None  # degrees of freedom of the CI's t quantile; None: points - 2

    @property
    def dof(self) -> int:
        return self.points - 2 if self.ci_dof is None else self.ci_dof

    def to_dict(self) -> dict:
        return {"amplitude_mps": self.amplitude, "rate_per_m": self.rate_per_m,
                "ci95_per_m": list(self.ci95_per_m), "ci95_dof": self.dof, "r2": self.r2,
                "points": self.points}


def _model(rho, a, k):
    return a * np.exp(-k * rho)


def fit_decay(rho_m: np.ndarray, value: np.ndarray, sigma: np.ndarray) -> DecayFit | None:
    """Fit one profile; ``None`` with fewer than 5 points or no convergence."""
    from scipy import stats  # here: reading a stored flow does not need scipy.stats

    if len(rho_m) < 5:
        return None
    a0 = value[np.argmin(rho_m)]
    pos = np.abs(value) > 0.05 * np.abs(a0)
    k0 = 30.0
    if pos.sum() >= 3 and a0 != 0:
        slope = np.polyfit(rho_m[pos], np.log(np.abs(value[pos]) + 1e-12), 1)[0]
        k0 = max(-slope, 1.0)
    try:
        (a, k), cov = curve_fit(_model, rho_m, value, p0=(a0, k0), sigma=sigma, maxfev=2000)
    except (RuntimeError, ValueError):
        return None
    dof = len(rho_m) - 2
    half = stats.t.ppf(0.975, dof) * float(np.sqrt(max(cov[1, 1], 0.0)))
    w = 1 / sigma ** 2
    resid = value - _model(rho_m, a, k)
    mean = np.sum(w * value) / np.sum(w)
    r2 = 1 - np.sum(w * resid ** 2) / np.sum(w * (value - mean) ** 2)
    return DecayFit(float(a), float(k), (float(k - half), float(k + half)), float(r2), len(rho_m))
