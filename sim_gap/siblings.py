"""Sibling contrasts: what one feature changes, measured at matched conditions.

When the points hold runs that differ in one feature (a lugged wheel and its smooth twin on
one soil, multipass 0 and a later pass, two gravity levels), each run of the treated side is
matched with the control side at the same set load and the same slip, the control's value
linearly interpolated in slip between its two nearest runs (never extrapolated), its
uncertainty propagated through the interpolation weights: ``u^2 = (1-w)^2 u_a^2 + w^2 u_b^2``
(GUM 5.1.2). The contrast of a (load, quantity) is the inverse-variance weighted mean of its
matched differences, with a 95 % interval (normal, 1.96 u). A base-model error common to both
sides cancels here; an effect must explain what is left.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from sim_gap.fit import quantities_of

Z95 = 1.959963984540054


def _features(points: pd.DataFrame) -> list[tuple[str, np.ndarray, np.ndarray, str]]:
    """``(feature, control mask, treated mask, words)`` for each one-feature difference."""
    out = []
    if "grouser_count" in points:
        lugged = (points["grouser_count"].to_numpy(float) > 0) & (
            points["grouser_height_m"].to_numpy(float) > 0)
        if lugged.any() and (~lugged).any():
            out.append(("grousers", ~lugged, lugged, "the lugged wheel minus its smooth twin"))
    mp = points["multipass"].to_numpy(int)
    for level in np.unique(mp)[1:]:
        out.append(("multipass", mp == mp.min(), mp == level,
                    f"multipass {level} minus multipass {mp.min()}"))
    g = points["gravity_mps2"].round(4).to_numpy()
    levels = np.unique(g)
    for level in levels[:-1]:
        out.append(("reduced_gravity", g == levels[-1], g == level,
                    f"gravity {level:g} m/s^2 minus {levels[-1]:g} m/s^2"))
    return out


def _control_at(slip_c, value_c, u_c, slip_t) -> tuple[np.ndarray, np.ndarray]:
    """Control values and uncertainties interpolated at ``slip_t`` (NaN outside)."""
    order = np.argsort(slip_c)
    s, v, u = slip_c[order], value_c[order], u_c[order]
    s_unique, inverse = np.unique(s, return_inverse=True)
    weights = 1.0 / u ** 2
    v_mean = np.bincount(inverse, weights * v) / np.bincount(inverse, weights)
    u_mean = 1.0 / np.sqrt(np.bincount(inverse, weights))
    inside = (slip_t >= s_unique[0]) & (slip_t <= s_unique[-1])
    j = np.clip(np.searchsorted(s_unique, slip_t) - 1, 0, max(len(s_unique) - 2, 0))
    if len(s_unique) == 1:
        same = np.isclose(slip_t, s_unique[0])
        return np.where(same, v_mean[0], np.nan), np.where(same, u_mean[0], np.nan)
    w = (slip_t - s_unique[j]) / (s_unique[j + 1] - s_unique[j])
    value = (1 - w) * v_mean[j] + w * v_mean[j + 1]
    u = np.sqrt(((1 - w) * u_mean[j]) ** 2 + (w * u_mean[j + 1]) ** 2)
    return np.where(inside, value, np.nan), np.where(inside, u, np.nan)


def contrasts(points: pd.DataFrame, sigma: dict[str, np.ndarray],
              predictions: dict[str, dict[str, np.ndarray]] | None = None) -> list[dict]:
    """The measured contrast of each one-feature difference per set load and quantity
    (``contrast``, ``u``, ``ci95``, ``slips`` matched, ``n``) and, for each entry of
    ``predictions`` (name -> quantity -> values at the points), the same contrast of the
    predictions (``predicted[name]``)."""
    predictions = predictions or {}
    load = points["load_set_n"].round(1).to_numpy()
    slip = points["slip"].to_numpy(float)
    out = []
    for feature, control, treated, words in _features(points):
        for level in np.unique(load[treated]):
            c, t = control & (load == level), treated & (load == level)
            if c.sum() < 1 or t.sum() < 1:
                continue
            for q in quantities_of(points):
                y = points[q].to_numpy(float)
                cm, tm_ = c & np.isfinite(y), t & np.isfinite(y)
                if not cm.any() or not tm_.any():
                    continue
                ctrl, u_ctrl = _control_at(slip[cm], y[cm], sigma[q][cm], slip[tm_])
                diff = y[tm_] - ctrl
                u = np.hypot(sigma[q][tm_], u_ctrl)
                ok = np.isfinite(diff)
                if not ok.any():
                    continue
                w = 1.0 / u[ok] ** 2
                mean, u_mean = float(np.sum(w * diff[ok]) / w.sum()), float(w.sum() ** -0.5)
                entry = {"feature": feature, "contrast_of": words, "load_n": float(level),
                         "quantity": q, "contrast": mean, "u": u_mean,
                         "ci95": [mean - Z95 * u_mean, mean + Z95 * u_mean],
                         "slips": [float(s) for s in slip[tm_][ok]], "n": int(ok.sum()),
                         "predicted": {}}
                for name, pred in predictions.items():
                    p_ctrl, _ = _control_at(slip[cm], pred[q][cm], np.ones(cm.sum()),
                                            slip[tm_])
                    d = (pred[q][tm_] - p_ctrl)[ok]
                    entry["predicted"][name] = float(np.sum(w * d) / w.sum())
                out.append(entry)
    return out
