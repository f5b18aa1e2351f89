"""examples/rover_sand_patch.py: the rover through the dune with the Python runtime and with
the wheel FMU in FMPy gives the same trajectory; on the dune's slope it settles where four
wheels' drawbar pull carries the weight's slope component with the drive at its torque
limit (force and torque balance: physics the example's integrator must reach, not the WPM's
numbers). In-family curves: swtlab's fit of the bb2_sand model."""

from __future__ import annotations

import importlib.util
import math
import sys
from pathlib import Path

import numpy as np
import pytest

from fitting import fit_results
from swtlab_base.domain import Wheel
from wpm_export import inputs_sha256, write_wpm_csv
from wpm_export.fmu import build_fmu
from test_fitting_synthetic import model_results_table

pytest.importorskip("fmpy")
EXAMPLE = Path(__file__).resolve().parents[1] / "examples" / "rover_sand_patch.py"


def _example():
    spec = importlib.util.spec_from_file_location("rover_sand_patch", EXAMPLE)
    module = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = module  # its dataclass looks itself up there
    spec.loader.exec_module(module)
    return module


def test_the_rover_through_the_dune_is_the_same_in_python_and_through_the_fmu(tmp_path):
    table = model_results_table(seed=7)
    csv = tmp_path / "wpm.csv"
    wheel = Wheel(radius_m=0.125, width_m=0.112, grouser_count=12, grouser_height_m=0.0092,
                  name="bb2")
    write_wpm_csv(fit_results(table), csv, inputs_sha256(table), "test", wheels={"bb2": wheel})
    build_fmu(csv, tmp_path / "wheel.fmu")
    rover = _example()
    forces, radius, slip_range = rover.python_wheel(str(csv))
    python = rover.simulate(forces, radius, slip_range)
    fmu_forces, close = rover.fmu_wheel(str(tmp_path / "wheel.fmu"))
    fmu = rover.simulate(fmu_forces, radius, slip_range)
    close()
    for name in ("x_m", "v_mps", "w_radps", "slip", "dp_n", "torque_nm"):
        np.testing.assert_allclose(getattr(fmu, name), getattr(python, name), rtol=1e-9,
                                   atol=1e-12)
    # through the dune, slower on it; settled on its slope at the end of it
    assert python.x_m[-1] > rover.PATCH_M[1]
    on_dune = (python.x_m >= rover.PATCH_M[0]) & (python.x_m < rover.PATCH_M[1])
    last = np.flatnonzero(on_dune)[-1]
    flat_end = python.v_mps[-1]
    assert python.v_mps[last] < 0.9 * flat_end
    theta = math.radians(rover.SLOPE_DEG)
    weight_share = rover.MASS_KG * rover.G_MPS2 * math.sin(theta) / 4.0
    assert python.dp_n[last] == pytest.approx(weight_share, rel=1e-3)
    # the soil's torque is the drive's, below its limit
    motor = rover.SPEED_GAIN_NMS * (rover.SPEED_MPS / radius - python.w_radps)
    assert python.torque_nm[last] == pytest.approx(motor[last], rel=1e-3)
    assert python.torque_nm[last] < rover.TORQUE_LIMIT_NM
    assert python.load_n[last] == pytest.approx(
        rover.MASS_KG * rover.G_MPS2 * math.cos(theta) / 4.0, rel=1e-12)
    rover.plot(python, fmu, str(tmp_path / "rover.png"))
    assert (tmp_path / "rover.png").stat().st_size > 10_000
