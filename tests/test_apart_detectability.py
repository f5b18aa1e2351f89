"""The oracle's distance between a truth and the truth without one effect
(testbeds.apart.detectability), checked on bulldozing, whose force only subtracts from the
drawbar pull and is linear in its drawn multiple of Rankine's wall: the distance must then be
exactly quadratic in that multiple and zero without it. In-family: the generator's own
solver on both sides; it checks the whitening and the projection, not a diagnosis.
"""

from __future__ import annotations

import copy

import pytest

from testbeds.apart.campaign import draw_campaign
from testbeds.apart.detectability import TELLABLE_D, distances, tellable
from testbeds.apart.score import calibration

BULLDOZING_CAMPAIGN = (4001, 4)  # a single: bulldozing on a smooth rigid wheel


def _with_multiple(drawn: dict, factor: float) -> dict:
    out = copy.deepcopy(drawn)
    law = out["truth"].effects["bulldozing"]
    law["rankine_multiple"] *= factor
    for row in out["rows"]:
        steady = out["truth"].steady(row["run"], row["scatter"])
        row["readings"] = out["truth"].readings(row["run"], steady)
    return out


def test_distance_is_quadratic_in_a_linear_effect_and_zero_without_it():
    drawn = draw_campaign(*BULLDOZING_CAMPAIGN)
    assert list(drawn["truth"].effects) == ["bulldozing"]
    full = distances(drawn)["bulldozing"]
    quarter = distances(_with_multiple(drawn, 0.25))["bulldozing"]
    assert full > TELLABLE_D
    assert quarter == pytest.approx(full / 16, rel=1e-6)
    assert distances(_with_multiple(drawn, 0.0))["bulldozing"] == pytest.approx(0.0, abs=1e-12)
    assert not tellable({"bulldozing": 0.0, "multipass": 1e3})


def _row(cls, outcome, tellable_):
    return {"campaign": "x", "class": cls, "outcome": outcome, "p_leading": None,
            "tellable": tellable_, "distances": {"grousers": 1.0}}


def test_rates_where_the_design_can_tell_leave_out_only_the_untellable():
    rows = [_row("single", "right", True), _row("single", "inconclusive", False),
            _row("none", "inconclusive", True), _row("pair", "right", False)]
    for r in rows[2:3]:
        del r["tellable"], r["distances"]  # a truth of no effect is always tellable
    cal = calibration(rows)
    assert cal["right_none_and_singles"] == (1, 3)
    assert cal["right_none_and_singles_tellable"] == (1, 2)
    assert cal["right_pairs_tellable"] == (0, 0)
    assert len(cal["untellable"]) == 2
