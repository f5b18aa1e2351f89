"""Sensor and logger imperfections: noise, drift, quantisation, gravel spikes,
dropped samples and uneven clocks. Pure functions of an ``np.random.Generator``."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class Rates:
    """Nominal sample rates per topic (Hz)."""

    wrench_hz: float = 100.0
    dp_hz: float = 100.0
    wheel_encoder_hz: float = 50.0
    sled_encoder_hz: float = 50.0
    tether_encoder_hz: float = 25.0
    suspension_hz: float = 25.0

    def by_topic(self) -> dict[str, float]:
        return {
            "/hub/wrench": self.wrench_hz,
            "/tether/force": self.dp_hz,
            "/wheel/encoder": self.wheel_encoder_hz,
            "/sled/encoder": self.sled_encoder_hz,
            "/tether/encoder": self.tether_encoder_hz,
            "/suspension/angle": self.suspension_hz,
        }


@dataclass(frozen=True)
class SensorModel:
    """Noise levels, resolutions and logger behaviour (SI units in the names)."""

    force_noise_n: float = 0.4
    torque_noise_nm: float = 0.02
    dp_noise_n: float = 0.3
    suspension_noise_rad: float = 2e-5
    force_resolution_n: float = 0.1
    dp_resolution_n: float = 0.05
    torque_resolution_nm: float = 0.01
    dp_raw_resolution_mv: float = 1e-3
    wheel_counts_per_rev: int = 16384
    sled_resolution_m: float = 5e-6
    tether_resolution_m: float = 1e-4
    tether_stiffness_n_per_m: float = 20000.0
    suspension_counts_per_rev: int = 2**17
    force_drift_n: float = 0.5
    torque_drift_nm: float = 0.02
    drift_knot_s: float = 10.0
    zero_force_n: float = 5.0
    zero_fz_n: float = 15.0
    zero_torque_nm: float = 0.3
    spike_rate_hz: float = 0.03
    spike_tau_s: float = 0.03
    spike_fz_ratio: tuple[float, float] = (0.05, 0.2)
    spike_fx_ratio: tuple[float, float] = (0.02, 0.1)
    dropped_fraction: float = 0.002
    gaps_per_channel: float = 1.0
    gap_max_s: float = 0.5
    clock_rate_error_ppm: float = 200.0
    clock_jitter_s: float = 5e-5
    clock_resolution_ns: int = 10000
    block_mean_s: float = 1.0
    single_sample_block_ratio: float = 0.05
    dp_in_millivolt_ratio: float = 0.3


def quantise(x, step: float) -> np.ndarray:
    """Round to the sensor's step, then to two digits below it so the written text stays short."""
    decimals = int(-np.floor(np.log10(step))) + 2
    return np.round(np.round(np.asarray(x, float) / step) * step, decimals) + 0.0  # no -0.0


def clock(n: int, rate_hz: float, rng: np.random.Generator, sensors: SensorModel):
    """True sample times and the logger's timestamps (ns) for a channel of ``n`` samples.

    The channel's clock runs with a small rate error and jitters by
    ``clock_jitter_s``; timestamps are whole multiples of ``clock_resolution_ns``.
    """
    period_s = 1.0 / rate_hz
    if sensors.clock_resolution_ns * 1e-9 > period_s / 4:
        raise ValueError(f"clock resolution {sensors.clock_resolution_ns} ns too coarse "
                         f"for {rate_hz} Hz")
    jitter = np.clip(rng.normal(0.0, sensors.clock_jitter_s, n), -0.25 * period_s, 0.25 * period_s)
    t_true_s = (np.arange(n) + rng.uniform(0.25, 0.75)) * period_s + jitter
    rate_error_ppm = rng.uniform(-1.0, 1.0) * sensors.clock_rate_error_ppm
    ticks = np.round(t_true_s * (1.0 + rate_error_ppm * 1e-6) * 1e9 / sensors.clock_resolution_ns)
    return t_true_s, ticks.astype(np.int64) * sensors.clock_resolution_ns, rate_error_ppm


def kept_samples(n: int, rate_hz: float, rng: np.random.Generator,
                 sensors: SensorModel) -> np.ndarray:
    """Mask of samples that reach the file: random single drops plus a few gaps."""
    keep = rng.random(n) >= sensors.dropped_fraction
    starts = rng.integers(0, max(n, 1), rng.poisson(sensors.gaps_per_channel))
    ends = starts + rng.integers(1, max(2, int(sensors.gap_max_s * rate_hz)), starts.size)
    idx = np.arange(n)[None, :]
    in_gap = ((idx >= starts[:, None]) & (idx < ends[:, None])).any(axis=0)
    return keep & ~in_gap


def slow_drift(t_s, duration_s: float, amplitude: float, rng: np.random.Generator,
               sensors: SensorModel) -> np.ndarray:
    """Thermal-like drift since zeroing: a random walk through knots every ``drift_knot_s``."""
    knots_s = np.arange(0.0, duration_s + sensors.drift_knot_s, sensors.drift_knot_s)
    walk = np.concatenate([[0.0], np.cumsum(rng.normal(0.0, 1.0, knots_s.size - 1))])
    return np.interp(t_s, knots_s, amplitude * walk / np.sqrt(knots_s.size))


@dataclass(frozen=True)
class GravelSpikes:
    """Short load events as the wheel rolls over gravel (times and peak amplitudes)."""

    t_s: np.ndarray
    fz_n: np.ndarray
    fx_n: np.ndarray
    ty_nm: np.ndarray
    tau_s: float

    def at(self, t_s, key: str) -> np.ndarray:
        dt = np.asarray(t_s, float)[None, :] - self.t_s[:, None]
        pulse = np.where(dt >= 0, np.exp(-np.clip(dt, 0.0, None) / self.tau_s), 0.0)
        return (getattr(self, key)[:, None] * pulse).sum(axis=0)


def gravel_spikes(start_s: float, end_s: float, load_n: float, radius_m: float,
                  rng: np.random.Generator, sensors: SensorModel) -> GravelSpikes:
    """Poisson gravel events while the wheel moves: load up, DP down, torque up."""
    count = rng.poisson(sensors.spike_rate_hz * (end_s - start_s))
    t = np.sort(rng.uniform(start_s, end_s, count))
    fx = -rng.uniform(*sensors.spike_fx_ratio, count) * load_n
    return GravelSpikes(t_s=t, fz_n=rng.uniform(*sensors.spike_fz_ratio, count) * load_n,
                        fx_n=fx, ty_nm=-fx * radius_m, tau_s=sensors.spike_tau_s)


def block_sizes(n: int, rate_hz: float, rng: np.random.Generator,
                sensors: SensorModel) -> np.ndarray:
    """Sizes of the logger's message blocks: around ``block_mean_s``, some of one sample."""
    mean = max(2, int(sensors.block_mean_s * rate_hz))
    sizes = rng.integers(1, 2 * mean, n + 1)
    sizes[rng.random(sizes.size) < sensors.single_sample_block_ratio] = 1
    total = np.cumsum(sizes)
    count = int(np.searchsorted(total, n)) + 1
    sizes = sizes[:count]
    sizes[-1] -= total[count - 1] - n
    return sizes[sizes > 0]
