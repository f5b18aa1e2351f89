"""Aliasing by design (sim_gap.aliasing): on one grousered wheel the soil's and the lugs'
slip-sinkage cannot be told apart, so a call resting on either is not confident; a smooth
wheel on the same soil, or a smooth wheel alone, lifts it."""

from __future__ import annotations

import pandas as pd

from sim_gap.aliasing import aliasing_problem
from swtlab.domain import Wheel

LUGGED = Wheel(radius_m=0.15, width_m=0.1, grouser_count=18, grouser_height_m=0.01)
SMOOTH = Wheel(radius_m=0.15, width_m=0.1)


def points(*wheels: Wheel) -> pd.DataFrame:
    rows = [{"wheel_radius_m": w.radius_m, "wheel_width_m": w.width_m,
             "grouser_count": w.grouser_count, "grouser_height_m": w.grouser_height_m,
             "slip": s} for w in wheels for s in (0.0, 0.2, 0.6)]
    return pd.DataFrame(rows)


def test_slip_sinkage_on_one_lugged_wheel_is_aliased():
    reason = aliasing_problem(points(LUGGED), LUGGED, ["slip_sinkage"],
                              {"slip_sinkage": "lyasko2010"}, {})
    assert "18 grousers of 10 mm" in reason and "smooth wheel" in reason
    pair = aliasing_problem(points(LUGGED), LUGGED, ["multipass", "slip_sinkage"],
                            {"multipass": "wong2010", "slip_sinkage": "ding2011"}, {})
    assert pair is not None


def test_a_smooth_wheel_lifts_the_aliasing():
    for p in (points(SMOOTH), points(SMOOTH, LUGGED)):
        assert aliasing_problem(p, LUGGED, ["slip_sinkage"], {"slip_sinkage": "ding2011"},
                                {}) is None
    # the points' own wheels count, not the simulation's
    assert aliasing_problem(pd.DataFrame({"slip": [0.1, 0.5]}), SMOOTH, ["slip_sinkage"],
                            {"slip_sinkage": "ding2011"}, {}) is None


def test_grousers_call_is_aliased_only_when_it_rests_on_lug_sinkage():
    p = points(LUGGED)
    # Ding's lug law with its lug slip-sinkage fitted: exponent + 3 * 0.01/0.15 * 0.6 = 0.12
    reason = aliasing_problem(p, LUGGED, ["grousers"], {"grousers": "ding2011"},
                              {"effects.grousers.lug_sinkage_gain": 3.0})
    assert "exponent grows by 0.12" in reason
    # fitted to no lug sinkage (below 0.01 at s = 0.6), or a law without that term
    assert aliasing_problem(p, LUGGED, ["grousers"], {"grousers": "ding2011"},
                            {"effects.grousers.lug_sinkage_gain": 0.2}) is None
    assert aliasing_problem(p, LUGGED, ["grousers"], {"grousers": "bekker1956"}, {}) is None
    # Bekker's law with the lugs' slip-sinkage of Lyasko's form: K_s(0.6)^(2 * 0.01/0.15)
    # = 2.3^0.133 = 1.12; at a gain of 0.1 it is 1.006, negligible
    reason = aliasing_problem(p, LUGGED, ["grousers"], {"grousers": "bekker1956~slip"},
                              {"effects.grousers.lug_slip_gain": 2.0})
    assert "sinkage grows 1.12 times at slip 0.60" in reason
    assert aliasing_problem(p, LUGGED, ["grousers"], {"grousers": "bekker1956~slip"},
                            {"effects.grousers.lug_slip_gain": 0.1}) is None
    assert aliasing_problem(p, LUGGED, ["bulldozing"], {"bulldozing": "bekker1969"}, {}) is None
