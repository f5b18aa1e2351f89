"""Weighted least-squares polynomials in slip, solved in a Chebyshev basis on the scaled slip
interval and converted to the power coefficients ``a_i`` of ``slip**i`` that the WPM CSV
carries (RUAG WPAT: "a least-squares polynomial curve fit is computed to obtain a continuous
function"; the power form is the one a simulator evaluates).
"""

from __future__ import annotations

import functools
from dataclasses import dataclass
from fractions import Fraction
from math import comb

import numpy as np
from numpy.polynomial import chebyshev


def scaled_slip(slip, slip_min: float, slip_max: float) -> np.ndarray:
    """Slip mapped affinely from [slip_min, slip_max] onto [-1, 1]."""
    return (2.0 * np.asarray(slip, dtype=float) - (slip_min + slip_max)) / (slip_max - slip_min)


def horner(coefficients, slip) -> np.ndarray:
    """``sum_i a_i slip**i`` with ``a`` along the last axis of ``coefficients`` (rows of
    coefficients broadcast against ``slip``)."""
    a = np.asarray(coefficients, dtype=float)
    s = np.asarray(slip, dtype=float)
    out = np.zeros(np.broadcast_shapes(a.shape[:-1], s.shape))
    for k in range(a.shape[-1] - 1, -1, -1):
        out = out * s + a[..., k]
    return out


def _chebyshev_power_coefficients(k: int) -> list[int]:
    """Integer power coefficients of the Chebyshev polynomial T_k(x)."""
    t_prev, t = [1], [0, 1]
    if k == 0:
        return t_prev
    for _ in range(k - 1):
        t_next = [0] + [2 * c for c in t]
        for i, c in enumerate(t_prev):
            t_next[i] -= c
        t_prev, t = t, t_next
    return t


@functools.lru_cache(maxsize=256)
def power_matrix(slip_min: float, slip_max: float, degree: int) -> np.ndarray:
    """Matrix ``M`` with ``a = M @ c``: Chebyshev coefficients ``c`` on the scaled interval to
    power coefficients ``a`` of slip. Built in exact rational arithmetic from the float
    endpoints (``x = alpha + beta*slip``), each entry rounded once to double."""
    lo, hi = Fraction(slip_min), Fraction(slip_max)
    beta, alpha = 2 / (hi - lo), -(hi + lo) / (hi - lo)
    # x**j = sum_i C(j, i) alpha**(j - i) beta**i slip**i
    x_powers = [[comb(j, i) * alpha ** (j - i) * beta ** i for i in range(j + 1)]
                for j in range(degree + 1)]
    m = [[Fraction(0)] * (degree + 1) for _ in range(degree + 1)]
    for k in range(degree + 1):
        for j, t_kj in enumerate(_chebyshev_power_coefficients(k)):
            if t_kj:
                for i, x_ji in enumerate(x_powers[j]):
                    m[i][k] += t_kj * x_ji
    return np.array([[float(v) for v in row] for row in m])


@dataclass(frozen=True)
class LeastSquares:
    """One weighted least-squares solve: power coefficients, fitted values at the points,
    leverages (diagonal of the hat matrix) and the 2-norm condition number of the weighted
    Chebyshev design matrix that was solved."""

    coefficients: np.ndarray
    fitted: np.ndarray
    leverage: np.ndarray
    condition_number: float


def weighted_lstsq(slip, value, weights, degree: int, slip_min: float,
                   slip_max: float) -> LeastSquares:
    """Minimise ``sum w_i (y_i - p(s_i))**2`` over degree-``degree`` polynomials by QR of the
    weighted Chebyshev-Vandermonde matrix on [slip_min, slip_max] (full rank assumed: at least
    degree + 1 distinct slips)."""
    root_w = np.sqrt(np.asarray(weights, dtype=float))
    design = chebyshev.chebvander(scaled_slip(slip, slip_min, slip_max), degree) * root_w[:, None]
    q, r = np.linalg.qr(design)
    cheb = np.linalg.solve(r, q.T @ (root_w * np.asarray(value, dtype=float)))
    coefficients = power_matrix(float(slip_min), float(slip_max), degree) @ cheb
    singular = np.linalg.svd(r, compute_uv=False)
    return LeastSquares(coefficients=coefficients, fitted=horner(coefficients, slip),
                        leverage=np.sum(q * q, axis=1),
                        condition_number=float(singular[0] / singular[-1]))


def lobatto_grid(slip_min: float, slip_max: float, n: int) -> np.ndarray:
    """Chebyshev-Lobatto points on [slip_min, slip_max], ends included, increasing."""
    x = -np.cos(np.pi * np.arange(n) / (n - 1))
    return slip_min + (x + 1.0) * 0.5 * (slip_max - slip_min)
