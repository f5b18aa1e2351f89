"""The forms of "outside the candidates" (sim_gap.diagnose.outside_forms): where one level
factor alone varies, a discrepancy apart per level is that effect's free form, so the
outside hypothesis takes one error alike on every level instead; where two factors vary,
it keeps its discrepancy apart per source and level (what neither free form makes)."""

from __future__ import annotations

import numpy as np
import pandas as pd

from sim_gap.diagnose import outside_forms
from sim_gap.evidence import observations, same_partition

RADIUS_M = 0.13


def _points(multipass: list[int], gravity: list[float]) -> pd.DataFrame:
    rows = [{"slip": slip, "wheel_load_n": load, "load_set_n": load, "multipass": m,
             "gravity_mps2": g, "dp_n": 10.0 * slip, "torque_nm": 2.0 + slip}
            for m in multipass for g in gravity for load in (80.0, 160.0)
            for slip in (0.1, 0.3, 0.6)]
    return pd.DataFrame(rows)


def _levels_form(points: pd.DataFrame, free_levels: list[np.ndarray]):
    sigma = {q: np.full(len(points), 0.5) for q in ("dp_n", "torque_nm")}
    obs = observations(points, sigma, RADIUS_M)
    # no start times and one travel velocity: the soil fit and the simulation are not read
    forms = outside_forms(None, points, obs, np.array([1.0, 2.0]), None, free_levels)
    return obs, forms["levels"][0]


def test_one_factor_varying_gives_one_error_alike_on_every_level():
    points = _points([0, 1], [9.81])
    obs, form = _levels_form(points, [points["multipass"].astype(str).to_numpy()])
    assert not np.array_equal(obs.kernel_grouped, obs.kernel_shared)  # per level before
    np.testing.assert_array_equal(form.kernel_grouped, form.kernel_shared)


def test_two_factors_varying_keep_the_discrepancy_apart_per_level():
    points = _points([0, 1], [1.62, 9.81])
    free = [points["multipass"].astype(str).to_numpy(),
            points["gravity_mps2"].astype(str).to_numpy()]
    obs, form = _levels_form(points, free)
    np.testing.assert_array_equal(form.kernel_grouped, obs.kernel_grouped)
    # entries of different multipass or gravity levels are independent in that form
    assert (form.kernel_grouped == 0.0).sum() > (form.kernel_shared == 0.0).sum()


def test_same_partition_compares_groupings_not_labels():
    assert same_partition(np.array(["a", "a", "b"]), np.array([1, 1, 2]))
    assert not same_partition(np.array(["a", "a", "b"]), np.array([1, 2, 2]))
    assert not same_partition(np.array(["a", "a", "a"]), np.array([1, 1, 2]))
