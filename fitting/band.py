"""Confidence and prediction bands of a curve (docs/fitting.md, "Bands").

At slip ``s`` the curve is linear in its parameters ``theta = (a_0 ... a_n, J, K)`` with
gradient ``g(s)``; its variance is ``g^T C g`` (the delta method is exact for a linear
model: Seber & Lee 2003, Linear Regression Analysis, 2nd ed., sec. 5.1). A new run's mean
adds the run-to-run variance ``scatter_sd**2`` (the prediction interval, ibid. sec. 5.2).
"""

from __future__ import annotations

import numpy as np

from fitting.curve import PowerCurve
from fitting.polynomial import curve_value, parameter_gradient


def curve_variance(curve: PowerCurve, slip) -> np.ndarray:
    """``g(s)^T C g(s)`` at ``slip`` (any shape), NaN where the curve carries no covariance."""
    s = np.asarray(slip, dtype=float)
    if curve.covariance is None:
        return np.full(s.shape, np.nan)
    g = parameter_gradient(s, curve.degree)
    c = np.asarray(curve.covariance, dtype=float)
    return np.maximum(np.einsum("...i,ij,...j->...", g, c, g), 0.0)


def band(curve: PowerCurve, slip) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(mean, conf_half95, pred_half95)`` at ``slip`` (arrays shaped like it, in the
    curve's unit): the curve, the 95 % half-width of where the true curve lies
    (``k95 sqrt(g^T C g)``) and of where one new run's mean lies (``k95 sqrt(g^T C g +
    scatter_sd**2)``); NaN half-widths for a curve without uncertainty (unknown, not 0).
    No warning outside the fitted slip range (the caller has ``curve.outside_range``)."""
    s = np.asarray(slip, dtype=float)
    mean = curve_value(curve.coefficients, s, curve.step_below_zero, curve.slope_below_zero)
    var = curve_variance(curve, s)
    return mean, curve.k95 * np.sqrt(var), curve.k95 * np.sqrt(var + curve.scatter_sd ** 2)
