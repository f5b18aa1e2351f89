"""Randomised monotone shapes: the families the testbed draws each effect's law from.

A shape is a JSON-ready dict, drawn once per campaign, evaluated by :func:`evaluate`:

- ``pchip``: a monotone cubic (Fritsch & Carlson 1980, SIAM J. Numer. Anal. 17(2):238-246;
  scipy's ``PchipInterpolator``) through knots at 0, ``k`` breakpoints drawn uniformly in
  (0, 1), and 1, with values rising from ``start`` to 1 in Dirichlet(1, ..., 1) steps: every
  non-decreasing curve through those end points can be drawn, none is preferred;
- ``power``: ``x^p`` with the exponent drawn.

So no effect follows one published law: its exponents and breakpoints change from campaign to
campaign.
"""

from __future__ import annotations

import numpy as np
from scipy.interpolate import PchipInterpolator


def draw_pchip(rng: np.random.Generator, start: float, breakpoints: int = 2) -> dict:
    """A non-decreasing shape on [0, 1] from ``start`` at 0 to 1 at 1."""
    inner = np.sort(rng.uniform(0.05, 0.95, breakpoints))
    steps = rng.dirichlet(np.ones(breakpoints + 1))
    values = start + (1 - start) * np.concatenate([[0.0], np.cumsum(steps)])
    return {"kind": "pchip", "x": [0.0, *inner.tolist(), 1.0], "y": values.tolist()}


def draw_power(rng: np.random.Generator, low: float, high: float) -> dict:
    """``x^p``, ``p`` uniform in [low, high]."""
    return {"kind": "power", "p": float(rng.uniform(low, high))}


def evaluate(shape: dict, x) -> np.ndarray:
    """The shape at ``x`` (clipped to [0, 1])."""
    x = np.clip(np.asarray(x, dtype=float), 0.0, 1.0)
    if shape["kind"] == "pchip":
        return PchipInterpolator(shape["x"], shape["y"])(x)
    if shape["kind"] == "power":
        return x ** shape["p"]
    raise ValueError(f"unknown shape kind {shape['kind']!r}")
