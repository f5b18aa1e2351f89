"""A planar four-wheeled rover driving through a sand dune, its wheels from a WPM CSV: once
with the Python runtime (wpm_export) asked every step, once with the wheel FMU (``swtlab wpm
fmu``) stepped in FMPy; both give the same trajectory.

    python examples/rover_sand_patch.py out/wpm.csv --fmu out/wheel.fmu --plot rover.png

The rover (mass ``MASS_KG``, four driven wheels sharing its weight, every wheel alike) drives
on sand at a commanded wheel speed; between ``PATCH_M`` the sand rises at ``SLOPE_DEG``.
States: position x, speed v and wheel angular speed w, explicit Euler at ``DT_S``:

    slip s = (r w - v) / (r w)  (driving; (r w - v) / v skidding)   (raw-run spec)
    I dw/dt = T_motor - T_wheel(s, W),  T_motor = clip(K (w_cmd - w), -T_max, T_max)
    m dv/dt = 4 DP(s, W) - m g sin(theta(x)),  W = m g cos(theta(x)) / 4

with T_wheel (the torque the soil takes) and DP from the WPM at the wheel's load W (the
slope changes it), the slip kept inside the curves' fitted range (clamped, counted). The
drive torque limit T_max is what makes the dune hard: the wheels slip more, the rover slows.
"""

from __future__ import annotations

import argparse
import math
from dataclasses import dataclass

import numpy as np

MASS_KG = 60.0
G_MPS2 = 9.81
SLOPE_DEG = 12.0
PATCH_M = (1.0, 2.5)  # the dune's slope, from x = 1 m to 2.5 m
WHEEL_INERTIA_KGM2 = 1.0  # wheel and the drive's inertia reflected through its gears
SPEED_GAIN_NMS = 20.0  # wheel-speed controller, N*m per rad/s
TORQUE_LIMIT_NM = 8.0  # per wheel: binds while the rover speeds up; 6 N*m barely climbs the dune
SPEED_MPS = 0.25  # commanded rover speed (wheel speed w_cmd = SPEED_MPS / r)
DT_S = 0.01
DURATION_S = 16.0


@dataclass
class Trajectory:
    """Per step: time, position, speed, wheel speed, slip, wheel load, DP and torque of one
    wheel; ``clamped``: steps whose slip left the fitted range (clamped to it)."""

    t_s: np.ndarray
    x_m: np.ndarray
    v_mps: np.ndarray
    w_radps: np.ndarray
    slip: np.ndarray
    load_n: np.ndarray
    dp_n: np.ndarray
    torque_nm: np.ndarray
    clamped: int


def slope_rad(x_m: float) -> float:
    return math.radians(SLOPE_DEG) if PATCH_M[0] <= x_m < PATCH_M[1] else 0.0


def simulate(wheel_forces, radius_m: float, slip_range: tuple[float, float]) -> Trajectory:
    """The rover driven through the dune; ``wheel_forces(slip, load_n) -> (dp_n,
    torque_nm)`` of one wheel."""
    steps = int(round(DURATION_S / DT_S))
    rows = np.zeros((steps, 8))
    x, v = 0.0, 0.05
    w = v / radius_m
    w_cmd = SPEED_MPS / radius_m
    clamped = 0
    for k in range(steps):
        theta = slope_rad(x)
        load = MASS_KG * G_MPS2 * math.cos(theta) / 4.0
        rim = radius_m * w
        slip = (rim - v) / rim if rim >= v else (rim - v) / v
        if not slip_range[0] <= slip <= slip_range[1]:
            clamped += 1
            slip = min(max(slip, slip_range[0]), slip_range[1])
        dp, torque = wheel_forces(slip, load)
        rows[k] = (k * DT_S, x, v, w, slip, load, dp, torque)
        motor = min(max(SPEED_GAIN_NMS * (w_cmd - w), -TORQUE_LIMIT_NM), TORQUE_LIMIT_NM)
        accel = (4.0 * dp - MASS_KG * G_MPS2 * math.sin(theta)) / MASS_KG
        x, v, w = x + DT_S * v, v + DT_S * accel, w + DT_S * (motor - torque) / WHEEL_INERTIA_KGM2
    return Trajectory(*rows.T, clamped=clamped)


def python_wheel(wpm_csv: str):
    """Wheel forces from the Python runtime: the curve at each step's load (kept per load
    value, the runtime's own curve object), evaluated at the slip."""
    from wpm_export import WheelPerformanceModule

    wpm = WheelPerformanceModule.load(wpm_csv)
    set_ = wpm.select()
    selection = dict(zip(("soil", "wheel", "multipass"), set_))
    curves: dict[float, tuple] = {}

    def forces(slip: float, load_n: float) -> tuple[float, float]:
        if load_n not in curves:
            curves[load_n] = tuple(wpm.curve(q, load_n, **selection)
                                   for q in ("dp_n", "torque_nm"))
        dp, torque = curves[load_n]
        return float(dp.evaluate(slip)), float(torque.evaluate(slip))

    radius = wpm.wheel(set_[1], needed_for="the rover").radius_m
    forces(0.0, MASS_KG * G_MPS2 / 4.0)  # the curves on level ground: their slip range
    dp, torque = curves[MASS_KG * G_MPS2 / 4.0]
    return forces, radius, (max(dp.slip_min, torque.slip_min), min(dp.slip_max, torque.slip_max))


def fmu_wheel(fmu_path: str):
    """Wheel forces from the FMU in FMPy (set load and slip, one step, read DP and torque);
    returns the forces, and a function that frees the instance."""
    from fmpy import extract, read_model_description
    from fmpy.fmi2 import FMU2Slave

    description = read_model_description(fmu_path)
    refs = {v.name: v.valueReference for v in description.modelVariables}
    folder = extract(fmu_path)
    fmu = FMU2Slave(guid=description.guid, unzipDirectory=folder,
                    modelIdentifier=description.coSimulation.modelIdentifier,
                    instanceName="wheel")
    fmu.instantiate()
    fmu.setupExperiment(startTime=0.0)
    fmu.enterInitializationMode()
    fmu.exitInitializationMode()
    clock = [0.0]
    inputs, outputs = [refs["load_n"], refs["slip"]], [refs["dp_n"], refs["torque_nm"]]

    def forces(slip: float, load_n: float) -> tuple[float, float]:
        fmu.setReal(inputs, [load_n, slip])
        fmu.doStep(currentCommunicationPoint=clock[0], communicationStepSize=DT_S)
        clock[0] += DT_S
        dp, torque = fmu.getReal(outputs)
        return dp, torque

    def close() -> None:
        fmu.terminate()
        fmu.freeInstance()

    return forces, close


def plot(python: Trajectory, fmu: Trajectory | None, path: str) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(3, 1, figsize=(7, 7), sharex=True)
    for trajectory, style, label in ((python, "-", "Python runtime"),
                                     (fmu, "--", "FMU in FMPy")):
        if trajectory is None:
            continue
        axes[0].plot(trajectory.t_s, trajectory.x_m, style, label=label)
        axes[1].plot(trajectory.t_s, trajectory.v_mps, style, label=label)
        axes[2].plot(trajectory.t_s, 100 * trajectory.slip, style, label=label)
    on_dune = (python.x_m >= PATCH_M[0]) & (python.x_m < PATCH_M[1])
    for ax in axes:
        ax.fill_between(python.t_s, 0, 1, where=on_dune, transform=ax.get_xaxis_transform(),
                        color="0.9", label=f"on the {SLOPE_DEG:g} deg dune")
    axes[0].set_ylabel("position, m")
    axes[1].set_ylabel("speed, m/s")
    axes[2].set_ylabel("slip, %")
    axes[2].set_xlabel("time, s")
    axes[0].legend(loc="upper left")
    axes[0].set_title(f"{MASS_KG:g} kg rover, drive torque limit {TORQUE_LIMIT_NM:g} N*m "
                      "per wheel")
    fig.tight_layout()
    fig.savefig(path, dpi=100)
    plt.close(fig)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("wpm_csv")
    parser.add_argument("--fmu", help="the wheel FMU (swtlab wpm fmu WPM.csv -o wheel.fmu)")
    parser.add_argument("--plot", help="PNG of the trajectories")
    args = parser.parse_args(argv)
    forces, radius, slip_range = python_wheel(args.wpm_csv)
    python = simulate(forces, radius, slip_range)
    fmu = None
    if args.fmu:
        fmu_forces, close = fmu_wheel(args.fmu)
        fmu = simulate(fmu_forces, radius, slip_range)
        close()
    print(f"Python runtime: x = {python.x_m[-1]:.4f} m after {DURATION_S:g} s, slip up to "
          f"{100 * python.slip.max():.1f} % ({python.clamped} steps clamped to the fitted "
          "range)")
    if fmu is not None:
        print(f"FMU in FMPy:    x = {fmu.x_m[-1]:.4f} m; largest difference in position "
              f"{np.max(np.abs(fmu.x_m - python.x_m)):.2e} m")
    if args.plot:
        plot(python, fmu, args.plot)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
