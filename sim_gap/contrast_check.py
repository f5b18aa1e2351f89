"""A law-free check of a confident call on the design's level contrasts.

Without a multipass or reduced-gravity effect, the runs of a multipass (or gravity) level
are the same physics as their twins at the first level: same wheel, load set and slip on
the same soil (gravity enters the built-in model only through the wheel load). So
whatever the chosen candidate's law misses elsewhere, its residuals at the two levels must
agree. If they differ systematically, something tied to that factor is at work that the
call leaves out: an effect whose law is not among the candidates (the held-out bench: a
multipass made by Wong's law, diagnosed with Krenn & Hirzinger's only, was called
``reduced_gravity`` alone). The residuals are compared pairwise (each run with its twin
at the factor's first level, matched on source, load set, slip and the other factors),
which removes the misfit that the call's law leaves at every level alike; a paired t-test
per quantity (Student 1908), the mean difference also at least ``MIN_SHIFT_SIGMA``. A
lack-of-fit test of the pure-error kind (Draper & Smith 1998, Applied Regression
Analysis, ch. 2.1), with the twin run standing in for the replicate.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from sim_gap.fit import quantities_of

#: factor column -> (its name in words, the effect tied to it)
TIED_FACTORS = {"multipass": ("multipass level", "multipass"),
                "gravity_mps2": ("gravity level", "reduced_gravity")}
#: twins differ in slip by at most this
SLIP_MATCH = 0.03
#: a paired difference must stand this many SE from zero (the confident call's margin) ...
Z_SHIFT = 4.0
#: ... and be at least this large in sigmas (smaller shifts change no conclusion)
MIN_SHIFT_SIGMA = 0.3
#: fewest twin pairs for the test
MIN_PAIRS = 4


def twin_differences(points: pd.DataFrame, residuals: np.ndarray, column: str
                     ) -> dict[float, np.ndarray]:
    """Per non-first level of ``column``: residual differences (pairs x quantities) of each
    run at that level minus its twin at the first level (nearest slip within
    ``SLIP_MATCH``, same source, load set and other factors)."""
    levels = np.unique(points[column].round(6))
    others = [c for c in ("source", "load_set_n", *TIED_FACTORS) if c in points and c != column]
    key = points[others].round(6).astype(str).agg("|".join, axis=1).to_numpy()
    level = points[column].round(6).to_numpy()
    slip = points["slip"].to_numpy(float)
    out = {}
    for value in levels[1:]:
        diffs = []
        for i in np.flatnonzero(level == value):
            twins = np.flatnonzero((level == levels[0]) & (key == key[i]))
            if twins.size == 0:
                continue
            j = twins[np.argmin(np.abs(slip[twins] - slip[i]))]
            if abs(slip[j] - slip[i]) <= SLIP_MATCH:
                diffs.append(residuals[i] - residuals[j])
        if len(diffs) >= MIN_PAIRS:
            out[float(value)] = np.array(diffs)
    return out


def contrast_problem(points: pd.DataFrame, residuals: np.ndarray, effects: list[str]
                     ) -> str | None:
    """Why a call cannot be confident: the standardised ``residuals`` (points x quantities,
    of the chosen candidate's fit) of a factor level differ from their twins' at the first
    level while ``effects`` (the call's and those the simulation already has) hold no
    effect tied to that factor; None if not."""
    names = quantities_of(points)
    for column, (words, effect) in TIED_FACTORS.items():
        if effect in effects or column not in points:
            continue
        for value, d in twin_differences(points, residuals, column).items():
            for k, q in enumerate(names):
                dq = d[:, k][np.isfinite(d[:, k])]
                if dq.size < MIN_PAIRS:
                    continue
                mean, se = dq.mean(), dq.std(ddof=1) / np.sqrt(dq.size)
                z = mean / se if se > 0 else (np.inf * np.sign(mean) if mean else 0.0)
                if abs(z) >= Z_SHIFT and abs(mean) >= MIN_SHIFT_SIGMA:
                    return (f"the residuals of {q} at {words} {value:g} differ from their "
                            f"twin runs' at {words} "
                            f"{np.unique(points[column].round(6))[0]:g} by {mean:+.2f} sigma "
                            f"({abs(z):.1f} SE over {dq.size} pairs), which no effect of the "
                            f"call explains: an effect tied to the {words} ({effect}, or "
                            "another) may be missing, under a law outside the candidates")
    return None
