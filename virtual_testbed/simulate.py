"""Noise-free signals of one run over time, from a performance law and a condition.

Everything is computed on a fine uniform grid (vectorised, no loop per
sample); sensors later sample it at their own uneven times. The steady state
is the law's value at the steady slip; the run reaches it through

- a smooth acceleration (``Timeline.accel_s``),
- thrust building up with shear displacement (time constant ``shear_build_s``),
- sinkage settling exponentially from the static sinkage with time constant
  ``settle_time_s/5`` (within 1 % after about 25 s at 40 m/h on ES-3),
  motion resistance following sinkage (compaction/bulldozing),
- at very high slip, dig-in: sinkage grows without bound, so resistance grows
  and drawbar pull rises, then collapses (no stable phase),
- grouser passing oscillation on forces and sinkage (see ``grousers``).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.integrate import cumulative_trapezoid

from virtual_testbed import grousers
from virtual_testbed.conditions import SLIP_IMPOSED, RunCondition
from virtual_testbed.lateral import DEFAULT_LATERAL, LateralLaw
from virtual_testbed.law import PerformanceLaw, self_propelled_slip, towed_slip
from virtual_testbed.rig import Timeline, Wheel


@dataclass(frozen=True)
class Dynamics:
    """Knobs of the transient, dig-in and oscillation (ratios are of the wheel load)."""

    grid_hz: float = 1000.0
    shear_build_s: float = 1.5
    static_sinkage_ratio: float = 0.6
    free_sled_start_slip_ratio: float = 0.5
    dig_in_slip_at_70n: float = 0.95
    dig_in_slip_at_300n: float = 0.80
    dig_in_multipass_margin: float = 0.05
    dig_rate_per_s: float = 0.025
    dig_delay_s: float = 5.0
    dp_oscillation_ratio: float = 0.025
    fz_oscillation_ratio: float = 0.02
    torque_oscillation_ratio: float = 0.025
    sinkage_oscillation_per_grouser_height: float = 0.05

    def dig_in_slip(self, load_n: float, multipass: int) -> float:
        """Slip from which the wheel digs in (falls with load, rises on compacted soil)."""
        frac = (load_n - 70.0) / (300.0 - 70.0)
        slip = self.dig_in_slip_at_70n + frac * (self.dig_in_slip_at_300n - self.dig_in_slip_at_70n)
        return slip + self.dig_in_multipass_margin * min(multipass, 1)


@dataclass(frozen=True)
class TrueRun:
    """Noise-free signals on the fine grid, with the steady state they settle to."""

    condition: RunCondition
    timeline: Timeline
    steady: dict[str, float]
    digs_in: bool
    dig_in_slip: float
    grousers_in_contact: float
    signals: dict[str, np.ndarray]


def steady_slip(condition: RunCondition, law: PerformanceLaw) -> float:
    """Slip the run settles at: the set point, or where DP = 0 (free sled) or torque = 0 (towed)."""
    if condition.mode in SLIP_IMPOSED:
        return float(condition.slip_setpoint)
    solver = self_propelled_slip if condition.mode == "free_sled" else towed_slip
    return solver(law, condition.load_set_n, condition.multipass, condition.gravity_mps2)


def surface_speed_mps(velocity_mps, slip):
    """``r*omega`` giving ``slip`` at travel velocity ``v`` (spec: driving and skid forms)."""
    slip = np.asarray(slip, float)
    driving = velocity_mps / (1.0 - np.minimum(slip, 0.999))
    return np.where(slip >= 0, driving, velocity_mps * (1.0 + slip))


def travel_speed_mps(surface_speed, slip):
    """Travel velocity ``v`` of a wheel with surface speed ``r*omega`` at ``slip``."""
    slip = np.asarray(slip, float)
    return np.where(slip >= 0, surface_speed * (1.0 - slip), surface_speed / (1.0 + slip))


def _smoothstep(t, start_s: float, length_s: float) -> np.ndarray:
    x = np.clip((t - start_s) / length_s, 0.0, 1.0)
    return 0.5 * (1.0 - np.cos(np.pi * x))


def _kinematics(c: RunCondition, slip_ss: float, speed, settle, radius_m: float, dyn: Dynamics):
    """Slip, travel velocity and wheel angular velocity over time.

    Speed control and towing impose the travel velocity (and the slip); a free
    sled imposes the wheel speed and travels as fast as the slip lets it, the
    slip rising from ``free_sled_start_slip_ratio`` of its steady value as the
    wheel sinks in.
    """
    if c.mode == "free_sled":
        slip = slip_ss + (dyn.free_sled_start_slip_ratio - 1.0) * slip_ss * settle
        omega = surface_speed_mps(c.velocity_set_mps, slip_ss) / radius_m * speed
        return slip, travel_speed_mps(omega * radius_m, slip), omega
    slip = np.full_like(speed, slip_ss)
    velocity = c.velocity_set_mps * speed
    return slip, velocity, surface_speed_mps(velocity, slip) / radius_m


def simulate_true_run(condition: RunCondition, law: PerformanceLaw, wheel: Wheel,
                      timeline: Timeline, dynamics: Dynamics, phase_rad: float = 0.0,
                      lateral: LateralLaw = DEFAULT_LATERAL) -> TrueRun:
    """Noise-free signals of one run on a uniform grid at ``dynamics.grid_hz``; a steered
    run also builds the side force of ``lateral`` at its slip angle."""
    c, tl, dyn = condition, timeline, dynamics
    if not np.isclose(law.radius_m, wheel.radius_m):
        raise ValueError(f"law radius {law.radius_m} m is not the wheel's {wheel.radius_m} m")
    t = np.arange(int(round(tl.duration_s * dyn.grid_hz)) + 1) / dyn.grid_hz
    slip_ss = steady_slip(c, law)
    law_ss = {k: float(v) for k, v in
              law.evaluate(c.load_set_n, slip_ss, c.multipass, c.gravity_mps2).items()}
    z_ss = law_ss["sinkage_m"]
    z_start = dyn.static_sinkage_ratio * float(
        law.evaluate(c.load_set_n, 0.0, c.multipass, c.gravity_mps2)["sinkage_m"])

    moving = t > tl.motion_start_s
    since_start = np.where(moving, t - tl.motion_start_s, 0.0)
    stop = 1.0 - _smoothstep(t, tl.decel_start_s, tl.decel_s)
    speed = _smoothstep(t, tl.motion_start_s, tl.accel_s) * stop
    shear = np.where(moving, 1.0 - np.exp(-since_start / dyn.shear_build_s), 0.0) * stop
    settle = np.exp(-since_start / (tl.settle_time_s / 5.0))

    slip, velocity, omega = _kinematics(c, slip_ss, speed, settle, wheel.radius_m, dyn)
    wheel_angle = cumulative_trapezoid(omega, t, initial=0.0)
    sled_position = cumulative_trapezoid(velocity, t, initial=0.0)

    dig_in_slip = dyn.dig_in_slip(c.load_set_n, c.multipass)
    digs_in = c.mode in SLIP_IMPOSED and slip_ss >= dig_in_slip
    dig_start_s = tl.motion_start_s + dyn.dig_delay_s
    dig_s = np.clip(np.minimum(t, tl.decel_start_s) - dig_start_s, 0.0, None)
    dig_m = dyn.dig_rate_per_s * z_ss * dig_s if digs_in else 0.0
    sinkage_base = z_ss + (z_start - z_ss) * settle + dig_m
    resistance = law_ss["resistance_n"] * sinkage_base / z_ss * shear
    thrust = resistance if c.mode == "free_sled" else law_ss["thrust_n"] * shear

    n = wheel.grouser_count
    if n > 0 and wheel.grouser_height_m > 0:
        in_contact = grousers.grousers_in_contact(z_ss, wheel.radius_m, wheel.grouser_height_m, n)
        pitch_rad = 2.0 * np.pi / n
        osc = grousers.oscillation_shape(wheel_angle + phase_rad, n, in_contact) * shear
        osc_fz = grousers.oscillation_shape(wheel_angle + phase_rad + pitch_rad / 4, n,
                                            in_contact) * shear
    else:  # a smooth rim: no grouser passing oscillation
        in_contact, osc = 0.0, np.zeros_like(t)
        osc_fz = osc
    w = c.load_set_n
    fx = thrust - resistance + dyn.dp_oscillation_ratio * w * osc
    signals = {
        "t_s": t,
        "velocity_mps": velocity,
        "omega_radps": omega,
        "wheel_angle_rad": wheel_angle,
        "sled_position_m": sled_position,
        "slip": slip,
        "fz_n": w + dyn.fz_oscillation_ratio * w * osc_fz,
        "fx_n": fx,
        "fy_n": float(lateral.side_force_n(w, c.steer_deg or 0.0)) * shear,
        "dp_trend_n": thrust - resistance,
        "dp_n": np.zeros_like(t) if c.mode == "free_sled" else fx,
        "torque_nm": (thrust + dyn.torque_oscillation_ratio * w * osc) * wheel.radius_m,
        "sinkage_m": sinkage_base
        + dyn.sinkage_oscillation_per_grouser_height * wheel.grouser_height_m * osc,
    }
    return TrueRun(condition=c, timeline=tl, steady={"slip": slip_ss, **law_ss}, digs_in=digs_in,
                   dig_in_slip=dig_in_slip, grousers_in_contact=in_contact, signals=signals)
