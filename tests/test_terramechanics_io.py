"""Model file, soil-parameter conversions and the ``swtlab sim`` command."""

from __future__ import annotations

import re

import numpy as np
import pandas as pd
import pytest

from swtlab_cli import exit_codes
from swtlab_cli.main import main as swtlab
from terramechanics import (LUNAR_NOMINAL, drucker_prager_to_mohr_coulomb, load_model,
                            mohr_coulomb_to_drucker_prager, save_model)
from terramechanics.model_file import SHIPPED_MODELS, ModelFileError

BB2_FILE = SHIPPED_MODELS / "bb2_sand.toml"


def test_mohr_coulomb_drucker_prager_values_and_round_trip():
    d, beta = mohr_coulomb_to_drucker_prager(1000.0, 30.0)  # sin 30 = 1/2: tan beta = 1
    assert beta == pytest.approx(45.0) and d == pytest.approx(1000.0 * np.sqrt(3))
    c = np.array([0.0, 170.0, 1300.0, 5000.0])
    phi = np.array([0.0, 35.0, 31.1, 45.0])
    c_back, phi_back = drucker_prager_to_mohr_coulomb(*mohr_coulomb_to_drucker_prager(c, phi))
    np.testing.assert_allclose(c_back, c, atol=1e-9)
    np.testing.assert_allclose(phi_back, phi, atol=1e-9)
    with pytest.raises(ValueError):
        drucker_prager_to_mohr_coulomb(100.0, 70.0)  # tan beta > 2: no friction angle


def test_model_file_round_trip(tmp_path):
    model = load_model(BB2_FILE).with_effects(bulldozing={"coefficient": 0.3})
    save_model(model, tmp_path / "m.toml")
    assert load_model(tmp_path / "m.toml") == model


def test_model_file_presets_and_errors(tmp_path):
    path = tmp_path / "m.toml"
    path.write_text('[wheel]\nradius_m = 0.2\nwidth_m = 0.1\n[soil]\npreset = "lunar_nominal"\n'
                    'cohesion_pa = 300.0\n[effects.slip_sinkage]\nn1 = 0.2\n'
                    '[effects.bulldozing]\nenabled = false\n[model]\ngravity_mps2 = 1.62\n')
    model = load_model(path)
    assert model.soil.kphi == LUNAR_NOMINAL.kphi and model.soil.cohesion_pa == 300.0
    assert list(model.effects) == ["slip_sinkage"] and model.effects["slip_sinkage"].n1 == 0.2
    assert model.gravity_mps2 == 1.62
    for text, message in [("[wheel]\nradius_m = 0.2\n", "missing table [soil]"),
                          ('[wheel]\nradius_m=0.2\nwidth_m=0.1\n[soil]\npreset="mud"\n', "preset"),
                          ('[wheel]\nradius_m=0.2\nwidth_m=0.1\n[soil]\npreset="lete_sand"\n'
                           "[effects.tyres]\n", "unknown effect"),
                          ('[wheel]\nradius_m=0.2\nwidth_m=0.1\nspokes=3\n[soil]\n', "spokes"),
                          ("[wheel\n", "not valid TOML")]:
        path.write_text(text)
        with pytest.raises(ModelFileError, match=re.escape(message)):
            load_model(path)


def test_sim_command_writes_long_csv(tmp_path, capsys):
    out = tmp_path / "curves.csv"
    code = swtlab(["sim", str(BB2_FILE), "--loads", "70,180,300", "--slips", "-0.1:0.9:0.05",
                   "--multipass", "0,1", "-o", str(out)])
    assert code == exit_codes.OK
    table = pd.read_csv(out)
    assert len(table) == 3 * 2 * 21
    assert list(table.columns[:8]) == ["load_n", "multipass", "gravity_mps2", "slip", "dp_n",
                                       "torque_nm", "sinkage_m", "resistance_n"]
    assert table["converged"].all()
    row = table[(table.load_n == 180) & (table.multipass == 0) & (table.slip == 0)].iloc[0]
    assert row["resistance_n"] == pytest.approx(load_model(BB2_FILE).curves(180.0, 0.0)[
        "resistance_n"], rel=1e-5)
    assert "126 rows" in capsys.readouterr().err


def test_sim_command_refuses_bad_input(tmp_path, capsys):
    assert swtlab(["sim", str(tmp_path / "none.toml"), "--loads", "1", "--slips", "0"]) == \
        exit_codes.BAD_INPUT
    with pytest.raises(SystemExit) as stop:
        swtlab(["sim", str(BB2_FILE), "--loads", "180", "--slips", "0:1"])
    assert stop.value.code == exit_codes.USAGE
    assert swtlab(["sim", str(BB2_FILE), "--loads", "-5", "--slips", "0"]) == exit_codes.USAGE


def test_model_as_the_virtual_testbed_law():
    from scipy.optimize import brentq

    from terramechanics import ModelLaw

    law = ModelLaw(load_model(BB2_FILE))
    assert law.radius_m == 0.125
    out = law.evaluate(180.0, np.array([0.0, 0.3]), 1, 9.80665)
    assert set(out) == {"dp_n", "torque_nm", "thrust_n", "resistance_n", "sinkage_m"}
    np.testing.assert_allclose(out["thrust_n"] - out["dp_n"], out["resistance_n"])
    towed = brentq(lambda s: float(law.evaluate(180.0, s, 0)["torque_nm"]), -0.99, 0.99)
    self_propelled = brentq(lambda s: float(law.evaluate(180.0, s, 0)["dp_n"]), -0.99, 0.99)
    assert -0.2 < towed < 0.0 < self_propelled < 0.2  # towed skids, free wheel slips
    params = law.parameters()
    assert params["soil"] == "bb2_sand" and params["soil.kphi"] == 1.8e7
    assert params["effects"] == "grousers,slip_sinkage,wheel_flexibility,multipass"
    assert params["laws"] == ("grousers=bekker1956,slip_sinkage=ding2011,"
                              "wheel_flexibility=wong2010,multipass=wong2010")
