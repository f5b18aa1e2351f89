"""Comparisons across test modes: towed motion resistance against powered runs near zero slip.

A towed (unpowered) wheel's motion resistance is ``R = T/r - DP`` with ``T`` about 0, i.e.
minus its drawbar pull. Labs compare it with ``R`` of powered speed-control runs
extrapolated to zero slip (e.g. the ExoMars BB2 wheel at 180 N: 18 N on fresh soil falling
to 15 N by multipass 2).
"""

from __future__ import annotations

from collections import defaultdict

import numpy as np

from run_results.result import RunResult


def _group_key(result: RunResult) -> tuple:
    c = result.condition
    return (c.get("wheel"), c.get("soil"), c.get("multipass"), c.get("load_n"))


def resistance_at_zero_slip(slip: np.ndarray, resistance_n: np.ndarray,
                            se_n: np.ndarray) -> tuple[float, float, str]:
    """``(R0, SE, how)``: linear interpolation at slip 0 between the nearest runs on either
    side (resistance is smallest near zero slip and grows both ways, so a straight line
    through all runs would overestimate it); linear extrapolation from the two runs nearest
    zero when all lie on one side; the run's own value when there is one run."""
    order = np.argsort(slip)
    s, r, e = slip[order], resistance_n[order], se_n[order]
    if s.size == 1:
        return float(r[0]), float(e[0]), "single run"
    below, above = np.flatnonzero(s <= 0), np.flatnonzero(s >= 0)
    if below.size and above.size:
        i, j, how = below[-1], above[0], "interpolated"
    else:
        i, j = (0, 1) if not below.size else (s.size - 2, s.size - 1)
        how = "extrapolated"
    if s[j] == s[i]:
        return float((r[i] + r[j]) / 2), float(np.hypot(e[i], e[j]) / 2), how
    w = (0.0 - s[i]) / (s[j] - s[i])
    return float((1 - w) * r[i] + w * r[j]), float(np.hypot((1 - w) * e[i], w * e[j])), how


def towed_vs_powered(results: list[RunResult], max_abs_slip: float = 0.15) -> list[dict]:
    """Per (wheel, soil, multipass, load): towed ``R`` against powered ``R`` at slip 0.

    Powered ``R`` at slip 0 comes from the speed-control runs with ``|slip| <= max_abs_slip``
    (``resistance_at_zero_slip``).
    """
    towed, powered = defaultdict(list), defaultdict(list)
    for r in results:
        if r.status == "no_stable_phase" or "resistance_n" not in r.quantities:
            continue
        if r.mode == "towed":
            towed[_group_key(r)].append(r)
        elif r.mode == "speed_control" and abs(r.quantities["slip"].mean) <= max_abs_slip:
            powered[_group_key(r)].append(r)
    rows = []
    for key in sorted(towed, key=str):
        wheel, soil, multipass, load_n = key
        t_r = np.array([r.quantities["resistance_n"].mean for r in towed[key]])
        t_se = np.array([r.quantities["resistance_n"].se for r in towed[key]])
        row = {"wheel": wheel, "soil": soil, "multipass": multipass, "load_n": load_n,
               "towed_runs": [r.run_id for r in towed[key]],
               "towed_resistance_n": float(t_r.mean()),
               "towed_resistance_se_n": float(np.sqrt(np.sum(t_se ** 2)) / t_se.size),
               "towed_slip": float(np.mean([r.quantities["slip"].mean for r in towed[key]])),
               "powered_runs": [r.run_id for r in powered.get(key, [])],
               "powered_resistance_at_zero_slip_n": None, "powered_resistance_se_n": None,
               "powered_method": None, "difference_n": None, "max_abs_slip": max_abs_slip}
        runs = powered.get(key, [])
        if runs:
            slip = np.array([r.quantities["slip"].mean for r in runs])
            res = np.array([r.quantities["resistance_n"].mean for r in runs])
            se = np.array([r.quantities["resistance_n"].se for r in runs])
            r0, r0_se, how = resistance_at_zero_slip(slip, res, se)
            row.update(powered_resistance_at_zero_slip_n=r0, powered_resistance_se_n=r0_se,
                       powered_method=how, difference_n=row["towed_resistance_n"] - r0)
        rows.append(row)
    return rows
