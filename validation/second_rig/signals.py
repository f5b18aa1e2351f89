"""The second rig's noise-free run: what the wheel really does, sample by sample.

Deliberately unlike the virtual testbed's signal model:

- start-up transients are **second-order underdamped** step responses (drawbar pull, torque,
  speeds; they overshoot and ring) and a **ramp-and-overshoot** for sinkage (linear rise past
  the steady value, Gaussian decay back), with the damping drawn per run;
- the grouser load is a **shark-fin** wave (``1 - exp(-u/a)`` rise, sharp release), each
  grouser's passage shifted by a fixed per-grouser offset plus a random per-passage jitter,
  so the period wanders and the wave is not a sum of a few fixed harmonics;
- the drives' speeds carry a slow AR(1) ripple (the true kinematics, not sensor noise).

The truth window opens when every transient envelope is below 1e-4 of its step and closes
at the deceleration, cut to whole nominal grouser periods.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass

import numpy as np
from scipy.signal import lfilter

from validation.second_rig.condition import RunCondition, SecondRigError

#: the envelope of every start-up transient is this fraction of its step at ``settle_s``
SETTLED_FRACTION = 1e-4


@dataclass(frozen=True)
class Timeline:
    """Phases of a run (s): rest, speed ramp (settles in ``ramp_s``), force and sinkage
    transients (down to :data:`SETTLED_FRACTION` ``settle_s`` after motion starts, to 2 % at
    about 0.42 ``settle_s``), steady running, deceleration, rest."""

    duration_s: float = 52.0
    rest_before_s: float = 3.0
    ramp_s: float = 2.5
    settle_s: float = 24.0
    decel_s: float = 1.5
    rest_after_s: float = 3.0
    base_dt_s: float = 0.002

    @property
    def motion_start_s(self) -> float:
        return self.rest_before_s

    @property
    def decel_start_s(self) -> float:
        return self.duration_s - self.rest_after_s - self.decel_s

    def check(self) -> None:
        steady_s = self.decel_start_s - self.motion_start_s - self.settle_s
        if self.ramp_s > self.settle_s or steady_s < 5.0 or min(asdict(self).values()) <= 0:
            raise SecondRigError(f"timeline leaves {steady_s:.1f} s steady (needs >= 5 s, "
                                 f"ramp_s <= settle_s, all > 0): {asdict(self)}")


@dataclass(frozen=True)
class SignalModel:
    """Shapes and sizes of the true signals (ratios of the load W, W r, grouser height)."""

    force_damping: tuple[float, float] = (0.3, 0.6)
    speed_damping: float = 0.65
    static_sinkage_ratio: tuple[float, float] = (0.6, 0.8)
    sinkage_overshoot: tuple[float, float] = (0.05, 0.2)
    sinkage_ramp_fraction: float = 0.3
    load_bump_ratio: float = 0.03
    speed_ripple_rel: float = 1e-3
    speed_ripple_tau_s: float = 0.7
    dp_grouser_rms_ratio: tuple[float, float] = (0.02, 0.04)
    torque_grouser_rms_ratio: tuple[float, float] = (0.02, 0.04)
    fz_grouser_rms_ratio: float = 0.015
    sinkage_grouser_rms_ratio: float = 0.05
    fin_decay: float = 0.3
    grouser_offset_sd: float = 0.04
    passage_jitter_sd: float = 0.02


@dataclass
class TrueRun:
    """Noise-free signals on the base grid ``t_s`` (SI), the truth window and the drawn
    shape parameters."""

    t_s: np.ndarray
    signals: dict[str, np.ndarray]
    window: tuple[float, float]
    parameters: dict


def step_response(tau_s: np.ndarray, zeta: float, settle_s: float) -> np.ndarray:
    """Unit step response of a second-order system, ``zeta`` < 1, whose envelope
    ``exp(-zeta wn t)`` falls to :data:`SETTLED_FRACTION` at ``settle_s`` (Ogata 2010,
    Modern Control Engineering, 5th ed., eq. 5-15); 0 before the step."""
    sigma = math.log(1 / SETTLED_FRACTION) / settle_s
    wd = sigma / zeta * math.sqrt(1 - zeta**2)
    tau = np.maximum(tau_s, 0.0)
    y = 1 - np.exp(-sigma * tau) * (np.cos(wd * tau) + sigma / wd * np.sin(wd * tau))
    return np.where(tau_s > 0, y, 0.0)


def impulse_shape(tau_s: np.ndarray, zeta: float, settle_s: float) -> np.ndarray:
    """``exp(-sigma t) sin(wd t)`` (the same system's ringing), 0 before the step."""
    sigma = math.log(1 / SETTLED_FRACTION) / settle_s
    wd = sigma / zeta * math.sqrt(1 - zeta**2)
    tau = np.maximum(tau_s, 0.0)
    return np.exp(-sigma * tau) * np.sin(wd * tau)


def ramp_overshoot(tau_s: np.ndarray, overshoot: float, ramp_end_s: float,
                   settle_s: float) -> np.ndarray:
    """0 -> 1: linear rise to ``1 + overshoot`` at ``ramp_end_s``, then a Gaussian decay to 1
    that is down to :data:`SETTLED_FRACTION` of the overshoot at ``settle_s``."""
    width = (settle_s - ramp_end_s) / math.sqrt(math.log(1 / SETTLED_FRACTION))
    tau = np.maximum(tau_s, 0.0)
    rise = (1 + overshoot) * tau / ramp_end_s
    decay = 1 + overshoot * np.exp(-(((tau - ramp_end_s) / width) ** 2))
    return np.where(tau < ramp_end_s, rise, decay)


def stop_factor(t_s: np.ndarray, timeline: Timeline) -> np.ndarray:
    """1 until the deceleration, smoothstep down to 0 over ``decel_s``."""
    x = np.clip((t_s - timeline.decel_start_s) / timeline.decel_s, 0.0, 1.0)
    return 1 - x * x * (3 - 2 * x)


def ar1(n: int, dt_s: float, tau_s: float, sd: float, rng: np.random.Generator) -> np.ndarray:
    """Stationary AR(1) sequence (discretised Ornstein-Uhlenbeck), correlation time ``tau_s``."""
    phi = math.exp(-dt_s / tau_s)
    shocks = rng.normal(0.0, sd * math.sqrt(1 - phi**2), n)
    shocks[0] = rng.normal(0.0, sd)
    return lfilter([1.0], [1.0, -phi], shocks)


def fin_wave(u: np.ndarray, decay: float) -> np.ndarray:
    """Shark-fin grouser wave over one pitch ``u`` in [0, 1): ``1 - exp(-u/decay)``, shifted
    and scaled to zero mean and unit RMS over the pitch (closed form)."""
    e1 = math.exp(-1 / decay)
    mean = 1 - decay * (1 - e1)
    mean_sq = 1 - 2 * decay * (1 - e1) + decay / 2 * (1 - e1**2)
    return (1 - np.exp(-u / decay) - mean) / math.sqrt(mean_sq - mean**2)


def grouser_phase(passages: np.ndarray, grouser_count: int, model: SignalModel,
                  rng: np.random.Generator) -> np.ndarray:
    """Phase ``u`` in [0, 1) within the current grouser pitch, from the continuous passage
    count ``n theta / 2 pi``: pitch boundaries at ``j + offset[j mod n] + jitter_j``."""
    j_max = int(np.ceil(passages.max())) + 3
    j = np.arange(-2, j_max)
    offsets = np.clip(rng.normal(0, model.grouser_offset_sd, grouser_count), -0.2, 0.2)
    jitter = np.clip(rng.normal(0, model.passage_jitter_sd, j.size), -0.2, 0.2)
    bounds = j + offsets[j % grouser_count] + jitter
    k = np.searchsorted(bounds, passages, side="right") - 1
    return (passages - bounds[k]) / (bounds[k + 1] - bounds[k])


def true_run(condition: RunCondition, steady: dict[str, float], timeline: Timeline,
             model: SignalModel, rng: np.random.Generator) -> TrueRun:
    """The noise-free signals of one run: ``v_mps``, ``omega_radps``, ``wheel_angle_rad``,
    ``sled_position_m``, ``dp_n``, ``torque_nm``, ``fz_n``, ``sinkage_m``."""
    timeline.check()
    wheel = condition.wheel
    t = np.arange(0.0, timeline.duration_s, timeline.base_dt_s)
    tau = t - timeline.motion_start_s
    stop = stop_factor(t, timeline)
    speed = step_response(tau, model.speed_damping, timeline.ramp_s) * stop
    ripple = [1 + ar1(t.size, timeline.base_dt_s, model.speed_ripple_tau_s,
                      model.speed_ripple_rel, rng) for _ in range(2)]
    v = steady["travel_velocity_mps"] * speed * ripple[0]
    omega = steady["wheel_omega_radps"] * speed * ripple[1]
    dt = timeline.base_dt_s
    sled = np.concatenate([[0.0], np.cumsum((v[1:] + v[:-1]) / 2 * dt)])
    angle = np.concatenate([[0.0], np.cumsum((omega[1:] + omega[:-1]) / 2 * dt)])

    draw = {"dp_damping": rng.uniform(*model.force_damping),
            "torque_damping": rng.uniform(*model.force_damping),
            "load_damping": rng.uniform(*model.force_damping),
            "static_sinkage_ratio": rng.uniform(*model.static_sinkage_ratio),
            "sinkage_overshoot": rng.uniform(*model.sinkage_overshoot),
            "dp_grouser_rms_ratio": rng.uniform(*model.dp_grouser_rms_ratio),
            "torque_grouser_rms_ratio": rng.uniform(*model.torque_grouser_rms_ratio),
            "grouser_start_phase": rng.uniform(0, 1)}
    settle = timeline.settle_s
    load = steady["wheel_load_n"]
    dp = steady["dp_n"] * step_response(tau, draw["dp_damping"], settle) * stop
    torque = steady["torque_nm"] * step_response(tau, draw["torque_damping"], settle) * stop
    fz = load * (1 + model.load_bump_ratio * impulse_shape(tau, draw["load_damping"], settle))
    z_static = draw["static_sinkage_ratio"] * steady["sinkage_m"]
    sinkage = z_static + (steady["sinkage_m"] - z_static) * ramp_overshoot(
        tau, draw["sinkage_overshoot"], model.sinkage_ramp_fraction * settle, settle)

    n = wheel.grouser_count
    if n > 0:
        passages = n * angle / (2 * math.pi) + draw["grouser_start_phase"]
        u = grouser_phase(passages, n, model, rng)
        moving = np.clip(speed, 0.0, 1.0)
        wave = fin_wave(u, model.fin_decay) * moving
        quarter = fin_wave((u + 0.25) % 1.0, model.fin_decay) * moving
        half = fin_wave((u + 0.5) % 1.0, model.fin_decay) * moving
        if condition.mode != "free_sled":
            dp = dp + draw["dp_grouser_rms_ratio"] * load * wave
        torque = torque + draw["torque_grouser_rms_ratio"] * load * wheel.radius_m * wave
        fz = fz + model.fz_grouser_rms_ratio * load * quarter
        sinkage = sinkage - model.sinkage_grouser_rms_ratio * wheel.grouser_height_m * half
    sinkage = np.maximum(sinkage, 0.0)

    start = timeline.motion_start_s + settle
    end = timeline.decel_start_s
    if n > 0:
        period = 2 * math.pi / (n * steady["wheel_omega_radps"])
        if end - start >= period:
            end = start + math.floor((end - start) / period) * period
    signals = {"v_mps": v, "omega_radps": omega, "wheel_angle_rad": angle,
               "sled_position_m": sled, "dp_n": dp, "torque_nm": torque, "fz_n": fz,
               "sinkage_m": sinkage}
    return TrueRun(t_s=t, signals=signals, window=(start, end), parameters=draw)


def window_means(run: TrueRun, radius_m: float) -> dict[str, float]:
    """Means of the noise-free signals over the truth window, in ``swtlab results`` names;
    slip is the mean of the instantaneous spec slip."""
    start, end = run.window
    inside = (run.t_s >= start) & (run.t_s < end)
    s = {k: v[inside] for k, v in run.signals.items()}
    surface = radius_m * s["omega_radps"]
    slip = np.where(surface >= s["v_mps"], (surface - s["v_mps"]) / surface,
                    (surface - s["v_mps"]) / s["v_mps"])
    thrust = s["torque_nm"] / radius_m
    return {"slip": float(slip.mean()), "travel_velocity_mps": float(s["v_mps"].mean()),
            "wheel_omega_radps": float(s["omega_radps"].mean()),
            "wheel_load_n": float(s["fz_n"].mean()), "dp_n": float(s["dp_n"].mean()),
            "torque_nm": float(s["torque_nm"].mean()), "thrust_n": float(thrust.mean()),
            "resistance_n": float((thrust - s["dp_n"]).mean()),
            "sinkage_m": float(s["sinkage_m"].mean())}
