"""A fit that ends on a bound of its range is no fit (sim_gap.identify.parameters_on_bounds):
a law pinned at its limit cannot give what the data ask."""

from __future__ import annotations

import terramechanics as tm
from sim_gap import candidates
from sim_gap.fit import FitResult
from sim_gap.identify import parameters_on_bounds

BASE = tm.shipped_model("bb2_sand").with_effects(**{n: False for n in tm.EFFECTS})


def fit_with(effects: tuple[str, ...], laws: tuple[str, ...], strengths: dict) -> FitResult:
    params = candidates.soil_params(BASE) + tuple(
        p for e, law in zip(effects, laws) for p in candidates.effect_params(e, law))
    c = candidates.Candidate(effects, params, laws)
    values = {p.name: p.start for p in params} | strengths
    return FitResult(c, values, chi2=1.0, n_residuals=40)


def test_strength_at_its_upper_limit_is_on_a_bound():
    pinned = fit_with(("bulldozing",), ("rankine_terzaghi1943",),
                      {"effects.bulldozing.coefficient": 4.999997})
    assert parameters_on_bounds(pinned) == ["effects.bulldozing.coefficient = 5, its upper limit"]
    inside = fit_with(("bulldozing",), ("rankine_terzaghi1943",),
                      {"effects.bulldozing.coefficient": 4.9})
    assert parameters_on_bounds(inside) == []


def test_a_strength_at_zero_is_off_not_pinned_but_a_log_lower_limit_is():
    # Wong's flexible wheel without hysteresis: that part of the law is off
    off = fit_with(("wheel_flexibility",), ("wong2010",),
                   {"effects.wheel_flexibility.hysteresis_coefficient": 0.0})
    assert parameters_on_bounds(off) == []
    # the softest wheel the law allows (5 kN/m): pinned
    soft = fit_with(("wheel_flexibility",), ("wong2010",),
                    {"effects.wheel_flexibility.radial_stiffness_n_m": 5.0e3})
    assert parameters_on_bounds(soft) == [
        "effects.wheel_flexibility.radial_stiffness_n_m = 5e+03, its lower limit"]
    # the soil recalibration's own limits count too (k_phi at a fifth of the simulation's)
    kphi = BASE.soil.kphi / 5
    soil = fit_with((), (), {"soil.kphi": kphi * 1.000001})
    assert parameters_on_bounds(soil) == [f"soil.kphi = {kphi:.3g}, its lower limit"]
