"""Each effect moves the curves the way the literature reports, with its numbers.

BB2 numbers (ExoMars BB2 flexible wheel single-wheel tests, as given in the swtlab
issue): at 180 N, resistance near zero slip about 18 N on virgin soil, 4.6 N of it
(25 %) hysteresis of the flexible wheel, about 15 N at multipass 2; maximum DP/W
about 0.4-0.5. Reduced gravity (Niksirat, Daca & Skonieczny 2020, IJRR 39(7)): at
the same wheel load about 20 % less traction at lunar and 5-10 % at Martian gravity,
with more sinkage (Reece's law here; the other laws in tests/test_terramechanics_laws.py).
"""

from __future__ import annotations

import re
import sys

import numpy as np
import pytest

from terramechanics import EARTH_GRAVITY_MPS2, EFFECTS, LETE_SAND, Wheel, WheelModel, load_model
from terramechanics.effects import BulldozingBekker1969, GrousersBekker1956, make_effect
from terramechanics.model_file import SHIPPED_MODELS
from swtlab_base.domain import MARS_GRAVITY_MPS2, MOON_GRAVITY_MPS2

BB2_FILE = SHIPPED_MODELS / "bb2_sand.toml"
SLIPS = np.linspace(0.0, 0.9, 19)


@pytest.fixture(scope="module")
def bb2() -> WheelModel:
    return load_model(BB2_FILE)


def test_registry_has_the_fixed_vocabulary():
    assert set(EFFECTS) == {"grousers", "slip_sinkage", "reduced_gravity", "wheel_flexibility",
                            "multipass", "bulldozing"}
    for name, cls in EFFECTS.items():
        assert cls.name == name and cls.__doc__
        assert re.search(r"\b(19|20)\d\d\b", sys.modules[cls.__module__].__doc__)  # cites a paper
        assert make_effect(name) == cls()
    with pytest.raises(KeyError):
        make_effect("tyre_pressure")


def test_bb2_magnitudes_near_zero_slip(bb2):
    out = bb2.curves(180.0, 0.0)
    assert out["resistance_n"] == pytest.approx(18.0, abs=0.5)
    assert out["hysteresis_n"] == pytest.approx(4.6, abs=0.05)
    assert out["hysteresis_n"] / out["resistance_n"] == pytest.approx(0.25, abs=0.02)
    peak = bb2.curves(180.0, SLIPS)["dp_n"].max() / 180.0
    assert 0.4 <= peak <= 0.5


def test_grousers_add_drawbar_pull(bb2):
    on, off = bb2.curves(180.0, SLIPS), bb2.with_effects(grousers=False).curves(180.0, SLIPS)
    assert np.all(on["dp_n"][2:] > off["dp_n"][2:])
    assert np.all(on["thrust_n"][1:] > off["thrust_n"][1:])
    assert np.all(on["torque_nm"][1:] > off["torque_nm"][1:])
    # a taller grouser (larger shear radius r + lambda h, more side shear) pulls more
    tall = bb2.with_wheel(grouser_height_m=0.02).curves(180.0, 0.4)
    assert tall["dp_n"] > on["dp_n"][8]


def test_slip_sinkage_sinks_more_at_high_slip(bb2):
    on, off = bb2.curves(180.0, SLIPS), bb2.with_effects(slip_sinkage=False).curves(180.0, SLIPS)
    assert on["sinkage_m"][0] == pytest.approx(off["sinkage_m"][0], rel=1e-9)
    assert np.all(on["sinkage_m"][1:] > off["sinkage_m"][1:])
    assert on["sinkage_m"][-1] > 2 * on["sinkage_m"][0]  # Ding et al. 2011: sinkage grows with slip


def test_reece_reduced_gravity_at_the_same_load(bb2):
    model = bb2.with_effects(reduced_gravity={"law": "reece1965"})
    earth = model.curves(180.0, SLIPS, gravity_mps2=EARTH_GRAVITY_MPS2)
    moon = model.curves(180.0, SLIPS, gravity_mps2=MOON_GRAVITY_MPS2)
    mars = model.curves(180.0, SLIPS, gravity_mps2=MARS_GRAVITY_MPS2)
    traction_loss = lambda c: 1 - c["dp_n"].max() / earth["dp_n"].max()  # noqa: E731
    assert 0.15 <= traction_loss(moon) <= 0.25  # about 20 %
    assert 0.05 <= traction_loss(mars) <= 0.11  # 5-10 %
    assert np.all(moon["sinkage_m"] > mars["sinkage_m"])
    assert np.all(mars["sinkage_m"] > earth["sinkage_m"])
    # at the reference gravity the effect changes nothing; off, gravity changes nothing
    np.testing.assert_allclose(earth["dp_n"], bb2.curves(180.0, SLIPS)["dp_n"])
    np.testing.assert_allclose(bb2.curves(180.0, SLIPS, gravity_mps2=1.62)["dp_n"],
                               bb2.curves(180.0, SLIPS)["dp_n"])


def test_flexible_wheel_sinks_less_and_pays_hysteresis(bb2):
    rigid = bb2.with_effects(wheel_flexibility=False).curves(180.0, SLIPS)
    flex = bb2.curves(180.0, SLIPS)
    assert np.all(flex["sinkage_m"] < rigid["sinkage_m"])
    assert np.all(flex["theta1_rad"] * 0.125 * (1 + flex["deflection_m"] / flex["sinkage_m"])
                  > rigid["theta1_rad"] * 0.125)  # longer contact arc
    assert flex["deflection_m"][0] == pytest.approx(180.0 / 30e3)
    no_loss = bb2.with_effects(wheel_flexibility={"hysteresis_coefficient": 0.0})
    no_loss = no_loss.curves(180.0, SLIPS)
    np.testing.assert_allclose(flex["resistance_n"] - no_loss["resistance_n"], 4.6, atol=0.05)
    np.testing.assert_allclose(flex["dp_n"], no_loss["dp_n"])


def test_multipass_compacts(bb2):
    passes = bb2.curves(180.0, 0.0, multipass=np.array([0, 1, 2]))
    assert passes["resistance_n"][0] == pytest.approx(18.0, abs=0.5)
    assert passes["resistance_n"][2] == pytest.approx(15.0, abs=0.5)
    assert np.all(np.diff(passes["resistance_n"]) < 0) and np.all(np.diff(passes["sinkage_m"]) < 0)
    off = bb2.with_effects(multipass=False).curves(180.0, 0.0, multipass=np.array([0, 2]))
    assert off["resistance_n"][0] == off["resistance_n"][1]


def test_bulldozing_adds_resistance():
    model = WheelModel(Wheel(0.125, 0.112), LETE_SAND)
    on, off = model.with_effects(bulldozing=True).curves(180.0, SLIPS), model.curves(180.0, SLIPS)
    assert np.all(on["bulldozing_n"] > 0)
    np.testing.assert_allclose(on["resistance_n"] - off["resistance_n"], on["bulldozing_n"])
    np.testing.assert_allclose(off["dp_n"] - on["dp_n"], on["bulldozing_n"])
    assert np.all(np.diff(on["bulldozing_n"]) > 0)  # deeper rut, more soil pushed
    half = model.with_effects(bulldozing=BulldozingBekker1969(coefficient=0.5)).curves(180.0, SLIPS)
    np.testing.assert_allclose(half["bulldozing_n"], 0.5 * on["bulldozing_n"])


def test_switching_and_parameters(bb2):
    assert list(bb2.effects) == ["grousers", "slip_sinkage", "wheel_flexibility", "multipass"]
    changed = bb2.with_effects(grousers={"shear_radius_factor": 1.0}, bulldozing=True)
    assert changed.effects["grousers"] == GrousersBekker1956(shear_radius_factor=1.0)
    assert "bulldozing" in changed.effects and "bulldozing" not in bb2.effects
    params = changed.parameters()
    assert params["effects.grousers.shear_radius_factor"] == 1.0 and params["soil.kphi"] == 1.8e7
    again = bb2.with_parameters({"effects.grousers.shear_radius_factor": 1.0,
                                 "effects.bulldozing.coefficient": 1.0})
    assert again == changed
    fitted = bb2.with_parameters({"soil.kphi": 2e7, "wheel.width_m": 0.1, "gravity_mps2": 3.71})
    assert (fitted.soil.kphi, fitted.wheel.width_m, fitted.gravity_mps2) == (2e7, 0.1, 3.71)
    with pytest.raises(KeyError):
        bb2.with_parameters({"tyre.pressure": 1.0})
    with pytest.raises(KeyError):
        WheelModel(bb2.wheel, bb2.soil, effects={"magic": GrousersBekker1956()})


def test_every_effect_on_stays_in_equilibrium(bb2):
    model = bb2.with_effects(**{name: True for name in EFFECTS})
    out = model.curves(np.array([70.0, 180.0, 300.0])[:, None], np.linspace(-0.5, 0.9, 50),
                       multipass=1, gravity_mps2=3.71)
    assert out["converged"].all()
    assert np.max(np.abs(out["fz_residual_n"]) / out["load_n"]) < 1e-3
