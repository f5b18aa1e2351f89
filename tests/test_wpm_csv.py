"""The WPM CSV (docs/wpm-csv.md): write, read back exactly, hash the inputs, accept another
tool's file written to the page, and refuse every malformed one with file, line and problem."""

from __future__ import annotations

import hashlib

import numpy as np
import pytest

from fitting import fit_results
from wpm_export import (COLUMNS, FORMAT, WpmFormatError, inputs_sha256, read_wpm_csv,
                        write_wpm_csv)
from wpm_export.schema import BRANCH_COLUMNS, UNCERTAINTY_COLUMNS
from test_fitting_synthetic import model_results_table

HEADER = ",".join(COLUMNS)  # the layout without the braked-branch columns, still read
GOOD_ROW = "sand,bb2,0,180,dp_n,N,3,-0.1,0.6,-11.0,200.0,-230.0,80.0,,,,,7,0.4"
BRANCH_HEADER = ",".join(COLUMNS + BRANCH_COLUMNS)  # before the uncertainty columns, still read
FULL_HEADER = ",".join(COLUMNS + BRANCH_COLUMNS + UNCERTAINTY_COLUMNS)  # what swtlab writes


@pytest.fixture(scope="module")
def table():
    return model_results_table(multipass=(0, 1), seed=4)


@pytest.fixture(scope="module")
def fits(table):
    return fit_results(table)


def test_round_trip_gives_the_same_curves(tmp_path, table, fits):
    path = tmp_path / "wpm.csv"
    digest = write_wpm_csv(fits, path, inputs_sha256(table), "0.1.0", created="2026-01-01")
    assert digest == hashlib.sha256(path.read_bytes()).hexdigest()
    header, curves = read_wpm_csv(path)
    assert header == {"format": FORMAT, "swtlab_version": "0.1.0",
                      "inputs_sha256": inputs_sha256(table), "created": "2026-01-01"}
    assert len(curves) == len(fits) == 30  # 2 multipass x 3 loads x 5 quantities
    by_key = {(c.wheel, c.soil, c.multipass, c.load_n, c.quantity): c for c in curves}
    s = np.linspace(-0.1, 0.6, 50)
    for f in fits:
        c = by_key[f.wheel, f.soil, f.multipass, f.load_n, f.quantity]
        assert c.coefficients == f.coefficients  # shortest round-trip decimals: exact
        assert (c.degree, c.slip_min, c.slip_max, c.n_points, c.unit) == (
            f.degree, f.slip_min, f.slip_max, f.n_points, f.unit)
        assert c.rmse == f.rmse
        assert (c.step_below_zero, c.slope_below_zero) == (f.step_below_zero,
                                                           f.slope_below_zero)
        np.testing.assert_allclose(c.evaluate(s), f.evaluate(s), rtol=0, atol=1e-12)
        assert (c.covariance, c.scatter_sd, c.k95) == (f.covariance, f.scatter_sd, f.k95)


def test_rows_are_sorted_and_unused_coefficients_empty(tmp_path, fits):
    path = tmp_path / "wpm.csv"
    write_wpm_csv(fits, path, "0" * 64, "0.1.0")
    lines = path.read_text().splitlines()
    assert lines[:4] == [f"# format: {FORMAT}", "# swtlab_version: 0.1.0",
                         f"# inputs_sha256: {'0' * 64}", FULL_HEADER]
    first = lines[4].split(",")
    assert first[:7] == ["bb2_sand", "bb2", "0", "70.0", "dp_n", "N", first[6]]
    degree = int(first[6])
    assert all(v == "" for v in first[10 + degree:17]) and all(first[9:10 + degree])
    assert [ln.split(",")[4] for ln in lines[4:9]] == ["dp_n", "torque_nm", "sinkage_m",
                                                        "resistance_n", "dp_over_w"]
    # same fits, same bytes
    again = tmp_path / "again.csv"
    assert write_wpm_csv(list(reversed(fits)), again, "0" * 64, "0.1.0") == \
        hashlib.sha256(path.read_bytes()).hexdigest()


def test_inputs_hash_is_deterministic_and_sensitive(table):
    digest = inputs_sha256(table)
    assert len(digest) == 64
    shuffled = table.sample(frac=1.0, random_state=3)[list(reversed(table.columns))]
    assert inputs_sha256(shuffled) == digest
    assert inputs_sha256(table.assign(run_note="x")) == digest  # unused column
    assert inputs_sha256(table.assign(multipass=table["multipass"].astype(float))) == digest
    changed = table.copy()
    changed.loc[5, "dp_n"] += 1e-9
    assert inputs_sha256(changed) != digest


def test_a_file_from_another_tool_written_to_the_page_loads(tmp_path):
    text = ("\ufeff# format: swtlab-wpm/1\r\n# generator: other-tool 2.1\r\n"
            f"{HEADER}\r\n"
            '"sand, fine",bb2,0,180,dp_n,N,3,-0.1,0.6,-11,200,-230,80,0,0,0,0,7,0.4\r\n'
            "\r\n")
    path = tmp_path / "other.csv"
    path.write_bytes(text.encode("utf-8"))
    header, (curve,) = read_wpm_csv(path)
    assert header == {"format": FORMAT, "generator": "other-tool 2.1"}
    assert curve.soil == "sand, fine" and curve.coefficients == (-11.0, 200.0, -230.0, 80.0)
    assert curve.evaluate(0.5) == pytest.approx(-11 + 100 - 57.5 + 10)
    assert (curve.step_below_zero, curve.slope_below_zero) == (0.0, 0.0)  # no such columns


def test_the_braked_branch_columns_are_read_and_evaluated(tmp_path):
    path = tmp_path / "branch.csv"
    path.write_text(f"# format: {FORMAT}\n{BRANCH_HEADER}\n{GOOD_ROW},3.0,-20.0\n")
    _, (curve,) = read_wpm_csv(path)
    assert (curve.step_below_zero, curve.slope_below_zero) == (3.0, -20.0)
    p = -11.0 + 200.0 * -0.05 - 230.0 * 0.0025 + 80.0 * -0.05 ** 3  # the polynomial at -5 %
    assert curve.evaluate(-0.05) == pytest.approx(p + 3.0 - 20.0 * -0.05, abs=1e-12)
    assert curve.evaluate(0.0) == -11.0  # zero slip: the driven side
    message = _bad(tmp_path, f"{GOOD_ROW},x,0", f"# format: {FORMAT}\n{BRANCH_HEADER}\n")
    assert message.startswith(":3: step_below_zero 'x' is not a number")


def test_the_uncertainty_columns_give_the_band_by_hand(tmp_path):
    """A cubic with J, K (m = 6 parameters): 21 numbers of the upper triangle; the variance at
    s = 0.5 is g^T C g with g = (1, .5, .25, .125, 0, 0), by hand for a diagonal C."""
    from fitting import band

    diagonal = [4.0, 1.0, 0.5, 0.25, 2.0, 3.0]
    upper = [diagonal[i] if i == j else 0.0 for i in range(6) for j in range(i, 6)]
    path = tmp_path / "u.csv"
    path.write_text(f"# format: {FORMAT}\n{FULL_HEADER}\n{GOOD_ROW},3.0,-20.0,2.0,1.5,"
                    + " ".join(map(str, upper)) + "\n")
    _, (curve,) = read_wpm_csv(path)
    mean, conf, pred = band(curve, 0.5)
    var = 4.0 + 0.25 * 1.0 + 0.0625 * 0.5 + 0.015625 * 0.25  # 4.2851...
    assert mean == pytest.approx(-11 + 100 - 57.5 + 10)
    assert conf == pytest.approx(2.0 * var ** 0.5) and pred == pytest.approx(
        2.0 * (var + 1.5 ** 2) ** 0.5)
    var_braked = 4.0 + 0.01 * 1.0 + 0.0001 * 0.5 + 1e-6 * 0.25 + 2.0 + 0.01 * 3.0  # s = -0.1
    assert band(curve, -0.1)[1] == pytest.approx(2.0 * var_braked ** 0.5)
    old = tmp_path / "old.csv"  # an older file: the uncertainty is unknown, not zero
    old.write_text(f"# format: {FORMAT}\n{BRANCH_HEADER}\n{GOOD_ROW},3.0,-20.0\n")
    _, (legacy,) = read_wpm_csv(old)
    assert legacy.covariance is None and all(np.isnan(band(legacy, 0.5)[1:]))
    prefix = f"# format: {FORMAT}\n{FULL_HEADER}\n"
    assert ":3: covariance has 3 numbers; degree 3 needs 21" in _bad(
        tmp_path, f"{GOOD_ROW},0,0,2.0,1.0,1 2 3", prefix)
    assert "give all three or none" in _bad(tmp_path, f"{GOOD_ROW},0,0,2.0,,", prefix)


def _bad(tmp_path, body: str, prefix: str = f"# format: {FORMAT}\n{HEADER}\n") -> str:
    path = tmp_path / "bad.csv"
    path.write_text(prefix + body)
    with pytest.raises(WpmFormatError) as info:
        read_wpm_csv(path)
    assert str(info.value).startswith(f"{path}:")
    return str(info.value)[len(str(path)):]


@pytest.mark.parametrize("row, problem", [
    (GOOD_ROW + ",9", ":3: 20 fields, the format has 19"),
    (GOOD_ROW.replace(",200.0,", ",2OO,"), ":3: a1 '2OO' is not a number"),
    (GOOD_ROW.replace(",200.0,", ",nan,"), ":3: a1 'nan' is not finite"),
    (GOOD_ROW.replace(",200.0,", ",,"), ":3: a1 '' is not a number"),
    (GOOD_ROW.replace(",N,3,", ",N,8,"), ":3: degree 8 outside 3-7"),
    (GOOD_ROW.replace(",N,3,", ",N,2,"), ":3: degree 2 outside 3-7"),
    (GOOD_ROW.replace(",N,3,", ",N,three,"), ":3: degree 'three' is not an integer"),
    (GOOD_ROW.replace("dp_n", "thrust_n"), ":3: unknown quantity 'thrust_n'"),
    (GOOD_ROW.replace(",N,", ",kN,"), ":3: unit 'kN' for dp_n; the format says 'N'"),
    (GOOD_ROW.replace("-0.1,0.6", "0.6,0.6"), ":3: slip range [0.6, 0.6]: need -1 <= "),
    (GOOD_ROW.replace("-0.1,0.6", "-0.1,60"), ":3: slip range [-0.1, 60]"),
    (GOOD_ROW.replace("80.0,,", "80.0,1.5,"), ":3: a4 = 1.5 beyond degree 3 (must be empty"),
    (GOOD_ROW.replace(",7,0.4", ",3,0.4"), ":3: n_points 3 < degree + 1 = 4"),
    (GOOD_ROW.replace(",7,0.4", ",7,-1"), ":3: rmse -1 < 0"),
    (GOOD_ROW.replace("sand,", ","), ":3: soil and wheel must not be empty"),
    (GOOD_ROW.replace(",180,", ",0,"), ":3: multipass 0 must be >= 0 and load_n 0 > 0"),
    (GOOD_ROW.replace(",0,180,", ",0.5,180,"), ":3: multipass '0.5' is not an integer"),
    (f"{GOOD_ROW}\n{GOOD_ROW}", ":4: duplicate curve ('sand', 'bb2', 0, 180.0, 'dp_n') "
                                "(also line 3)"),
    ("", ":2: no curve rows after the column header"),
])
def test_malformed_rows_name_file_line_and_problem(tmp_path, row, problem):
    assert _bad(tmp_path, row).startswith(problem)


@pytest.mark.parametrize("prefix, problem", [
    (f"{HEADER}\n", ":1: missing '# format: swtlab-wpm/1' line before the column header"),
    (f"# swtlab_version: 1\n# format: {FORMAT}\n{HEADER}\n",
     ":1: first line must be '# format: swtlab-wpm/1'"),
    (f"# format: swtlab-wpm/2\n{HEADER}\n", ":2: format 'swtlab-wpm/2', this reader reads"),
    (f"# format {FORMAT}\n{HEADER}\n", ":1: header comment must read '# key: value'"),
    (f"# format: {FORMAT}\n{HEADER.replace('a0,a1', 'a1,a0')}\n", ":2: column header must be"),
    ("", ":0: empty file"),
])
def test_malformed_headers_are_errors(tmp_path, prefix, problem):
    assert _bad(tmp_path, GOOD_ROW if prefix else "", prefix).startswith(problem)


def test_a_file_that_is_not_utf8_is_an_error(tmp_path):
    path = tmp_path / "latin.csv"
    path.write_bytes(f"# format: {FORMAT}\n{HEADER}\n".encode() + b"sabl\xe9,bb2\n")
    with pytest.raises(WpmFormatError, match=":3: not UTF-8"):
        read_wpm_csv(path)


def test_the_example_of_the_format_page_reads_and_evaluates_as_stated():
    from pathlib import Path

    from wpm_export import parse_wpm_csv

    page = (Path(__file__).parents[1] / "docs" / "wpm-csv.md").read_text()
    example = page.split("```text\n", 1)[1].split("```", 1)[0]
    header, curves = parse_wpm_csv(example, "docs/wpm-csv.md")
    assert header["format"] == FORMAT and len(curves) == 4
    assert curves[0].evaluate(0.2) == pytest.approx(13.11, abs=0.005)
    assert curves[0].evaluate(-0.05) == pytest.approx(-7.52, abs=0.005)  # braked branch
    assert (curves[3].step_below_zero, curves[3].slope_below_zero) == (0.0, 0.0)


GEOMETRY = ('# wheel_geometry: {"bb2": {"radius_m": 0.125, "width_m": 0.112, "grouser_count": 12, '
            '"grouser_height_m": 0.0092, "stiffness_n_per_mm": null}}')


def test_wheel_geometry_round_trips_and_old_files_still_read(tmp_path, table, fits):
    from swtlab_base.domain import Wheel
    from wpm_export import WheelPerformanceModule

    wheel = Wheel(0.125, 0.112, 12, 0.0092, stiffness_n_per_mm=30.0, name=fits[0].wheel)
    write_wpm_csv(fits, tmp_path / "new.csv", inputs_sha256(table), "0.1.0",
                  wheels={wheel.name: wheel})
    assert WheelPerformanceModule.load(tmp_path / "new.csv").wheel() == wheel
    write_wpm_csv(fits, tmp_path / "old.csv", inputs_sha256(table), "0.1.0")
    old = WheelPerformanceModule.load(tmp_path / "old.csv")
    dp = next(f for f in fits if f.quantity == "dp_n")
    assert old.wheels == {}   # every WPM query still answers
    assert old.at_slip(0.2, dp.load_n, multipass=dp.multipass)["dp_n"] == pytest.approx(
        dp.evaluate(0.2), rel=1e-12)
    with pytest.raises(ValueError, match="no wheel geometry .* needs wheel"):
        old.wheel(needed_for="the gap diagnosis")
    with pytest.raises(ValueError, match="no geometry for wheel"):
        write_wpm_csv(fits, tmp_path / "x.csv", inputs_sha256(table), "0.1.0", wheels={})


@pytest.mark.parametrize("line, problem", [
    ("# wheel_geometry: {bb2}", "wheel_geometry is not JSON"),
    (GEOMETRY.replace(', "stiffness_n_per_mm": null', ""), r"missing \['stiffness_n_per_mm'\]"),
    (GEOMETRY.replace("0.125", "-0.125"), "radius_m -0.125 must be > 0"),
    (GEOMETRY.replace('"bb2"', '"other"'), r"lacks wheel\(s\) \['bb2'\]"),
])
def test_malformed_wheel_geometry_names_the_line(tmp_path, line, problem):
    from wpm_export import parse_wpm_csv

    text = ("# format: swtlab-wpm/1\n" + line + "\n" + ",".join(COLUMNS) + "\n"
            "sand,bb2,0,70.0,dp_n,N,3,-0.1,0.6,1,2,3,4,,,,,7,0.1\n")
    with pytest.raises(WpmFormatError, match=f"<t>:2: .*{problem}"):
        parse_wpm_csv(text, "<t>")
