"""A tabulated simulation: another tool's output as a points CSV (docs/points-csv.md), read
at the measured conditions by linear interpolation in slip within each simulated condition
(same wheel, set load, multipass level and gravity). Never extrapolated: a measured slip
outside a condition's simulated slips, or a condition that was not simulated, is an error
that says which."""

from __future__ import annotations

import numpy as np
import pandas as pd

from sim_gap.points_csv import WHEEL_KEY
from sim_gap.vocabulary import QUANTITIES

#: the columns that make a condition; compared after rounding to 6 decimals
CONDITION = (*WHEEL_KEY, "load_set_n", "multipass", "gravity_mps2")


def _groups(frame: pd.DataFrame) -> dict[tuple, np.ndarray]:
    """Row indices per condition."""
    out: dict[tuple, list[int]] = {}
    for i, row in enumerate(frame[list(CONDITION)].astype(float).round(6).to_numpy()):
        out.setdefault(tuple(float(v) for v in row), []).append(i)
    return {k: np.array(v) for k, v in out.items()}


def at_points(table: pd.DataFrame, points: pd.DataFrame, source: str) -> dict[str, np.ndarray]:
    """Each simulated quantity of ``table`` at the slips of ``points`` (NaN for a quantity
    the table lacks at that condition)."""
    missing = [c for c in CONDITION if c not in points]
    if missing:
        raise ValueError(f"{source}: the measured points lack {', '.join(missing)}, needed to "
                         "find their condition in a tabulated simulation")
    out = {q: np.full(len(points), np.nan) for q in QUANTITIES}
    groups = _groups(table)
    slips = points["slip"].to_numpy(float)
    for key, idx in _groups(points).items():
        where = ", ".join(f"{c} {v:g}" for c, v in zip(CONDITION, key))
        if key not in groups:
            raise ValueError(f"{source}: no simulated rows at the measured condition ({where})")
        sim = table.iloc[groups[key]].sort_values("slip")
        lo, hi = sim["slip"].min(), sim["slip"].max()
        outside = slips[idx][(slips[idx] < lo - 1e-9) | (slips[idx] > hi + 1e-9)]
        if outside.size:
            raise ValueError(f"{source}: measured slip {outside[0]:g} is outside the simulated "
                             f"slips [{lo:g}, {hi:g}] at ({where}); a tabulated simulation is "
                             "not extrapolated (simulate those slips)")
        for q in QUANTITIES:
            if q in sim and sim[q].notna().sum() >= 2:
                ok = sim[q].notna().to_numpy()
                s, v = sim["slip"].to_numpy(float)[ok], sim[q].to_numpy(float)[ok]
                inside = (slips[idx] >= s[0] - 1e-9) & (slips[idx] <= s[-1] + 1e-9)
                out[q][idx[inside]] = np.interp(slips[idx][inside], s, v)
    return out
