"""Weighted least-squares polynomials in slip, solved in a Chebyshev basis on the scaled slip
interval and converted to the power coefficients ``a_i`` of ``slip**i`` that the WPM CSV
carries (RUAG WPAT: "a least-squares polynomial curve fit is computed to obtain a continuous
function"; the power form is the one a simulator evaluates), optionally plus a braked
branch ``[slip < 0] (J + K slip)``: a step and a change of slope at zero slip (braked/towed
vs driven wheel; docs/fitting.md, "The join at zero slip").
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


BRANCH_TERMS = (0, 1, 2)  # braked-branch terms: none, the step J, the step J and slope K


def curve_value(coefficients, slip, step_below_zero=0.0, slope_below_zero=0.0) -> np.ndarray:
    """``sum_i a_i slip**i``, plus ``J + K slip`` where ``slip < 0`` (the braked branch:
    ``J`` = ``step_below_zero``, ``K`` = ``slope_below_zero``, one per row of
    ``coefficients``, broadcast like them); zero slip belongs to the driven side."""
    s = np.asarray(slip, dtype=float)
    step, slope = (np.asarray(x, dtype=float) for x in (step_below_zero, slope_below_zero))
    if not (step.any() or slope.any()):  # a plain polynomial: no branch to add
        return horner(coefficients, s)
    return horner(coefficients, s) + np.where(s < 0, step + slope * s, 0.0)


def _braked_span(slip_min: float) -> float:
    """Width of the braked side of the slip range (1 where there is none: unused)."""
    return -slip_min if slip_min < 0 else 1.0


def branch_design(slip, slip_min: float, slip_max: float, degree: int,
                  branch: int) -> np.ndarray:
    """Design matrix: Chebyshev-Vandermonde columns on the scaled interval, then the first
    ``branch`` of the braked-branch columns ``[slip < 0]``, ``x [slip < 0]`` with ``x`` the
    slip over the braked span (``slip / -slip_min``: -1 ... 0), for a well-conditioned
    matrix."""
    s = np.asarray(slip, dtype=float)
    below = (s < 0).astype(float)
    columns = [below, below * s / _braked_span(slip_min)][:branch]
    return np.column_stack([chebyshev.chebvander(scaled_slip(s, slip_min, slip_max), degree),
                            *columns])


def branch_from_solution(solution, slip_min: float, slip_max: float,
                         degree: int) -> tuple[np.ndarray, np.ndarray]:
    """(power coefficients, (J, K)) from the solution vector(s) along the last axis of a
    :func:`branch_design` solve (missing branch terms are 0)."""
    solution = np.asarray(solution, dtype=float)
    coefficients = solution[..., :degree + 1] @ power_matrix(slip_min, slip_max, degree).T
    branch = np.zeros(solution.shape[:-1] + (2,))
    terms = solution[..., degree + 1:]
    branch[..., :terms.shape[-1]] = terms
    branch[..., 1] /= _braked_span(slip_min)
    return coefficients, branch


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
    """One weighted least-squares solve: power coefficients, the braked branch ``(J, K)``
    (``branch`` of them fitted, the others 0) and their standard-error factors
    ``sqrt([(X^T W X)^-1]_kk)`` (NaN where not fitted), fitted values at the points,
    leverages (diagonal of the hat matrix), the 2-norm condition number of the weighted
    design matrix that was solved, and ``covariance``: ``(X^T W X)^-1`` of the parameters
    ``(a_0 ... a_n, J, K)`` (:func:`parameter_gradient`; zero rows for terms not fitted),
    unscaled (the covariance when the weights are 1/sigma^2)."""

    coefficients: np.ndarray
    branch: int
    below_zero: np.ndarray
    below_zero_se: np.ndarray
    fitted: np.ndarray
    leverage: np.ndarray
    condition_number: float
    covariance: np.ndarray

    @property
    def n_parameters(self) -> int:
        return len(self.coefficients) + self.branch


def weighted_lstsq(slip, value, weights, degree: int, slip_min: float,
                   slip_max: float, branch: int = 0) -> LeastSquares:
    """Minimise ``sum w_i (y_i - p(s_i) - [s_i < 0](J + K s_i))**2`` over degree-``degree``
    polynomials ``p`` and the first ``branch`` of (J, K) by QR of the weighted design matrix
    (:func:`branch_design`) on [slip_min, slip_max] (full rank assumed: at least degree + 1
    distinct slips, and with a branch enough slips on each side of zero)."""
    root_w = np.sqrt(np.asarray(weights, dtype=float))
    design = branch_design(slip, slip_min, slip_max, degree, branch) * root_w[:, None]
    q, r = np.linalg.qr(design)
    solution = np.linalg.solve(r, q.T @ (root_w * np.asarray(value, dtype=float)))
    coefficients, below = branch_from_solution(solution, float(slip_min), float(slip_max),
                                               degree)
    factor = np.sqrt(np.sum(np.linalg.inv(r)[degree + 1:] ** 2, axis=1))  # (R^T R)^-1 diagonal
    se = np.full(2, np.nan)
    se[:branch] = factor * np.array([1.0, 1.0 / _braked_span(slip_min)])[:branch]
    singular = np.linalg.svd(r, compute_uv=False)
    to_parameters = solution_to_parameters(float(slip_min), float(slip_max), degree,
                                           design.shape[1])
    r_inv_t = np.linalg.inv(r).T @ to_parameters  # Cov(solution) = R^-1 R^-T
    return LeastSquares(coefficients=coefficients, branch=branch, below_zero=below,
                        below_zero_se=se, fitted=curve_value(coefficients, slip, *below),
                        leverage=np.sum(q * q, axis=1),
                        condition_number=float(singular[0] / singular[-1]),
                        covariance=r_inv_t.T @ r_inv_t)


def solution_to_parameters(slip_min: float, slip_max: float, degree: int,
                           n_solution: int) -> np.ndarray:
    """Matrix ``T`` (n_solution x degree + 3) with ``theta = solution @ T``: a
    :func:`branch_design` solution (Chebyshev coefficients, then branch terms) to the
    parameters ``(a_0 ... a_n, J, K)`` (linear: :func:`branch_from_solution` of the unit
    vectors)."""
    coefficients, branch = branch_from_solution(np.eye(n_solution), slip_min, slip_max, degree)
    return np.hstack([coefficients, branch])


def parameter_gradient(slip, degree: int) -> np.ndarray:
    """``g(s) = (1, s, ..., s**n, [s < 0], [s < 0] s)`` along the last axis: the curve's
    derivative by its parameters ``(a_0 ... a_n, J, K)`` (the curve is linear in them)."""
    s = np.asarray(slip, dtype=float)[..., None]
    below = (s < 0).astype(float)
    return np.concatenate([s ** np.arange(degree + 1), below, below * s], axis=-1)


def lobatto_grid(slip_min: float, slip_max: float, n: int) -> np.ndarray:
    """Chebyshev-Lobatto points on [slip_min, slip_max], ends included, increasing."""
    x = -np.cos(np.pi * np.arange(n) / (n - 1))
    return slip_min + (x + 1.0) * 0.5 * (slip_max - slip_min)
