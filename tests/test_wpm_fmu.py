"""The wheel FMU (``swtlab wpm fmu``) in FMPy: a time-varying load and slip give the Python
runtime's DP, torque, sinkage, resistance and 95 % half-widths at every step
(``WheelPerformanceModule.at_slip`` and ``band``); FMPy's own validation finds no problem; a
load outside the tested ones or a NaN slip stops the simulation with the runtime's message.
In-family: the curves are swtlab's fit of the bb2_sand model."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

from fitting import fit_results
from swtlab_cli.main import main as swtlab
from wpm_export import WheelPerformanceModule, inputs_sha256, write_wpm_csv
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


@pytest.mark.parametrize("load_n, slip", [(400.0, 0.2), (150.0, np.nan)])
def test_a_bad_query_stops_with_the_runtimes_message(made, load_n, slip):
    csv, fmu = made
    messages = []
    inputs = np.array([(0.0, load_n, slip), (1.0, load_n, slip)],
                      dtype=[("time", float), ("load_n", float), ("slip", float)])
    from fmpy.fmi1 import FMICallException

    with pytest.raises(FMICallException):
        fmpy.simulate_fmu(str(fmu), input=inputs, step_size=0.5, stop_time=1.0,
                          output=["dp_n"],
                          logger=lambda *args: messages.append(args[-1].decode()
                                                               if isinstance(args[-1], bytes)
                                                               else str(args[-1])))
    wpm = WheelPerformanceModule.load(csv)
    with pytest.raises(ValueError) as python_error:
        wpm.at_slip(slip, load_n, multipass=1)
    assert any(m.endswith(f": {python_error.value}") for m in messages), messages
