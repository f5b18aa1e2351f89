"""Vectorised bracketed root solve for the sinkage (vertical equilibrium W = Fz)."""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

REL_TOL = 1e-6  # solve to 1e-6 W; the model reports converged where |W - Fz| < 1e-3 W


def solve_increasing(f: Callable[[np.ndarray, np.ndarray | None], np.ndarray], hi: np.ndarray,
                     target: np.ndarray, power: np.ndarray, max_iter: int = 80
                     ) -> tuple[np.ndarray, np.ndarray]:
    """Solve ``f(x) = target > 0`` elementwise for f increasing on [0, hi] from f(0) = 0.

    Regula falsi with the Anderson-Björck modification (Anderson & Björck 1973, BIT 13:
    253-264) on 1-D arrays, in ``u = x^power``: with ``power = n + 1/2`` the vertical force
    of a wheel is nearly linear in u (Bekker's rigid-wheel sinkage, ``W ~ z^((2n+1)/2)``;
    Wong, Theory of Ground Vehicles 2008, ch. 2), so few steps are needed. An element
    whose bracket holds no root ends at ``hi``. ``f(x, at)`` gives f at ``x`` for the
    elements ``at`` (indices; None: all of them): once half the elements are solved, a
    step evaluates only the others. Returns ``(x, f(x) - target)``.
    """
    target, hi = np.asarray(target, dtype=float), np.asarray(hi, dtype=float)
    a, fa = np.zeros_like(target), -target  # f(0) = 0: no sinkage, no force
    b, fb = hi ** power, f(hi, None) - target
    tol = REL_TOL * np.abs(target)
    x = hi.copy()  # the sinkages evaluated (b is their u = x^power)
    active = np.flatnonzero((fb >= 0) & (np.abs(fb) > tol))
    for _ in range(max_iter):
        if active.size == 0:
            break
        a_at, b_at, fa_at, fb_at = a[active], b[active], fa[active], fb[active]
        c = np.clip(b_at - fb_at * (b_at - a_at) / np.where(fb_at != fa_at, fb_at - fa_at, 1.0),
                    np.minimum(a_at, b_at), np.maximum(a_at, b_at))
        z = c ** (1.0 / power[active])
        if 2 * active.size > x.size:  # most unsolved: a whole evaluation costs less
            whole = x.copy()
            whole[active] = z
            fc = f(whole, None)[active] - target[active]
        else:
            fc = f(z, active) - target[active]
        flip = fc * fb_at < 0
        shrink = 1.0 - fc / np.where(fb_at != 0, fb_at, 1.0)
        a[active] = np.where(flip, b_at, a_at)
        fa[active] = np.where(flip, fb_at, fa_at * np.where(shrink > 0, shrink, 0.5))
        b[active], fb[active] = c, fc
        x[active] = z
        active = active[np.abs(fc) > tol[active]]
    return x, fb
