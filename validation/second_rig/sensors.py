"""The second rig's instruments: how the true signals become the numbers in a raw run.

Per channel, in this order: gain error (drawn within the stated calibration uncertainty),
zero offset (recorded in ``swt.zero`` from a lifted-wheel reading before the run), load-cell
drift since that zeroing (random walk plus a linear trend; the zeroing happens
``zero_lead_s`` before the run, so the rest readings at both ends of the run see it),
coloured noise (AR(1) plus 1/f), rare electrical spikes (one or two samples, either sign),
quantisation, encoder resolution, and a clock per channel (phase, rate error, jitter,
dropped samples). None of these is corrected by the rig: the files carry them.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass

import numpy as np

from validation.second_rig.condition import RunCondition
from validation.second_rig.signals import TrueRun, ar1

WRENCH_FIELDS = ("fx", "fy", "fz", "tx", "ty", "tz")


@dataclass(frozen=True)
class Rates:
    """Nominal sample rates (Hz) per spec topic; unlike the virtual testbed's."""

    wrench_hz: float = 120.0
    tether_force_hz: float = 96.0
    wheel_encoder_hz: float = 48.0
    sled_encoder_hz: float = 36.0
    tether_encoder_hz: float = 24.0
    suspension_hz: float = 30.0

    def by_topic(self) -> dict[str, float]:
        return {"/hub/wrench": self.wrench_hz, "/tether/force": self.tether_force_hz,
                "/wheel/encoder": self.wheel_encoder_hz, "/sled/encoder": self.sled_encoder_hz,
                "/tether/encoder": self.tether_encoder_hz,
                "/suspension/angle": self.suspension_hz}


@dataclass(frozen=True)
class SensorModel:
    """Sizes of every sensor effect (SI unless named otherwise)."""

    force_ar_sd_n: float = 0.25
    force_pink_sd_n: float = 0.08
    torque_ar_sd_nm: float = 0.012
    torque_pink_sd_nm: float = 0.004
    dp_ar_sd_n: float = 0.2
    dp_pink_sd_n: float = 0.06
    noise_tau_s: float = 0.08
    arm_noise_sd_rad: float = 1.2e-5
    drift_walk_n_per_sqrt_s: float = 0.04
    drift_rate_max_n_per_s: float = 0.004
    torque_drift_walk_nm_per_sqrt_s: float = 0.002
    torque_drift_rate_max_nm_per_s: float = 0.0002
    zero_lead_s: tuple[float, float] = (30.0, 180.0)
    zero_offset_max_n: float = 4.0
    fz_zero_offset_max_n: float = 20.0
    zero_offset_max_nm: float = 0.25
    zero_reading_sd_n: float = 0.02
    zero_reading_sd_nm: float = 0.001
    gain_rel_u: float = 0.003
    dp_offset_u_n: float = 0.05
    dp_raw_ratio: float = 0.5
    dp_gain_n_per_mv: tuple[float, float] = (18.0, 28.0)
    force_step_n: float = 0.02
    torque_step_nm: float = 0.002
    dp_step_n: float = 0.02
    dp_step_mv: float = 5e-4
    wheel_counts_per_rev: int = 10000
    sled_step_m: float = 1e-5
    tether_step_m: float = 2.5e-4
    tether_stiffness_n_per_m: float = 15e3
    arm_counts_per_rev: int = 65536
    arm_length_m: float = 0.55
    angle_zero_rad: tuple[float, float] = (0.05, 0.15)
    clock_ppm_max: float = 150.0
    clock_jitter_s: float = 60e-6
    clock_step_ns: int = 1000
    dropped_fraction: float = 1e-3
    spike_rate_per_s: float = 0.02
    spike_ratio: tuple[float, float] = (0.03, 0.10)
    #: write ``<topic>.<field>.gain_rel_u`` / ``.offset_u`` (raw-run spec, optional keys)
    write_calibration_uncertainty: bool = False


def pink_noise(n: int, sd: float, rng: np.random.Generator) -> np.ndarray:
    """1/f noise: white noise shaped by ``1/sqrt(f)`` in the frequency domain (Timmer &
    Koenig 1995, Astron. Astrophys. 300, 707), scaled to standard deviation ``sd``."""
    if n < 4 or sd == 0:
        return np.zeros(n)
    spectrum = np.fft.rfft(rng.normal(size=n))
    f = np.arange(spectrum.size, dtype=float)
    spectrum[0] = 0.0
    spectrum[1:] /= np.sqrt(f[1:])
    x = np.fft.irfft(spectrum, n)
    return x * (sd / x.std())


def drift(t_s: np.ndarray, lead_s: float, walk_per_sqrt_s: float, rate_per_s: float,
          rng: np.random.Generator) -> np.ndarray:
    """Drift since zeroing at ``-lead_s``: a random walk on 0.1 s knots, linearly
    interpolated, plus ``rate_per_s * (t + lead_s)``; 0 at the zeroing."""
    knots = np.arange(-lead_s, t_s.max() + 0.2, 0.1)
    walk = np.concatenate([[0.0], np.cumsum(rng.normal(0, walk_per_sqrt_s * math.sqrt(0.1),
                                                       knots.size - 1))])
    return np.interp(t_s, knots, walk) + rate_per_s * (t_s + lead_s)


def quantise(x: np.ndarray, step: float) -> np.ndarray:
    """Round to the nearest multiple of ``step`` (an ADC or a resolver)."""
    return np.round(x / step) * step


def sample_clock(rate_hz: float, duration_s: float, sensor: SensorModel,
                 rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray, dict]:
    """True sample times (>= 0) and their logged ``t_ns``: random phase, rate error, jitter,
    whole clock steps, a fraction of samples dropped (never the first or last)."""
    dt = 1.0 / rate_hz
    ppm = rng.uniform(-sensor.clock_ppm_max, sensor.clock_ppm_max)
    k = np.arange(int((duration_s - dt) * rate_hz))
    jitter = np.clip(rng.normal(0, sensor.clock_jitter_s, k.size), -0.3 * dt, 0.3 * dt)
    # the logger starts at 0: jitter cannot put the first sample before it
    t_true = np.maximum(rng.uniform(0, dt) + k * dt + jitter, 0.0)
    keep = rng.random(k.size) >= sensor.dropped_fraction
    keep[[0, -1]] = True
    t_true = t_true[keep]
    step = sensor.clock_step_ns
    t_ns = (np.round(t_true * (1 + ppm * 1e-6) * 1e9 / step) * step).astype(np.int64)
    return t_true, t_ns, {"rate_hz": rate_hz, "rate_error_ppm": ppm,
                          "samples_dropped": int((~keep).sum())}


def add_spikes(x: np.ndarray, t_s: np.ndarray, moving: tuple[float, float], scale: float,
               sensor: SensorModel, rng: np.random.Generator) -> list[dict]:
    """Electrical spikes (one or two samples, either sign) while the wheel moves; in place."""
    inside = np.flatnonzero((t_s >= moving[0]) & (t_s < moving[1]))
    spikes = []
    for _ in range(rng.poisson(sensor.spike_rate_per_s * (moving[1] - moving[0]))):
        i = int(rng.choice(inside[:-1]))
        size = float(rng.choice([-1, 1]) * rng.uniform(*sensor.spike_ratio) * scale)
        width = int(rng.integers(1, 3))
        x[i:i + width] += size
        spikes.append({"t_s": float(t_s[i]), "size": size, "samples": width})
    return spikes


def measure(condition: RunCondition, run: TrueRun, rates: Rates, sensor: SensorModel,
            duration_s: float, moving: tuple[float, float],
            rng: np.random.Generator) -> tuple[dict, dict, dict]:
    """``(topics, records, measurement)``: spec topics (``t_ns`` + fields, file units), the
    ``swt.zero`` / ``swt.calibration`` / ``swt.suspension`` records, and the truth of every
    sensor effect (offsets, gains, drift over the truth window, clocks, spikes)."""
    wheel, load = condition.wheel, condition.load_n
    lead_s = rng.uniform(*sensor.zero_lead_s)
    win = run.window
    topics, zero, calibration = {}, {}, {}
    meas = {"zero_lead_s": lead_s, "clocks": {}, "spikes": {}, "gain_error_rel": {},
            "zero_offset": {}, "drift_window_mean": {}, "drift_rest_before": {},
            "drift_rest_after": {}}
    base = run.signals
    true_of = {"fx": base["dp_n"], "fy": None, "fz": base["fz_n"], "tx": None,
               "ty": base["torque_nm"], "tz": None}

    def clock(topic: str) -> tuple[np.ndarray, np.ndarray]:
        t_true, t_ns, info = sample_clock(rates.by_topic()[topic], duration_s, sensor, rng)
        meas["clocks"][topic] = info
        return t_true, t_ns

    def gain_error() -> float:
        return float(np.clip(rng.normal(0, sensor.gain_rel_u), -2.5 * sensor.gain_rel_u,
                             2.5 * sensor.gain_rel_u))

    def load_cell(key: str, t: np.ndarray, true: np.ndarray | None, torque: bool,
                  noise: tuple[float, float]) -> np.ndarray:
        """Gain, drift, coloured noise and spikes of one cell (SI, before offset)."""
        dt = 1.0 / rates.by_topic()[key.rsplit(".", 1)[0]]
        eps = gain_error()
        x = np.zeros(t.size) if true is None else np.interp(t, run.t_s, true) * (1 + eps)
        walk = sensor.torque_drift_walk_nm_per_sqrt_s if torque else sensor.drift_walk_n_per_sqrt_s
        rate_max = (sensor.torque_drift_rate_max_nm_per_s if torque
                    else sensor.drift_rate_max_n_per_s)
        d_t = np.arange(0.0, duration_s, 0.05)
        d = drift(d_t, lead_s, walk, rng.uniform(-rate_max, rate_max), rng)
        meas["drift_window_mean"][key] = float(d[(d_t >= win[0]) & (d_t < win[1])].mean())
        meas["drift_rest_before"][key] = float(d[d_t < moving[0]].mean())
        meas["drift_rest_after"][key] = float(d[d_t >= moving[1]].mean())
        meas["gain_error_rel"][key] = eps
        x = x + np.interp(t, d_t, d) + ar1(t.size, dt, sensor.noise_tau_s, noise[0], rng)
        x += pink_noise(t.size, noise[1], rng)
        meas["spikes"][key] = add_spikes(x, t, moving, load * (wheel.radius_m if torque else 1),
                                         sensor, rng)
        return x

    t, t_ns = clock("/hub/wrench")
    wrench = {"t_ns": t_ns}
    for f in WRENCH_FIELDS:
        torque = f.startswith("t")
        noise = ((sensor.torque_ar_sd_nm, sensor.torque_pink_sd_nm) if torque
                 else (sensor.force_ar_sd_n, sensor.force_pink_sd_n))
        x = load_cell(f"/hub/wrench.{f}", t, true_of[f], torque, noise)
        limit = (sensor.zero_offset_max_nm if torque else sensor.fz_zero_offset_max_n
                 if f == "fz" else sensor.zero_offset_max_n)
        offset = rng.uniform(-limit, limit)
        meas["zero_offset"][f] = offset
        reading_sd = sensor.zero_reading_sd_nm if torque else sensor.zero_reading_sd_n
        zero[f] = float(offset + rng.normal(0, reading_sd))
        step = sensor.torque_step_nm if torque else sensor.force_step_n
        wrench[f] = quantise(x + offset, step)
        if sensor.write_calibration_uncertainty:
            calibration[f"/hub/wrench.{f}.gain_rel_u"] = sensor.gain_rel_u
    topics["/hub/wrench"] = wrench

    t, t_ns = clock("/tether/force")
    x = load_cell("/tether/force.dp", t, base["dp_n"], False, (sensor.dp_ar_sd_n,
                                                             sensor.dp_pink_sd_n))
    if rng.random() < sensor.dp_raw_ratio:
        gain = rng.uniform(*sensor.dp_gain_n_per_mv)
        electrical_zero_mv = rng.uniform(-0.1, 0.1)
        offset_error = rng.normal(0, sensor.dp_offset_u_n)
        calibration["/tether/force.dp.gain"] = gain
        calibration["/tether/force.dp.offset"] = -gain * electrical_zero_mv + offset_error
        dp_file = quantise(x / gain + electrical_zero_mv, sensor.dp_step_mv)
        meas["dp_logged_in"] = "mV"
        if sensor.write_calibration_uncertainty:
            calibration["/tether/force.dp.offset_u"] = sensor.dp_offset_u_n
    else:
        offset_error = rng.normal(0, sensor.zero_reading_sd_n)  # tared with the wrench
        dp_file = quantise(x + offset_error, sensor.dp_step_n)
        meas["dp_logged_in"] = "N"
    meas["dp_offset_error_n"] = float(offset_error)
    if sensor.write_calibration_uncertainty:
        calibration["/tether/force.dp.gain_rel_u"] = sensor.gain_rel_u
    topics["/tether/force"] = {"t_ns": t_ns, "dp": dp_file}

    t, t_ns = clock("/wheel/encoder")
    step = 2 * math.pi / sensor.wheel_counts_per_rev
    topics["/wheel/encoder"] = {"t_ns": t_ns, "angle": np.floor(
        np.interp(t, run.t_s, base["wheel_angle_rad"]) / step) * step}
    sled_start_m = rng.uniform(0.1, 0.5)
    t, t_ns = clock("/sled/encoder")
    sled = np.interp(t, run.t_s, base["sled_position_m"]) + sled_start_m
    topics["/sled/encoder"] = {"t_ns": t_ns, "position": np.floor(sled / sensor.sled_step_m)
                               * sensor.sled_step_m}
    if condition.mode != "free_sled":
        t, t_ns = clock("/tether/encoder")
        tether = (np.interp(t, run.t_s, base["sled_position_m"]) + rng.uniform(0.0, 0.2)
                  + np.interp(t, run.t_s, base["dp_n"]) / sensor.tether_stiffness_n_per_m)
        topics["/tether/encoder"] = {"t_ns": t_ns, "position": quantise(tether,
                                                                         sensor.tether_step_m)}

    angle_zero = rng.uniform(*sensor.angle_zero_rad)
    t, t_ns = clock("/suspension/angle")
    hub_m = -np.interp(t, run.t_s, base["sinkage_m"])
    if wheel.stiffness_n_per_mm is not None:
        hub_m -= np.interp(t, run.t_s, base["fz_n"]) / (1000 * wheel.stiffness_n_per_mm)
    angle = np.arcsin(math.sin(angle_zero) + hub_m / sensor.arm_length_m)
    angle += ar1(t.size, 1 / rates.suspension_hz, sensor.noise_tau_s, sensor.arm_noise_sd_rad,
                 rng)
    topics["/suspension/angle"] = {"t_ns": t_ns, "angle": quantise(
        angle, 2 * math.pi / sensor.arm_counts_per_rev)}

    records = {"zero": zero, "suspension": {"arm_length_m": sensor.arm_length_m,
                                            "angle_zero_rad": angle_zero}}
    if calibration:
        records["calibration"] = calibration
    meas["sensor_model"] = asdict(sensor)
    meas["rates_hz"] = rates.by_topic()
    return topics, records, meas
