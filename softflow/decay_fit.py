"""Exponential decay fits ``v(rho) = A exp(-k rho)`` of velocity profiles, with their CIs.

``rho = r - R`` the distance from the rim (m). Weighted nonlinear least squares
(scipy ``curve_fit``, started from a log-linear fit); the 95 % confidence interval
of ``k`` is ``k +- t(0.975, n-2) * sigma_k`` from the scaled covariance; R² of the
weighted fit. That CI holds the scatter about one profile only;
:func:`softflow.field_analysis.jackknife_ci` replaces it by the scatter over frame pairs
(``ci_dof`` then the pairs less one). This gives ``alpha3(beta)`` (tangential) and ``k(beta) =
alpha1 / (eps_vol^P + alpha2)`` (radial) of the SOFT velocity-field model.

:func:`fit_decay_across` fits a bin's profile together with those of its neighbouring angles,
the rate linear in the angle (local linear regression over angle, as in Cleveland 1979's
locally weighted regression, with an amplitude per profile): the flow's noise differs from
bin to bin, the rate varies smoothly with the angle.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.optimize import curve_fit
from scipy.special import stdtrit

MAX_EXPONENT = 700.0  # exp(700) ~ 1e304, below float64's overflow


@dataclass
class DecayFit:
    amplitude: float
    rate_per_m: float
    ci95_per_m: tuple[float, float]
    r2: float
    points: int
    ci_dof: int | None = None  # degrees of freedom of the CI's t quantile; None: points - 2
    #: angle offsets (deg) of the bins fitted together with this one (:func:`fit_decay_across`)
    joint_offsets_deg: tuple[float, ...] = (0.0,)

    @property
    def dof(self) -> int:
        return self.points - 2 if self.ci_dof is None else self.ci_dof

    def to_dict(self) -> dict:
        return {"amplitude_mps": self.amplitude, "rate_per_m": self.rate_per_m,
                "ci95_per_m": list(self.ci95_per_m), "ci95_dof": self.dof, "r2": self.r2,
                "points": self.points, "joint_bins_offset_deg": list(self.joint_offsets_deg)}


def _model(rho, a, k):
    return a * np.exp(-k * rho)


def fit_decay(rho_m: np.ndarray, value: np.ndarray, sigma: np.ndarray) -> DecayFit | None:
    """Fit one profile; ``None`` with fewer than 5 points or no convergence."""
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
    half = stdtrit(dof, 0.975) * float(np.sqrt(max(cov[1, 1], 0.0)))
    w = 1 / sigma ** 2
    resid = value - _model(rho_m, a, k)
    mean = np.sum(w * value) / np.sum(w)
    r2 = 1 - np.sum(w * resid ** 2) / np.sum(w * (value - mean) ** 2)
    return DecayFit(float(a), float(k), (float(k - half), float(k + half)), float(r2), len(rho_m))


def fit_decay_across(rho_m: list, value: list, sigma: list, offsets_rad: np.ndarray,
                     centre: int) -> DecayFit | None:
    """Fit neighbouring bins' profiles jointly, ``A_m exp(-(k + s dbeta_m) rho)``: an amplitude
    per profile, the rate linear in the angle offset ``dbeta_m`` (``offsets_rad``, 0 for the
    ``centre`` profile). Returns the centre's amplitude and ``k``, ``k``'s 95 % CI from the
    scaled covariance (``t(0.975, n - p)``), the R² and point count of the centre's own profile.
    ``None`` when the centre profile cannot be fitted alone (:func:`fit_decay`) or the joint fit
    does not converge; with fewer than three profiles, the centre's own fit."""
    from scipy.optimize import least_squares

    own = fit_decay(rho_m[centre], value[centre], sigma[centre])
    if own is None or len(rho_m) < 3:
        return own
    which = np.concatenate([np.full(len(r), i) for i, r in enumerate(rho_m)])
    rho, val, sig = (np.concatenate(x) for x in (rho_m, value, sigma))
    dbeta = np.asarray(offsets_rad, float)[which]

    def decay(p):
        # a trial step far below zero rate would overflow exp: capped, it is a worse step
        # that Levenberg-Marquardt rejects as it would an infinite one
        exponent = -(p[0] + p[1] * dbeta) * rho
        return np.exp(np.minimum(exponent, MAX_EXPONENT)), exponent < MAX_EXPONENT

    def resid(p):
        return (p[2:][which] * decay(p)[0] - val) / sig

    rows = np.arange(len(val))

    def jacobian(p):
        """d resid / d (k, s, A_0 ...): the exponent's slopes where it is not capped."""
        e, free = decay(p)
        d_rate = -p[2:][which] * e * rho * free / sig
        out = np.zeros((len(val), len(p)))
        out[:, 0], out[:, 1] = d_rate, d_rate * dbeta
        out[rows, 2 + which] = e / sig
        return out

    start = [v[np.argmin(r)] for r, v in zip(rho_m, value)]
    start[centre] = own.amplitude
    sol = least_squares(resid, np.r_[own.rate_per_m, 0.0, start], jac=jacobian, method="lm",
                        max_nfev=4000)
    dof = len(val) - len(sol.x)
    if not sol.success or dof < 1:
        return None
    try:
        cov = np.linalg.inv(sol.jac.T @ sol.jac) * np.sum(sol.fun ** 2) / dof
    except np.linalg.LinAlgError:
        return None
    k, a = float(sol.x[0]), float(sol.x[2 + centre])
    half = stdtrit(dof, 0.975) * float(np.sqrt(max(cov[0, 0], 0.0)))
    r, v, s = rho_m[centre], value[centre], sigma[centre]
    w = 1 / s ** 2
    mean = np.sum(w * v) / np.sum(w)
    r2 = 1 - np.sum(w * (v - _model(r, a, k)) ** 2) / np.sum(w * (v - mean) ** 2)
    offsets = tuple(float(np.rad2deg(o)) for o in offsets_rad)
    return DecayFit(a, k, (k - half, k + half), float(r2), len(r), joint_offsets_deg=offsets)
