"""Grouser effective-radius models of the SOFT velocity-field model, and choosing among them.

The issue's models (McGill and Concordia SOFT work), ``g = cos((theta - theta1 +
omega t) n_G)``, ``omega t`` measured as the wheel's grouser angle in each frame:
(2) piecewise ``R + h g`` where ``g >= 0``; (4) cosine ``R + h/2 (1 + g)``;
(5) cosine series ``R + h/2 (1 + 3/2 g - 1/2 g^3)``; (6) gear ``R + h/2 (1 + tanh(gamma g))``.

Selection: on every frame pair's (not averaged) world-frame field, each model's
prediction ``A_c(beta) exp(-a_c(beta) (r - R_e))`` for both components, with the
decay rates ``a_c`` of the mean-field fits and the amplitude of each beta bin by
linear least squares, for ``theta1`` over a grid of 16 across a grouser pitch (and
``gamma`` in 0.5..12 for (6)); score = RMS residual (m/s) at the best parameters.
"""

from __future__ import annotations

import numpy as np

MODELS = ("piecewise", "cosine", "cosine_series", "gear")
GAMMAS = (0.5, 1.0, 1.5, 2.0, 3.0, 4.0, 6.0, 8.0, 12.0)


def effective_radius(theta: np.ndarray, wheel_angle: np.ndarray, radius: float, height: float,
                     count: int, model: str, theta1: float, gamma: float = 3.0) -> np.ndarray:
    """``R_e`` (same unit as ``radius``) at ``theta`` with the wheel turned by ``wheel_angle``."""
    g = np.cos((theta - theta1 + wheel_angle) * count)
    if model == "piecewise":
        return radius + height * np.maximum(g, 0.0)
    if model == "cosine":
        return radius + height / 2 * (1 + g)
    if model == "cosine_series":
        return radius + height / 2 * (1 + 1.5 * g - 0.5 * g ** 3)
    if model == "gear":
        return radius + height / 2 * (1 + np.tanh(gamma * g))
    raise ValueError(f"unknown grouser model {model!r}; known: {MODELS}")


def select_model(samples: dict, radius_px: float, height_px: float, count: int,
                 rates_per_m: dict, px_per_m: float) -> dict:
    """Score every model; ``samples``: arrays ``r_px, theta, bin, wheel_angle, v_r, v_t`` (m/s).

    ``rates_per_m``: ``{"r": k per bin, "t": alpha3 per bin}`` (NaN where no fit).
    Returns ``{"chosen", "scores_mps": {model: rms}, "theta1_rad": {...}, "gamma"}``.
    """
    nb = int(samples["bin"].max()) + 1
    pitch = 2 * np.pi / count
    components = []  # what the 192 parameter sets share: (where, -rate, y, bin, sum of y^2)
    for comp, key in (("r", "v_r"), ("t", "v_t")):
        rate = rates_per_m[comp][samples["bin"]]
        ok = np.isfinite(rate)
        y, b = samples[key][ok], samples["bin"][ok]
        components.append((ok, -rate[ok], y, b, np.bincount(b, y * y, nb)))
    n = sum(int(ok.sum()) for ok, *_ in components)
    scores, theta1s, best_gamma = {}, {}, None
    for model in MODELS:
        best = (np.inf, 0.0, None)
        for gamma in (GAMMAS if model == "gear" else (None,)):
            for theta1 in np.arange(16) * pitch / 16:
                r_e = effective_radius(samples["theta"], samples["wheel_angle"], radius_px,
                                       height_px, count, model, theta1, gamma or 3.0)
                rho = (samples["r_px"] - r_e) / px_per_m
                sse = 0.0
                for ok, minus_rate, y, b, syy in components:
                    e = np.exp(minus_rate * rho[ok])
                    sye = np.bincount(b, y * e, nb)
                    see = np.bincount(b, e * e, nb)
                    explained = np.where(see > 0, sye ** 2 / np.maximum(see, 1e-300), 0)
                    sse += float(np.sum(syy - explained))
                rms = np.sqrt(sse / max(n, 1))
                if rms < best[0]:
                    best = (rms, float(theta1), gamma)
        scores[model], theta1s[model] = float(best[0]), best[1]
        if model == "gear":
            best_gamma = best[2]
    ranked = sorted(scores, key=scores.get)
    return {"chosen": ranked[0], "scores_mps": scores, "theta1_rad": theta1s,
            "gamma": best_gamma,
            "margin_percent": 100 * (scores[ranked[1]] - scores[ranked[0]]) / scores[ranked[1]]}
