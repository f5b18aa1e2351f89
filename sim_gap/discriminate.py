"""The test that would tell two fitted candidates apart: the extra conditions where their
predictions differ most, in units of the fitting uncertainty (a simple optimal-design
criterion: the largest standardised prediction difference)."""

from __future__ import annotations

import numpy as np
import pandas as pd

from sim_gap.fit import quantities_of
from sim_gap.points_csv import WHEEL_KEY
from sim_gap.simulated import Simulated
from sim_gap.vocabulary import model_error_floor
from swtlab_base.domain.gravity import MARS_GRAVITY_MPS2, MOON_GRAVITY_MPS2

#: gravity levels proposed when a campaign has only one: Mars and the Moon
PROPOSED_GRAVITY_MPS2 = (MARS_GRAVITY_MPS2, MOON_GRAVITY_MPS2)


def _grid(loads, slips, multipass, gravity) -> pd.DataFrame:
    w, s, m, g = np.meshgrid(loads, slips, multipass, gravity, indexing="ij")
    return pd.DataFrame({"load_set_n": w.ravel(), "wheel_load_n": w.ravel(), "slip": s.ravel(),
                         "multipass": m.ravel().astype(int), "gravity_mps2": g.ravel()})


#: the wheel of the "smooth wheel" proposal (grousers removed, same rim)
SMOOTH_WHEEL = {"wheel.grouser_count": 0, "wheel.grouser_height_m": 0.0}


def proposals(points: pd.DataFrame, grousered: bool = False
              ) -> list[tuple[str, pd.DataFrame, dict[str, float]]]:
    """Extra tests a lab can run, each as the points it would measure and the change of
    wheel it needs (a smooth wheel, for a ``grousered`` one, tells lug effects from soil
    effects)."""
    loads = np.unique(points["load_set_n"])
    mps = np.unique(points["multipass"])
    gs = np.unique(points["gravity_mps2"].round(4))
    slips = np.array([0.1, 0.3, 0.5])
    other_g = [g for g in PROPOSED_GRAVITY_MPS2 if not np.any(np.isclose(gs, g, atol=0.05))][0]
    out = [
        (f"add a load ({1.6 * loads.max():.0f} N and {0.5 * loads.min():.0f} N)",
         _grid([0.5 * loads.min(), 1.6 * loads.max()], slips, mps[:1], gs[:1])),
        (f"run multipass level {mps.max() + 1}", _grid(loads, slips, [mps.max() + 1], gs[:1])),
        (f"test at another gravity ({other_g} m/s^2, gravity-offload rig or parabolic flight)",
         _grid(loads, slips, mps[:1], [other_g])),
        ("more slips above 0.5 (0.6, 0.75, 0.9)", _grid(loads, [0.6, 0.75, 0.9], mps[:1], gs[:1])),
        ("add skid (braked) slips (-0.5, -0.2)", _grid(loads, [-0.5, -0.2], mps[:1], gs[:1])),
    ]
    out = [(text, grid, {}) for text, grid in out]
    if grousered:
        out.append(("run a smooth wheel (same rim, no grousers) on the same soil at these "
                    "loads and slips", _grid(loads, slips, mps[:1], gs[:1]), SMOOTH_WHEEL))
    return out


def separating_test(sim: Simulated, points: pd.DataFrame, values_a: dict[str, float],
                    values_b: dict[str, float]) -> dict:
    """The proposal with the largest standardised difference between the two fits. With
    each source simulated on its own wheel (``sim.wheel_per_row``) a proposal is run on
    every measured wheel, and a smooth wheel is proposed only when no source has one."""
    quantities = quantities_of(points)
    best = {"test": None, "separation_sigma": 0.0}
    if sim.wheel_per_row:
        wheels = points[list(WHEEL_KEY)].drop_duplicates()
        grousered = bool(((wheels["grouser_count"] > 0) & (wheels["grouser_height_m"] > 0)).all())
    else:
        wheels, grousered = None, sim.wheel.grouser_count > 0 and sim.wheel.grouser_height_m > 0
    for text, grid, change in proposals(points, grousered):
        if wheels is not None:
            grid = grid.merge(wheels, how="cross")
            if change:  # the smooth wheel is the row's wheel here, not a model parameter
                grid = grid.assign(grouser_count=0, grouser_height_m=0.0)
                change = {}
        a, b = sim.predict(grid, {**values_a, **change}), sim.predict(grid, {**values_b, **change})
        load = grid["wheel_load_n"].to_numpy(float)
        sep = max(float(np.nanmax(np.abs(a[q] - b[q]) / model_error_floor(q, load, sim.radius_m)))
                  for q in quantities)
        if sep > best["separation_sigma"]:
            best = {"test": text, "separation_sigma": round(sep, 2)}
    return best
