"""Comparisons across test modes: towed motion resistance against powered runs near zero slip.

A towed (unpowered) wheel's motion resistance is ``R = T/r - DP`` with ``T`` about 0, i.e.
minus its drawbar pull. Labs compare it with ``R`` of powered speed-control runs
extrapolated to zero slip (e.g. the ExoMars BB2 wheel at 180 N: 18 N on fresh soil falling
to 15 N by multipass 2).
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from run_results.result import RunResult
from swtlab_base.domain.replicates import with_repeatability
from swtlab_base.domain.results import (COLUMNS, budget_columns, check_results,
                                        not_measured_text, wheel_columns)


GROUP = ["wheel", "soil", "multipass", "load_set_n"]


def results_row(r: RunResult) -> dict:
    """One run's row of the results table (``swtlab_base.domain.results``, docs/results.md)."""
    c, w = r.condition, r.window
    row = {"campaign": r.campaign, "run_id": r.run_id, **wheel_columns(r.wheel), "soil": r.soil,
           "mode": c.mode, "multipass": c.multipass, "load_set_n": c.load_set_n,
           "slip_setpoint": c.slip_setpoint, "velocity_set_mps": c.velocity_set_mps,
           "gravity_mps2": c.gravity_mps2, "steer_deg": c.steer_deg, "status": r.status,
           "flags": "; ".join(r.flags), "window_found": w.found, "window_start_s": w.start_s,
           "window_end_s": w.end_s, "window_method": w.method, "no_window_reason": w.reason,
           "not_measured": not_measured_text(m for b in r.uncertainty.values()
                                             for m in b.not_measured)}
    for name, q in r.quantities.items():
        row.update({f"{name}_mean": q.mean, f"{name}_std": q.std, f"{name}_se": q.se})
        if name in r.uncertainty:
            row.update(budget_columns(name, r.uncertainty[name].to_dict()))
    row.update(r.oscillation)
    return row


def results_table(results: list[RunResult]) -> pd.DataFrame:
    """Run results as the one-row-per-run table of ``swtlab results`` (docs/results.md), for
    code without a database; checked against the schema (``swtlab_base.domain.check_results``)."""
    table = pd.DataFrame.from_records([results_row(r) for r in results],
                                      columns=None if results else list(COLUMNS))
    return check_results(with_repeatability(table))


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


def towed_vs_powered(table: pd.DataFrame, max_abs_slip: float = 0.15) -> list[dict]:
    """Per (wheel, soil, multipass, load): towed ``R`` against powered ``R`` at slip 0.

    ``table``: one row per run as ``swtlab results`` lists it (or :func:`results_table`).
    Powered ``R`` at slip 0 comes from the speed-control runs with ``|slip| <= max_abs_slip``
    (``resistance_at_zero_slip``).
    """
    if table.empty or "resistance_n_mean" not in table:
        return []
    usable = table[(table["status"] != "no_stable_phase") & table["resistance_n_mean"].notna()]
    towed = usable[usable["mode"] == "towed"]
    powered = usable[(usable["mode"] == "speed_control")
                     & (usable["slip_mean"].abs() <= max_abs_slip)]
    rows = []
    for key, runs in towed.groupby(GROUP, sort=True):
        wheel, soil, multipass, load_n = key
        se = runs["resistance_n_se"].to_numpy(float)
        row = {"wheel": wheel, "soil": soil, "multipass": int(multipass), "load_n": float(load_n),
               "towed_runs": list(runs["run_id"]),
               "towed_resistance_n": float(runs["resistance_n_mean"].mean()),
               "towed_resistance_se_n": float(np.sqrt(np.sum(se ** 2)) / se.size),
               "towed_slip": float(runs["slip_mean"].mean()),
               "powered_runs": [], "powered_resistance_at_zero_slip_n": None,
               "powered_resistance_se_n": None, "powered_method": None, "difference_n": None,
               "max_abs_slip": max_abs_slip}
        same = powered[(powered[GROUP] == pd.Series(key, index=GROUP)).all(axis=1)]
        if len(same):
            r0, r0_se, how = resistance_at_zero_slip(same["slip_mean"].to_numpy(float),
                                                     same["resistance_n_mean"].to_numpy(float),
                                                     same["resistance_n_se"].to_numpy(float))
            row.update(powered_runs=list(same["run_id"]), powered_resistance_at_zero_slip_n=r0,
                       powered_resistance_se_n=r0_se, powered_method=how,
                       difference_n=row["towed_resistance_n"] - r0)
        rows.append(row)
    return rows
