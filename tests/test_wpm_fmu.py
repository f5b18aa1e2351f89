"""The wheel FMU (``swtlab wpm fmu``) in FMPy: a time-varying load and slip give the Python
runtime's DP, torque, sinkage, resistance and 95 % half-widths at every step
(``WheelPerformanceModule.at_slip`` and ``band``); FMPy's own validation finds no problem, and
the FMI cross-check rules' checks (FMPy's ``fmpy.cross_check``) pass on the FMU laid out as a
cross-check submission; bad input -- a load outside the tested ones, a NaN load or slip,
another wheel, a CSV of another format version -- stops the simulation (or the ``swtlab wpm
fmu`` command) with the runtime's message. In-family: the curves are swtlab's fit of the
bb2_sand model; the cross-check's reference is the Python runtime's answer."""

from __future__ import annotations

import re
import warnings
import zipfile

import numpy as np
import pytest

from fitting import fit_results
from swtlab_cli.main import main as swtlab
from wpm_export import (WheelPerformanceModule, WpmFormatError, WpmSelectionError,
                        inputs_sha256, write_wpm_csv)
from test_fitting_synthetic import model_results_table

fmpy = pytest.importorskip("fmpy")


@pytest.fixture(scope="module")
def made(tmp_path_factory):
    folder = tmp_path_factory.mktemp("fmu")
    table = model_results_table(multipass=(0, 1), seed=7)
    csv = folder / "wpm.csv"
    write_wpm_csv(fit_results(table), csv, inputs_sha256(table), "test")
    fmu = folder / "wheel.fmu"
    assert swtlab(["wpm", "fmu", str(csv), "-o", str(fmu), "--multipass", "1"]) == 0
    return csv, fmu


def test_fmpy_validation_finds_no_problem(made):
    from fmpy.validation import validate_fmu

    assert validate_fmu(str(made[1])) == []


def _write_csv(path, columns: dict) -> None:
    """A CSV of the FMI cross-check rules: a header of the names, time first."""
    np.savetxt(path, np.column_stack(list(columns.values())), delimiter=",",
               header=",".join(columns), comments="", fmt="%.17g")


@pytest.mark.filterwarnings("ignore:Please import:DeprecationWarning")  # FMPy's scipy import
def test_the_fmi_cross_check_rules_find_no_problem(made, tmp_path):
    """The checks the FMI cross-check repository runs on a vendor's test FMUs and results, as
    FMPy implements them (``fmpy.cross_check.validate_vendor_repo``: the model description
    against the FMI schema, FMI version and kind, the input, reference and options files,
    and the importing tool's result within the rules' band about the reference): the FMU
    laid out as swtlab's test FMU, its reference the Python runtime's answers, FMPy the
    importing tool. A result 20 % off is caught (the check is live)."""
    from fmpy.cross_check.validate_vendor_repo import validate_repo
    from importlib.metadata import version

    csv, fmu = made
    model = "swtwpm_wheel"  # the cross-check rules: <model>/<model>.fmu
    repo = tmp_path / "swtlab-fmi-cross-check"
    exported = repo / "fmus" / "2.0" / "cs" / "linux64" / "swtlab" / version("swtlab") / model
    exported.mkdir(parents=True)
    (exported / f"{model}.fmu").write_bytes(fmu.read_bytes())
    t = np.linspace(0.0, 2.0, 201)
    load_n, slip = 75.0 + 110.0 * (1 + np.sin(3 * t)), 0.05 + 0.25 * (1 + np.sin(2 * t))
    names = ["dp_n", "torque_nm", "sinkage_m", "resistance_n"]
    expected = WheelPerformanceModule.load(csv).at_slip(slip, load_n, multipass=1)
    _write_csv(exported / f"{model}_in.csv", {"time": t, "load_n": load_n, "slip": slip})
    _write_csv(exported / f"{model}_ref.csv", {"time": t, **{q: expected[q] for q in names}})
    (exported / f"{model}_ref.opt").write_text(
        "StartTime,0.0\nStopTime,2.0\nStepSize,0.01\nRelTol,1e-06\n")
    # the importing tool, as the rules run it: the input file, the options' step and stop
    inputs = np.genfromtxt(exported / f"{model}_in.csv", delimiter=",", names=True)
    result = fmpy.simulate_fmu(str(exported / f"{model}.fmu"), input=inputs, step_size=0.01,
                               stop_time=2.0, output=names)
    imported = (repo / "results" / "2.0" / "cs" / "linux64" / "FMPy" / fmpy.__version__
                / "swtlab" / version("swtlab") / model)
    imported.mkdir(parents=True)
    out = {"time": result["time"], **{q: result[q] for q in names}}
    _write_csv(imported / f"{model}_out.csv", out)
    (imported / "passed").touch()
    assert validate_repo(str(repo)) == (1, 1, [])
    _write_csv(imported / f"{model}_out.csv", {**out, "dp_n": 1.2 * result["dp_n"]})
    _, _, problems = validate_repo(str(repo))
    assert len(problems) == 1 and 'outside epsilon band for variable "dp_n"' in problems[0]


def test_a_time_varying_load_and_slip_give_the_runtimes_outputs(made):
    csv, fmu = made
    t = np.linspace(0.0, 2.0, 9)
    inputs = np.array(list(zip(t, 75.0 + 110.0 * (1 + np.sin(3 * t)), 0.5 * np.sin(2 * t))),
                      dtype=[("time", float), ("load_n", float), ("slip", float)])
    names = ["dp_n", "torque_nm", "sinkage_m", "resistance_n"]
    result = fmpy.simulate_fmu(str(fmu), input=inputs, step_size=0.01, stop_time=2.0,
                               output=["load_n", "slip", *names,
                                       *[f"{n}_conf95" for n in names],
                                       *[f"{n}_pred95" for n in names], "status"])
    assert len(result) == 201 and np.ptp(result["load_n"]) > 150 and np.ptp(result["slip"]) > 0.5
    wpm = WheelPerformanceModule.load(csv)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # slips beyond the fitted range: extrapolated, flagged
        expected = wpm.at_slip(result["slip"], result["load_n"], multipass=1)
        for q in names:
            scale = np.max(np.abs(expected[q]))
            np.testing.assert_allclose(result[q], expected[q], rtol=0, atol=1e-9 * scale)
            _, conf, pred = wpm.band(q, result["slip"], result["load_n"], multipass=1)
            np.testing.assert_allclose(result[f"{q}_conf95"], conf, rtol=1e-9)
            np.testing.assert_allclose(result[f"{q}_pred95"], pred, rtol=1e-9)
    outside = (result["slip"] < wpm.curve("dp_n", 150.0, multipass=1).slip_min) | (
        result["slip"] > wpm.curve("dp_n", 150.0, multipass=1).slip_max)
    assert np.array_equal(result["status"] == 1, outside) and outside.any()


def _simulate(fmu, load_n: float, slip: float, start_values=None) -> tuple[Exception, list]:
    """Simulate one second at a constant load and slip: (the exception FMPy raised, the
    FMU's log messages)."""
    messages = []
    inputs = np.array([(0.0, load_n, slip), (1.0, load_n, slip)],
                      dtype=[("time", float), ("load_n", float), ("slip", float)])
    with pytest.raises(Exception) as raised:
        fmpy.simulate_fmu(str(fmu), input=inputs, step_size=0.5, stop_time=1.0,
                          output=["dp_n"], start_values=start_values or {},
                          logger=lambda *args: messages.append(args[-1].decode()
                                                               if isinstance(args[-1], bytes)
                                                               else str(args[-1])))
    return raised.value, messages


def _carried(fmu, folder):
    """The CSV the FMU carries, unpacked to ``folder/resources/wpm.csv``."""
    with zipfile.ZipFile(fmu) as archive:
        archive.extract("resources/wpm.csv", folder)
    return folder / "resources" / "wpm.csv"


def _named(message: str) -> str:
    """The message with the path of the carried CSV (the FMU's unpacked copy, or ours)
    written as ``resources/wpm.csv``."""
    return re.sub(r"\S*/resources/wpm\.csv", "resources/wpm.csv", message)


@pytest.mark.parametrize("load_n, slip", [(400.0, 0.2), (150.0, np.nan), (np.nan, 0.2),
                                          (-5.0, 0.2)])
def test_a_bad_query_stops_with_the_runtimes_message(made, load_n, slip):
    csv, fmu = made
    from fmpy.fmi1 import FMICallException

    raised, messages = _simulate(fmu, load_n, slip)
    assert isinstance(raised, FMICallException)
    wpm = WheelPerformanceModule.load(csv)
    with pytest.raises(ValueError) as python_error:
        wpm.at_slip(slip, load_n, multipass=1)
    assert any(m.endswith(f": {python_error.value}") for m in messages), messages


def test_another_wheel_stops_with_the_runtimes_message(made, tmp_path):
    """The FMU's ``wheel`` parameter set to a wheel its CSV does not hold."""
    _, fmu = made
    from fmpy.fmi1 import FMICallException

    raised, messages = _simulate(fmu, 150.0, 0.2, {"wheel": "mars_wheel"})
    assert isinstance(raised, FMICallException)
    with pytest.raises(WpmSelectionError) as python_error:
        WheelPerformanceModule.load(_carried(fmu, tmp_path)).slip_for(
            "dp_n", 10.0, 150.0, wheel="mars_wheel")
    expected = _named(str(python_error.value))
    assert expected == ("no curves for wheel='mars_wheel' in resources/wpm.csv; choices: "
                        "soil='bb2_sand', wheel='bb2', multipass=1")
    assert [_named(m) for m in messages] == [expected]


def test_a_csv_of_another_format_version_is_refused_at_instantiation(made, tmp_path):
    """An FMU whose carried CSV says ``swtlab-wpm/2`` (made by hand: the command refuses
    such a file, below) does not instantiate, naming the file, line and version."""
    _, fmu = made
    other = tmp_path / "v2.fmu"
    with zipfile.ZipFile(fmu) as source, zipfile.ZipFile(other, "w") as target:
        for item in source.infolist():
            data = source.read(item)
            if item.filename == "resources/wpm.csv":
                data = data.replace(b"# format: swtlab-wpm/1", b"# format: swtlab-wpm/2")
            target.writestr(item, data)
    raised, messages = _simulate(other, 150.0, 0.2)
    assert "instantiate" in str(raised)
    with pytest.raises(WpmFormatError) as python_error:
        WheelPerformanceModule.load(_carried(other, tmp_path))
    expected = _named(str(python_error.value))
    assert re.fullmatch(r"resources/wpm\.csv:\d+: format 'swtlab-wpm/2', this reader reads "
                        r"'swtlab-wpm/1'", expected)
    assert [_named(m) for m in messages] == [expected]


@pytest.mark.parametrize("bad", ["another format version", "another wheel"])
def test_the_fmu_command_refuses_bad_input_with_the_runtimes_message(made, tmp_path, capsys,
                                                                      bad):
    csv, _ = made
    source, flags = csv, ["--wheel", "mars_wheel"]
    if bad == "another format version":
        source, flags = tmp_path / "v2.csv", []
        source.write_text(csv.read_text().replace("swtlab-wpm/1", "swtlab-wpm/2"))
    out = tmp_path / "wheel.fmu"
    capsys.readouterr()
    assert swtlab(["wpm", "fmu", str(source), "-o", str(out), *flags]) == 3
    with pytest.raises(ValueError) as python_error:
        WheelPerformanceModule.load(source).slip_for("dp_n", 10.0, 150.0, wheel="mars_wheel")
    assert capsys.readouterr().err == f"swtlab wpm: {python_error.value}\n"
    assert not out.exists()
