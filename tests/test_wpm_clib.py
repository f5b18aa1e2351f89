"""libswtwpm (the C WPM, through wpm_export.clib) against the Python runtime's public API
(``WheelPerformanceModule``: ``at_slip``, ``slip_for``, ``band``, ``curve``): 100,000 random
queries (forward values and the inverse at random continuous loads) and the 95 % bands agree
within 1e-9; the edges (beyond the maximum, below the minimum, inside the jump at zero slip,
outside the tested loads) and bad input (another format version, another wheel, NaN queries,
loads out of range) give the same answers and the same messages; 100 mutated files run
through the reader and every query under AddressSanitizer + UBSan without a finding (the
bench, ``python -m bench wpm_c``, runs 10,000).

In-family: the curves come from swtlab's own fit of the bb2_sand model (the writer and the
runtime are what the C library is held to); the C code shares no code with the Python
runtime, only the documented method (docs/wpm-csv.md)."""

from __future__ import annotations

import csv
import shutil
import warnings
from pathlib import Path

import numpy as np
import pytest

from fitting import LoadExtrapolationWarning, LoadRangeError, fit_results
from swtlab_base.domain import Wheel
from wpm_export import (WheelPerformanceModule, WpmFormatError, WpmSelectionError,
                        inputs_sha256, read_wpm_csv, write_wpm_csv)
from wpm_export.clib import CWheelPerformanceModule
from bench.wpm_fuzz import build_driver, run_driver, seed_texts, write_mutants
from test_fitting_synthetic import model_results_table

QUERIES = 100_000
WHEEL = Wheel(radius_m=0.125, width_m=0.112, grouser_count=12, grouser_height_m=0.0092,
              stiffness_n_per_mm=None, name="bb2")
RTOL = 1e-9


@pytest.fixture(scope="module")
def files(tmp_path_factory) -> dict[str, Path]:
    """The full WPM CSV (uncertainty, braked branch, three loads) and its variants."""
    folder = tmp_path_factory.mktemp("clib")
    table = model_results_table(multipass=(0, 1), seed=7)
    full = folder / "wpm.csv"
    write_wpm_csv(fit_results(table), full, inputs_sha256(table), "test", wheels={"bb2": WHEEL})
    names = ("full", "no_uncertainty", "no_branch", "no_geometry", "one_load", "two_loads")
    out = {}
    for name, text in zip(names, seed_texts(full.read_text())):
        out[name] = folder / f"{name}.csv"
        out[name].write_text(text)
    return out


def _scale(path: Path, quantity: str, multipass: int) -> float:
    """The quantity's value scale: the largest |value| of its tested curves on their range
    (values cross zero, so their error is relative to this)."""
    _, curves = read_wpm_csv(path)
    return max(float(np.max(np.abs(c.evaluate(np.linspace(c.slip_min, c.slip_max, 201)))))
               for c in curves if c.quantity == quantity and c.multipass == multipass)


def _tested_loads(path: Path, quantity: str, multipass: int) -> list[float]:
    return sorted(c.load_n for c in read_wpm_csv(path)[1]
                  if c.quantity == quantity and c.multipass == multipass)


def _compare(path: Path, n: int, seed: int) -> int:
    """``n`` forward and ``n`` inverse queries per quantity and multipass at random loads in
    the tested range: C and Python agree within RTOL; returns the number compared."""
    py, c = WheelPerformanceModule.load(path), CWheelPerformanceModule(path)
    rng = np.random.default_rng(seed)
    compared = 0
    for _, _, mp in py.sets():
        for q in py.quantities(multipass=mp):
            tested = _tested_loads(path, q, mp)
            curve = py.curve(q, tested[0], multipass=mp)
            loads = rng.uniform(tested[0], tested[-1], n)
            slips = rng.uniform(curve.slip_min, curve.slip_max, n)
            with warnings.catch_warnings():
                warnings.simplefilter("error")
                expected = py.at_slip(slips, loads, multipass=mp)[q]
                got = c.value(q, slips, loads, multipass=mp)
            scale = _scale(path, q, mp)
            np.testing.assert_allclose(got, expected, rtol=0, atol=RTOL * scale)
            # targets over the curves' values and beyond both ends (above_max, below_min)
            span = np.ptp(expected)
            targets = rng.uniform(expected.min() - 0.2 * span, expected.max() + 0.2 * span, n)
            want = py.slip_for(q, targets, loads, multipass=mp)
            have = c.slip_for(q, targets, loads, multipass=mp)
            assert np.array_equal(want.status, have.status)
            np.testing.assert_allclose(have.slip, want.slip, rtol=0, atol=RTOL)  # NaN == NaN
            np.testing.assert_allclose(have.value, want.value, rtol=0, atol=RTOL * scale)
            assert {"ok", "above_max", "below_min"} <= set(want.status.tolist())
            compared += 2 * n
    return compared


def test_one_hundred_thousand_random_queries_agree_with_the_python_runtime(files):
    assert _compare(files["full"], QUERIES // 20, seed=1) == QUERIES


@pytest.mark.parametrize("variant", ["no_uncertainty", "no_branch", "one_load", "two_loads"])
def test_every_header_variant_and_load_count_agrees(files, variant):
    if variant == "one_load":  # one tested load: only that load answers
        py, c = WheelPerformanceModule.load(files[variant]), CWheelPerformanceModule(
            files[variant])
        load = read_wpm_csv(files[variant])[1][0].load_n
        s = np.linspace(-0.1, 0.6, 50)
        for q in py.quantities(multipass=0):
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                np.testing.assert_allclose(c.value(q, s, load, multipass=0),
                                           py.at_slip(s, load, multipass=0)[q], rtol=0,
                                           atol=RTOL * _scale(files[variant], q, 0))
        return
    _compare(files[variant], 1000, seed=2)


def test_bands_agree_with_the_runtimes(files):
    path = files["full"]
    py, c = WheelPerformanceModule.load(path), CWheelPerformanceModule(path)
    rng = np.random.default_rng(3)
    for mp in (0, 1):
        for q in ("dp_n", "torque_nm", "sinkage_m", "resistance_n"):
            tested = _tested_loads(path, q, mp)
            curve = py.curve(q, tested[0], multipass=mp)
            # 12 random loads and the tested ones, 25 slips at each
            loads = np.repeat(np.concatenate([rng.uniform(tested[0], tested[-1], 12), tested]),
                              25)
            slips = rng.uniform(curve.slip_min, curve.slip_max, loads.size)
            mean, conf, pred = py.band(q, slips, loads, multipass=mp)
            got = c.band(q, slips, loads, multipass=mp)
            assert np.all(conf > 0)
            np.testing.assert_allclose(got[1], conf, rtol=RTOL)
            np.testing.assert_allclose(got[2], pred, rtol=RTOL)
            np.testing.assert_allclose(got[0], mean, rtol=0, atol=RTOL * _scale(path, q, mp))
    # no uncertainty columns: unknown (NaN), not zero, in both
    unknown = CWheelPerformanceModule(files["no_uncertainty"]).band("dp_n", [0.2], 150.0,
                                                                    multipass=0)
    assert np.isnan(unknown[1]).all() and np.isnan(unknown[2]).all()
    assert np.isnan(WheelPerformanceModule.load(files["no_uncertainty"]).band(
        "dp_n", [0.2], 150.0, multipass=0)[1]).all()


def test_edges_beyond_the_maximum_below_the_minimum_and_inside_the_step(files):
    path = files["full"]
    py, c = WheelPerformanceModule.load(path), CWheelPerformanceModule(path)
    load = 151.5
    for q in py.quantities(multipass=0):
        curve = py.curve(q, load, multipass=0)
        s = np.linspace(curve.slip_min, curve.slip_max, 200_001)
        values = curve.evaluate(s)
        top, bottom = values.max(), values.min()
        found = c.slip_for(q, [top + 1.0, bottom - 1.0], load, multipass=0)
        assert found.status.tolist() == ["above_max", "below_min"]
        assert found.slip[0] == 1.0 and np.isnan(found.slip[1])
        # the extremes over the fitted range (turning points included, and the braked limit
        # y(0-) at the jump): Python's to RTOL, the dense grid's to its resolution
        scale = _scale(path, q, 0)
        np.testing.assert_allclose(found.value, py.slip_for(
            q, [top + 1.0, bottom - 1.0], load, multipass=0).value, rtol=0, atol=RTOL * scale)
        resolution = np.max(np.abs(np.diff(values)))
        assert abs(found.value[0] - top) <= resolution and abs(found.value[1] - bottom) <= \
            resolution
        if curve.step_below_zero and curve.slip_min < 0:  # the jump at zero slip
            below = curve.evaluate(-1e-15)
            mid = 0.5 * (below + curve.evaluate(0.0))
            reached_before = np.any(np.diff(np.sign(values[s < 0] - mid)) != 0)
            step = c.slip_for(q, mid, load, multipass=0)
            assert step.status == py.slip_for(q, mid, load, multipass=0).status
            if not reached_before:
                assert step.status == "at_step" and step.slip == 0.0 and step.value == mid


def test_targets_inside_a_jump_at_zero_slip_give_at_step_in_both(files, tmp_path):
    """dp_n's curves given a jump up at zero slip (step_below_zero -20 N: the braked side
    ends 20 N below the driven one): targets in the jump and not reached below zero give
    slip 0.0 and ``at_step``, the same in C and Python, at random loads."""
    rows = list(csv.reader(files["full"].read_text().splitlines()))
    header = next(r for r in rows if r and r[0] == "soil")
    step = header.index("step_below_zero")
    for r in rows:
        if len(r) == len(header) and r[4] == "dp_n":
            r[step] = "-20.0"
    path = tmp_path / "jump.csv"
    path.write_text("\n".join(",".join(r) for r in rows) + "\n")
    py, c = WheelPerformanceModule.load(path), CWheelPerformanceModule(path)
    rng = np.random.default_rng(5)
    loads = rng.uniform(70.0, 300.0, 2000)
    at_zero = py.at_slip(0.0, loads, multipass=0)["dp_n"]
    targets = at_zero - rng.uniform(-5.0, 25.0, loads.size)  # across the jump and around it
    want = py.slip_for("dp_n", targets, loads, multipass=0)
    have = c.slip_for("dp_n", targets, loads, multipass=0)
    assert np.array_equal(want.status, have.status)
    assert (want.status == "at_step").sum() > 100
    np.testing.assert_allclose(have.slip, want.slip, rtol=0, atol=RTOL)
    np.testing.assert_allclose(have.value, want.value, rtol=0, atol=RTOL * 100.0)
    assert np.all(have.slip[have.status == "at_step"] == 0.0)


def _message(call) -> tuple[type, str]:
    with pytest.raises(Exception) as caught:
        call()
    return caught.type, str(caught.value)


def _warning(call) -> tuple[type, str]:
    with pytest.warns(Warning) as caught:
        call()
    return caught[0].category, str(caught[0].message)


def test_bad_input_gives_the_same_error_and_message_as_python(files, tmp_path):
    path = files["full"]
    py, c = WheelPerformanceModule.load(path), CWheelPerformanceModule(path)
    one = files["one_load"]
    py_one, c_one = WheelPerformanceModule.load(one), CWheelPerformanceModule(one)
    cases = {  # expected (exception, message): (python call, C call)
        (LoadRangeError, "load_n=400 N is outside the tested loads (70-300 N) of dp_n; pass "
         "allow_extrapolation=True to extrapolate linearly from the two nearest loads"):
        (lambda: py.slip_for_one("dp_n", 10.0, 400.0, multipass=0),
         lambda: c.slip_for("dp_n", 10.0, 400.0, multipass=0)),
        (LoadRangeError, "load_n=10 N is outside the tested loads (70-300 N) of dp_n; pass "
         "allow_extrapolation=True to extrapolate linearly from the two nearest loads"):
        (lambda: py.at_slip([0.1, 0.2], [100.0, 10.0], multipass=0),
         lambda: c.value("dp_n", [0.1, 0.2], [100.0, 10.0], multipass=0)),
        (LoadRangeError, "load_n=nan: the wheel load must be a finite number > 0 N"):
        (lambda: py.slip_for("dp_n", 10.0, [150.0, np.nan], multipass=0),
         lambda: c.slip_for("dp_n", 10.0, [150.0, np.nan], multipass=0)),
        (LoadRangeError, "load_n=-5.0: the wheel load must be a finite number > 0 N"):
        (lambda: py.band_one("dp_n", 0.2, -5.0, multipass=0),
         lambda: c.band("dp_n", 0.2, -5.0, multipass=0)),
        (LoadRangeError, "load_n=0.0: the wheel load must be a finite number > 0 N"):
        (lambda: py.slip_for_one("dp_n", 10.0, 0.0, multipass=0),
         lambda: c.slip_for("dp_n", 10.0, 0.0, multipass=0)),
        (ValueError, "target=nan: dp_n queries need a finite number"):  # before the load
        (lambda: py.slip_for("dp_n", [5.0, np.nan], [150.0, -1.0], multipass=0),
         lambda: c.slip_for("dp_n", [5.0, np.nan], [150.0, -1.0], multipass=0)),
        (ValueError, "slip=inf: torque_nm queries need a finite number"):
        (lambda: py.band_one("torque_nm", np.inf, 150.0, multipass=0),
         lambda: c.band("torque_nm", np.inf, 150.0, multipass=0)),
        (ValueError, "slip=nan: dp_n queries need a finite number"):
        (lambda: py.at_slip(np.nan, 150.0, multipass=0),
         lambda: c.value("dp_n", np.nan, 150.0, multipass=0)),
        (WpmSelectionError, f"no curves for wheel='other wheel' in "
         f"{path}; choices: soil='bb2_sand', wheel='bb2', multipass=0; soil='bb2_sand', "
         "wheel='bb2', multipass=1"):
        (lambda: py.slip_for("dp_n", 10.0, 150.0, wheel="other wheel"),
         lambda: c.slip_for("dp_n", 10.0, 150.0, wheel="other wheel")),
        (WpmSelectionError, f"2 curve sets match in {path}; pick one: soil='bb2_sand', "
         "wheel='bb2', multipass=0; soil='bb2_sand', wheel='bb2', multipass=1"):
        (lambda: py.slip_for_one("dp_n", 10.0, 150.0),
         lambda: c.slip_for("dp_n", 10.0, 150.0)),
        (WpmSelectionError, f"no curves for soil=\"it's\", multipass=3 in {path}; "
         "choices: soil='bb2_sand', wheel='bb2', multipass=0; soil='bb2_sand', wheel='bb2', "
         "multipass=1"):
        (lambda: py.band("dp_n", 0.1, 150.0, soil="it's", multipass=3),
         lambda: c.band("dp_n", 0.1, 150.0, soil="it's", multipass=3)),
    }
    tested = _tested_loads(one, "dp_n", 0)[0]
    cases[(LoadRangeError, f"load_n=120 N: dp_n was tested at {tested:g} N only, nothing to "
           "interpolate from")] = (lambda: py_one.slip_for_one("dp_n", 1.0, 120.0, multipass=0),
                                   lambda: c_one.slip_for("dp_n", 1.0, 120.0, multipass=0))
    for expected, (python_call, c_call) in cases.items():
        assert _message(python_call) == expected
        assert _message(c_call) == expected
    # a load outside the tested ones, allowed: the same warning and value
    loads = [320.0, 100.0, 330.0]
    for quantity in ("dp_n", "sinkage_m"):
        python_warning = _warning(lambda q=quantity: py.slip_for(
            q, [1e-3] * 3, loads, multipass=0, allow_extrapolation=True))
        assert python_warning == (LoadExtrapolationWarning, f"2 load(s) outside the tested "
                                  f"loads (70-300 N) of {quantity}, e.g. load_n=320 N: "
                                  "extrapolated linearly")
        assert _warning(lambda q=quantity: c.slip_for(
            q, [1e-3] * 3, loads, multipass=0, allow_extrapolation=True)) == python_warning
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        far = c.value("dp_n", 0.2, 330.0, multipass=0, allow_extrapolation=True)
        assert far == pytest.approx(py.at_slip(0.2, 330.0, multipass=0,
                                               allow_extrapolation=True)["dp_n"], rel=1e-9)
    # another format version, and a file that is not there
    other = tmp_path / "v2.csv"
    other.write_text(path.read_text().replace("swtlab-wpm/1", "swtlab-wpm/2"))
    for bad in (other, files["full"].parent / "missing.csv"):
        python_error = _message(lambda bad=bad: WheelPerformanceModule.load(bad))
        c_error = _message(lambda bad=bad: CWheelPerformanceModule(bad))
        assert issubclass(python_error[0], c_error[0])
    assert _message(lambda: CWheelPerformanceModule(other)) == _message(
        lambda: WheelPerformanceModule.load(other))
    assert "format 'swtlab-wpm/2', this reader reads 'swtlab-wpm/1'" in _message(
        lambda: CWheelPerformanceModule(other))[1]


def test_the_wheel_geometry_header_is_read(files):
    c = CWheelPerformanceModule(files["full"])
    expected = WheelPerformanceModule.load(files["full"]).wheel().geometry()
    assert c.wheel_geometry() == expected
    with pytest.raises(WpmSelectionError, match="no wheel geometry"):
        CWheelPerformanceModule(files["no_geometry"]).wheel_geometry()


@pytest.mark.skipif(shutil.which("gcc") is None, reason="needs gcc with the sanitizers")
def test_a_hundred_mutated_files_under_the_sanitizers(files, tmp_path):
    paths = write_mutants(seed_texts(files["full"].read_text()), 100, seed=11, folder=tmp_path)
    results, exit_code, report = run_driver(build_driver(tmp_path), paths)
    assert exit_code == 0 and "ERROR" not in report and "runtime error" not in report, report
    assert len(results) == len(paths)
    refused = [(p, m) for p, (code, m) in zip(paths, results) if code < 0]
    assert all(code in (0, -1) for code, _ in results)  # read, or a format error
    assert all(m.startswith(f"{p}:") and len(m) > len(str(p)) + 4 for p, m in refused)
    assert 0.3 * len(paths) < len(refused) < len(paths)  # the mutants break files, not all
    # the C reader refuses what the Python reader refuses (NUL bytes: refused by C only)
    for p, (code, _) in zip(paths, results):
        if b"\x00" in p.read_bytes():
            continue
        try:
            read_wpm_csv(p)
            python_reads = True
        except WpmFormatError:
            python_reads = False
        except (TypeError, OverflowError):  # the Python reader's hostile-JSON gaps
            continue
        assert python_reads == (code == 0), p
