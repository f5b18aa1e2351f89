"""Terramechanics curve set: 50 slips x 3 loads, every effect on (goal < 0.5 s)."""

from __future__ import annotations

import time

import numpy as np

from terramechanics import EFFECTS, load_model
from terramechanics.model_file import SHIPPED_MODELS

MODEL = SHIPPED_MODELS / "bb2_sand.toml"
GOAL_S = 0.5


def main(quick: bool = False) -> dict:
    model = load_model(MODEL).with_effects(**{name: True for name in EFFECTS})
    loads = np.array([70.0, 180.0, 300.0])[:, None]
    slips = np.linspace(-0.5, 0.9, 50)[None, :]
    repeats = 3 if quick else 10
    times = []
    for _ in range(repeats):
        start = time.perf_counter()
        curves = model.curves(loads, slips, multipass=1, gravity_mps2=3.71)
        times.append(time.perf_counter() - start)
    best = min(times)
    worst_residual = float(np.max(np.abs(curves["fz_residual_n"]) / curves["load_n"]))
    print(f"{'case':<34}{'best s':>10}{'median s':>10}{'goal s':>8}{'max |W-Fz|/W':>15}")
    print(f"{'50 slips x 3 loads, all effects':<34}{best:>10.4f}{np.median(times):>10.4f}"
          f"{GOAL_S:>8.2f}{worst_residual:>15.1e}")
    return {"curve_set_best_s": best, "curve_set_median_s": float(np.median(times)),
            "goal_s": GOAL_S, "points": int(curves["dp_n"].size),
            "max_rel_fz_residual": worst_residual,
            "all_converged": bool(curves["converged"].all())}
