"""Ground truth of a simulated run, written apart from the raw files.

Stable-phase means are means of the noise-free signals (oscillation included,
gravel spikes and sensor effects excluded) over the true stable window.
"""

from __future__ import annotations

from dataclasses import asdict

import numpy as np

from virtual_testbed.grousers import passing_frequency_hz
from virtual_testbed.simulate import TrueRun

TRUTH_SCHEMA = "swtlab.virtual_testbed.truth/1"


def stable_means(true_run: TrueRun, radius_m: float, start_s: float,
                 end_s: float) -> dict[str, float]:
    """Noise-free means over ``[start_s, end_s]`` (thrust = T/r, resistance = T/r - DP)."""
    sig = true_run.signals
    window = (sig["t_s"] >= start_s) & (sig["t_s"] <= end_s)

    def mean(key):
        return float(np.mean(sig[key][window]))

    thrust_n = mean("torque_nm") / radius_m
    steered = {} if true_run.condition.mode != "steered" else {
        "side_force_n": mean("fy_n"), "slip_angle_deg": float(true_run.condition.steer_deg)}
    return {
        "slip": mean("slip"),
        "travel_velocity_mps": mean("velocity_mps"),
        "wheel_omega_radps": mean("omega_radps"),
        "wheel_load_n": mean("fz_n"),
        "dp_n": mean("dp_n"),
        "torque_nm": mean("torque_nm"),
        "thrust_n": thrust_n,
        "motion_resistance_n": thrust_n - mean("dp_n"),
        "sinkage_m": mean("sinkage_m"),
        **steered,
    }


def _dig_in(true_run: TrueRun) -> dict | None:
    """Where a dig-in run's drawbar-pull trend (no oscillation) peaked and where it ended."""
    if not true_run.digs_in:
        return None
    sig, tl = true_run.signals, true_run.timeline
    moving = (sig["t_s"] >= tl.motion_start_s) & (sig["t_s"] <= tl.decel_start_s)
    trend = np.where(moving, sig["dp_trend_n"], -np.inf)
    peak = int(np.argmax(trend))
    end = int(np.searchsorted(sig["t_s"], tl.decel_start_s))
    return {"dp_trend_peak_n": float(trend[peak]), "dp_trend_peak_t_s": float(sig["t_s"][peak]),
            "dp_trend_end_n": float(sig["dp_trend_n"][end]),
            "sinkage_end_m": float(sig["sinkage_m"][end])}


def truth_record(true_run: TrueRun, *, radius_m: float, grouser_count: int, raw_file: str,
                 form: str, seed: int, law_parameters: dict, dynamics, sensors, rates,
                 measurement_record: dict) -> dict:
    """The truth JSON of one run (schema ``TRUTH_SCHEMA``, see docs/virtual-testbed.md)."""
    c, tl = true_run.condition, true_run.timeline
    if true_run.digs_in:
        window, means = None, None
        reason = (f"dig-in: slip {c.slip_setpoint:.2f} >= {true_run.dig_in_slip:.3f} at "
                  f"{c.load_set_n:g} N, multipass {c.multipass}: sinkage grows without bound, "
                  "drawbar pull rises then collapses")
        omega = float(true_run.signals["omega_radps"].max())
    else:
        window, reason = {"start_s": tl.window_start_s, "end_s": tl.decel_start_s}, None
        means = stable_means(true_run, radius_m, tl.window_start_s, tl.decel_start_s)
        omega = means["wheel_omega_radps"]
    return {
        "schema": TRUTH_SCHEMA,
        "run_id": c.run_id,
        "raw_file": raw_file,
        "form": form,
        "seed": seed,
        "condition": c.to_dict(),
        "stable_window": window,
        "no_stable_phase_reason": reason,
        "stable_means": means,
        "law_steady": true_run.steady,
        "grouser_passing_frequency_hz": float(passing_frequency_hz(grouser_count, omega)),
        "grousers_in_contact": true_run.grousers_in_contact,
        "dig_in_threshold_slip": true_run.dig_in_slip,
        "dig_in": _dig_in(true_run),
        "timeline": {**asdict(tl), "motion_start_s": tl.motion_start_s,
                     "window_start_s": tl.window_start_s, "decel_start_s": tl.decel_start_s,
                     "duration_s": tl.duration_s},
        "law": law_parameters,
        "dynamics": asdict(dynamics),
        "sensors": asdict(sensors),
        "rates_hz": asdict(rates),
        "measurement": measurement_record,
    }
