"""Vectorised bracketed root solve for the sinkage (vertical equilibrium W = Fz)."""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

REL_TOL = 1e-6  # solve to 1e-6 W; the model reports converged where |W - Fz| < 1e-3 W


def solve_increasing(f: Callable[[np.ndarray], np.ndarray], lo: np.ndarray, hi: np.ndarray,
                     target: np.ndarray, max_iter: int = 80) -> tuple[np.ndarray, np.ndarray]:
    """Solve ``f(x) = target`` elementwise for f increasing on [lo, hi] (Illinois method).

    Regula falsi with the Illinois modification (Dowell & Jarratt 1971) on whole
    arrays; an element whose bracket holds no root ends at the nearer bound. Returns
    ``(x, f(x) - target)``.
    """
    a, b = np.array(lo, dtype=float), np.array(hi, dtype=float)
    fa, fb = f(a) - target, f(b) - target
    tol = REL_TOL * np.abs(target)
    no_root = (fa > 0) | (fb < 0)
    x = np.where(np.abs(fa) < np.abs(fb), a, b)
    fx = np.where(np.abs(fa) < np.abs(fb), fa, fb)
    for _ in range(max_iter):
        done = no_root | (np.abs(fx) <= tol)
        if done.all():
            break
        denom = np.where(fb != fa, fb - fa, 1.0)
        c = np.clip(b - fb * (b - a) / denom, np.minimum(a, b), np.maximum(a, b))
        fc = f(c) - target
        flip = fc * fb < 0
        a, fa = np.where(flip, b, a), np.where(flip, fb, fa * 0.5)
        b, fb = c, fc
        x, fx = np.where(done, x, c), np.where(done, fx, fc)
    return x, fx
