"""``swtlab wpm query`` end to end: inverse and values at a slip, text and --json, curve-set
choice, and bad input (exit 3, one line)."""

from __future__ import annotations

import json

import pytest

from fitting import OutsideSlipRangeWarning, fit_results
from swtlab_cli import exit_codes
from swtlab_cli.main import main
from wpm_export import WheelPerformanceModule, inputs_sha256, write_wpm_csv
from test_fitting_synthetic import model_results_table


@pytest.fixture(scope="module")
def wpm_csv(tmp_path_factory):
    table = model_results_table(multipass=(0, 1), seed=9)
    path = tmp_path_factory.mktemp("cli") / "wpm.csv"
    write_wpm_csv(fit_results(table), path, inputs_sha256(table), "test")
    return str(path)


def _run(capsys, *argv):
    code = main(["wpm", "query", *argv])
    out, err = capsys.readouterr()
    return code, out, err


def test_dp_query_json(capsys, wpm_csv):
    code, out, err = _run(capsys, wpm_csv, "--load", "120", "--dp", "25", "--multipass", "0",
                          "--json")
    assert code == exit_codes.OK and err == ""
    answer = json.loads(out)
    expected = WheelPerformanceModule.load(wpm_csv).slip_for("dp_n", 25.0, 120.0, multipass=0)
    assert answer["slip"] == pytest.approx(float(expected.slip), abs=1e-12)
    assert 0.1 < answer["slip"] < 0.3  # the model: DP 25 N at 120 N near 20 % slip
    assert (answer["quantity"], answer["unit"], answer["status"]) == ("dp_n", "N", "ok")
    assert answer["value"] == pytest.approx(25.0, abs=1e-9)
    assert (answer["soil"], answer["wheel"], answer["multipass"]) == ("bb2_sand", "bb2", 0)
    assert answer["method"] == "pchip" and answer["tested_loads_n"] == [70.0, 180.0, 300.0]


def test_unreachable_dp_text_and_json(capsys, wpm_csv):
    code, out, _ = _run(capsys, wpm_csv, "--load", "120", "--dp", "500", "--multipass", "0")
    assert code == 0 and "slip 1.0 (100 %), maximum achievable" in out
    code, out, _ = _run(capsys, wpm_csv, "--load", "120", "--dp", "500", "--multipass", "0",
                        "--json")
    answer = json.loads(out)
    assert answer["slip"] == 1.0 and answer["status"] == "above_max"
    assert 40.0 < answer["value"] < 60.0
    code, out, _ = _run(capsys, wpm_csv, "--load", "120", "--dp", "-500", "--multipass", "0",
                        "--json")
    assert json.loads(out)["slip"] is None and json.loads(out)["status"] == "below_min"


def test_a_dp_inside_the_jump_at_zero_slip(capsys, tmp_path):
    from wpm_export.schema import BRANCH_COLUMNS, COLUMNS

    path = tmp_path / "step.csv"  # hand-made: DP = 100 s, 5 N lower on the braked side
    path.write_text("# format: swtlab-wpm/1\n" + ",".join(COLUMNS + BRANCH_COLUMNS) + "\n"
                    "sand,w,0,100.0,dp_n,N,3,-0.2,0.6,0,100,0,0,,,,,9,0.1,-5,0\n")
    code, out, _ = _run(capsys, str(path), "--load", "100", "--dp", "-2")
    assert code == 0 and "dp_n = -2 N at slip 0: inside the curve's jump at zero slip" in out
    code, out, _ = _run(capsys, str(path), "--load", "100", "--dp", "-2", "--json")
    answer = json.loads(out)
    assert (answer["slip"], answer["status"]) == (0.0, "at_step")
    assert answer["value"] == pytest.approx(-2.0)
    code, out, _ = _run(capsys, str(path), "--load", "100", "--dp", "-10", "--json")
    assert json.loads(out)["slip"] == pytest.approx(-0.05)  # 100 s - 5 = -10 on the braked side


@pytest.mark.parametrize("option, quantity", [("--torque", "torque_nm"), ("--sinkage", "sinkage_m"),
                                              ("--resistance", "resistance_n")])
def test_other_quantities(capsys, wpm_csv, option, quantity):
    target = {"torque_nm": "4", "sinkage_m": "0.005", "resistance_n": "15"}[quantity]
    code, out, _ = _run(capsys, wpm_csv, "--load", "150", option, target, "--multipass", "1",
                        "--json")
    answer = json.loads(out)
    assert code == 0 and answer["quantity"] == quantity and answer["status"] == "ok"
    assert answer["value"] == pytest.approx(float(target), rel=1e-9)


def test_slip_query_prints_every_quantity(capsys, wpm_csv):
    code, out, _ = _run(capsys, wpm_csv, "--load", "120", "--slip", "0.3", "--multipass", "0")
    assert code == 0
    lines = out.splitlines()
    assert lines[0].startswith("bb2_sand / bb2 / multipass 0 at 120 N (pchip")
    assert [ln.split()[0] for ln in lines[1:]] == ["dp_n", "torque_nm", "sinkage_m",
                                                   "resistance_n", "dp_over_w"]
    code, out, _ = _run(capsys, wpm_csv, "--load", "120", "--slip", "0.75", "--multipass", "0",
                        "--json")
    answer = json.loads(out)
    values = WheelPerformanceModule.load(wpm_csv).curve("torque_nm", 120.0, multipass=0)
    with pytest.warns(OutsideSlipRangeWarning):
        assert answer["values"]["torque_nm"] == pytest.approx(float(values.evaluate(0.75)))
    assert answer["units"]["sinkage_m"] == "m"
    assert all(answer["outside_slip_range"].values())  # 0.75 > 0.6: flagged


@pytest.mark.parametrize("argv, message", [
    (["--load", "120", "--dp", "25"], "2 curve sets match in "),
    (["--load", "120", "--dp", "25"], "pick one: --soil bb2_sand --wheel bb2 --multipass 0; "
                                      "--soil bb2_sand --wheel bb2 --multipass 1"),
    (["--load", "400", "--dp", "25", "--multipass", "0"],
     "--load 400 N is outside the tested loads"),
    (["--load", "120", "--dp", "25", "--soil", "clay"], "no curves for --soil clay in "),
])
def test_bad_queries_exit_3_with_one_line(capsys, wpm_csv, argv, message):
    code, out, err = _run(capsys, wpm_csv, *argv)
    assert code == exit_codes.BAD_INPUT and out == ""
    assert err.count("\n") == 1 and err.startswith("swtlab wpm: ") and message in err


def test_malformed_file_exits_3_naming_the_line(capsys, tmp_path, wpm_csv):
    bad = tmp_path / "bad.csv"
    lines = open(wpm_csv).read().splitlines()
    lines[5] = lines[5].replace(",3,", ",9,", 1)
    bad.write_text("\n".join(lines) + "\n")
    code, _, err = _run(capsys, str(bad), "--load", "120", "--dp", "25")
    assert code == exit_codes.BAD_INPUT
    assert err.strip() == f"swtlab wpm: {bad}:6: degree 9 outside 3-7"
    code, _, err = _run(capsys, str(tmp_path / "missing.csv"), "--load", "120", "--dp", "25")
    assert code == exit_codes.BAD_INPUT and "No such file" in err


def test_extrapolation_on_request_warns(capsys, wpm_csv):
    code, out, err = _run(capsys, wpm_csv, "--load", "330", "--dp", "25", "--multipass", "0",
                          "--allow-extrapolation", "--json")
    assert code == 0 and json.loads(out)["extrapolated_load"] is True
    assert "warning: 1 load(s) outside the tested loads (70-300 N)" in err


def test_dp_query_gives_the_slip_and_its_uncertainty(capsys, wpm_csv, tmp_path):
    """Issue 18.4: the slip's 95 % half-widths are the DP band over the slope there
    (u_slip = u_DP / |dDP/dslip|), checked against a finite-difference slope of the curve;
    an older CSV without the uncertainty columns says the uncertainty is unknown."""
    from fitting import band

    code, out, _ = _run(capsys, wpm_csv, "--load", "120", "--dp", "25", "--multipass", "0",
                        "--json")
    answer = json.loads(out)
    curve = WheelPerformanceModule.load(wpm_csv).curve("dp_n", 120.0, multipass=0)
    s, h = answer["slip"], 1e-6
    slope = float(curve.evaluate(s + h) - curve.evaluate(s - h)) / (2 * h)
    _, conf, pred = band(curve, s)
    assert answer["uncertainty_known"] is True
    assert answer["value_conf_half95"] == pytest.approx(float(conf), rel=1e-9)
    assert answer["slip_conf_half95"] == pytest.approx(float(conf) / abs(slope), rel=1e-6)
    assert answer["slip_pred_half95"] == pytest.approx(float(pred) / abs(slope), rel=1e-6)
    assert 0 < answer["slip_conf_half95"] < answer["slip_pred_half95"] < 0.05
    code, out, _ = _run(capsys, wpm_csv, "--load", "120", "--dp", "25", "--multipass", "0")
    assert code == 0 and "slip +- " in out and "(linearised)" in out
    old = tmp_path / "old.csv"  # the same file without the three uncertainty columns
    lines = open(wpm_csv).read().splitlines()
    old.write_text("\n".join(ln if ln.startswith("#") else ",".join(ln.split(",")[:-3])
                             for ln in lines) + "\n")
    code, out, _ = _run(capsys, str(old), "--load", "120", "--dp", "25", "--multipass", "0")
    assert code == 0 and "slip uncertainty unknown" in out
    code, out, _ = _run(capsys, str(old), "--load", "120", "--dp", "25", "--multipass", "0",
                        "--json")
    assert json.loads(out)["slip_conf_half95"] is None
    assert json.loads(out)["slip"] == pytest.approx(answer["slip"], abs=1e-12)
