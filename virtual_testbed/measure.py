"""Turn a noise-free run into the raw channels a real SWT logger would write."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from virtual_testbed import sensors as sn
from virtual_testbed.rig import Suspension, Wheel
from virtual_testbed.simulate import TrueRun
from virtual_testbed.topics import TOPIC_FIELDS


@dataclass(frozen=True)
class RawRun:
    """A run as written to disk: metadata records, channels (with ``t_ns``) and message blocks.

    ``metadata`` maps record names without ``swt.`` (``run``, ``wheel``, ...) to
    typed values; the MCAP writer turns them into strings, the CSV writer into JSON.
    """

    run_id: str
    metadata: dict[str, dict[str, float | int | str]]
    channels: dict[str, dict[str, np.ndarray]]
    blocks: dict[str, np.ndarray]
    #: encoded camera frames per topic (``virtual_testbed.track_photos.TrackPhoto``)
    images: dict[str, list] = field(default_factory=dict)


@dataclass(frozen=True)
class Measurement:
    """The raw run plus what the sensors did to it (for the truth file)."""

    raw: RawRun
    record: dict


def suspension_angle_rad(sinkage_m, fz_n, wheel: Wheel, suspension: Suspension) -> np.ndarray:
    """Arm angle giving this sinkage (spec: ``z = -h`` rigid, ``z = -h - fz/(1000 k)`` flexible)."""
    hub_height_m = -np.asarray(sinkage_m, float)
    if wheel.stiffness_n_per_mm:
        hub_height_m = hub_height_m - np.asarray(fz_n, float) / (1000.0 * wheel.stiffness_n_per_mm)
    return np.arcsin(np.sin(suspension.angle_zero_rad) + hub_height_m / suspension.arm_length_m)


def _zero_offsets(rng: np.random.Generator, s: sn.SensorModel) -> dict[str, float]:
    scale = {"fx": s.zero_force_n, "fy": s.zero_force_n, "fz": s.zero_fz_n,
             "tx": s.zero_torque_nm, "ty": s.zero_torque_nm, "tz": s.zero_torque_nm}
    return {k: round(float(rng.uniform(-v, v)), 3) for k, v in scale.items()}


def _dp_calibration(rng: np.random.Generator, s: sn.SensorModel) -> dict[str, float]:
    """Some runs log the DP load cell in raw mV: SI = gain * raw + offset (``swt.calibration``)."""
    if rng.random() >= s.dp_in_millivolt_ratio:
        return {}
    return {"/tether/force.dp.gain": round(float(rng.uniform(20.0, 30.0)), 4),
            "/tether/force.dp.offset": round(float(rng.uniform(-3.0, 3.0)), 3)}


@dataclass(frozen=True)
class _Sensing:
    """What every channel needs to turn true signals into readings."""

    true_run: TrueRun
    wheel: Wheel
    suspension: Suspension
    sensors: sn.SensorModel
    rng: np.random.Generator
    zero: dict[str, float]
    calibration: dict[str, float]
    spikes: sn.GravelSpikes

    def true_at(self, t_s, key: str) -> np.ndarray:
        return np.interp(t_s, self.true_run.signals["t_s"], self.true_run.signals[key])

    def noisy(self, t_s, value, noise: float, drift: float) -> np.ndarray:
        duration_s = self.true_run.timeline.duration_s
        return (value + self.rng.normal(0.0, noise, t_s.size)
                + sn.slow_drift(t_s, duration_s, drift, self.rng, self.sensors))


def _wrench(ctx: _Sensing, t):
    s, zero, spikes = ctx.sensors, ctx.zero, ctx.spikes
    true = {"fx": ctx.true_at(t, "fx_n") + spikes.at(t, "fx_n"), "fy": ctx.true_at(t, "fy_n"),
            "fz": ctx.true_at(t, "fz_n") + spikes.at(t, "fz_n"), "tx": 0.0,
            "ty": ctx.true_at(t, "torque_nm") + spikes.at(t, "ty_nm"), "tz": 0.0}
    out = {}
    for axis, value in true.items():  # six axes
        force = axis.startswith("f")
        noise, drift, step = ((s.force_noise_n, s.force_drift_n, s.force_resolution_n) if force else
                              (s.torque_noise_nm, s.torque_drift_nm, s.torque_resolution_nm))
        out[axis] = sn.quantise(ctx.noisy(t, value + zero[axis], noise, drift), step)
    return out


def _tether_force(ctx: _Sensing, t):
    s, tethered = ctx.sensors, ctx.true_run.condition.mode != "free_sled"
    dp = ctx.true_at(t, "dp_n") + (ctx.spikes.at(t, "fx_n") if tethered else 0.0)
    dp = ctx.noisy(t, dp, s.dp_noise_n, s.force_drift_n)
    if ctx.calibration:
        gain = ctx.calibration["/tether/force.dp.gain"]
        offset = ctx.calibration["/tether/force.dp.offset"]
        return {"dp": sn.quantise((dp - offset) / gain, s.dp_raw_resolution_mv)}
    return {"dp": sn.quantise(dp, s.dp_resolution_n)}


def _wheel_encoder(ctx: _Sensing, t):
    step = 2.0 * np.pi / ctx.sensors.wheel_counts_per_rev
    return {"angle": sn.quantise(np.floor(ctx.true_at(t, "wheel_angle_rad") / step) * step, step)}


def _sled_encoder(ctx: _Sensing, t):
    step = ctx.sensors.sled_resolution_m
    position_m = np.floor(ctx.true_at(t, "sled_position_m") / step) * step
    return {"position": sn.quantise(position_m, step)}


def _tether_encoder(ctx: _Sensing, t):
    """Draw-wire on the tether: sled position plus the tether's stretch under DP."""
    stretch_m = ctx.true_at(t, "dp_n") / ctx.sensors.tether_stiffness_n_per_m
    return {"position": sn.quantise(ctx.true_at(t, "sled_position_m") + stretch_m,
                                    ctx.sensors.tether_resolution_m)}


def _suspension_encoder(ctx: _Sensing, t):
    s = ctx.sensors
    angle = suspension_angle_rad(ctx.true_at(t, "sinkage_m"), ctx.true_at(t, "fz_n"), ctx.wheel,
                                 ctx.suspension)
    return {"angle": sn.quantise(angle + ctx.rng.normal(0.0, s.suspension_noise_rad, t.size),
                                 2.0 * np.pi / s.suspension_counts_per_rev)}


_CHANNELS = {"/hub/wrench": _wrench, "/tether/force": _tether_force,
             "/wheel/encoder": _wheel_encoder, "/sled/encoder": _sled_encoder,
             "/tether/encoder": _tether_encoder, "/suspension/angle": _suspension_encoder}


def measure(true_run: TrueRun, wheel: Wheel, suspension: Suspension, rates: sn.Rates,
            sensors: sn.SensorModel, rng: np.random.Generator,
            metadata: dict[str, dict]) -> Measurement:
    """Sample the true signals at each channel's own clock and add the sensor imperfections.

    A free sled has no tether, so no ``/tether/encoder`` (its DP load cell reads zero).
    """
    tl, c = true_run.timeline, true_run.condition
    ctx = _Sensing(true_run, wheel, suspension, sensors, rng, zero=_zero_offsets(rng, sensors),
                   calibration=_dp_calibration(rng, sensors),
                   spikes=sn.gravel_spikes(tl.motion_start_s, tl.decel_start_s, c.load_set_n,
                                           wheel.radius_m, rng, sensors))
    topics = [t for t in _CHANNELS if not (t == "/tether/encoder" and c.mode == "free_sled")]
    channels, blocks, clocks = {}, {}, {}
    for topic in topics:  # one iteration per channel, vectorised inside
        rate_hz = rates.by_topic()[topic]
        n = int(tl.duration_s * rate_hz)
        t_true_s, t_ns, ppm = sn.clock(n, rate_hz, rng, sensors)
        keep = sn.kept_samples(n, rate_hz, rng, sensors)
        fields = _CHANNELS[topic](ctx, t_true_s[keep])
        channels[topic] = {"t_ns": t_ns[keep], **{k: fields[k] for k in TOPIC_FIELDS[topic]}}
        blocks[topic] = sn.block_sizes(int(keep.sum()), rate_hz, rng, sensors)
        clocks[topic] = {"rate_hz": rate_hz, "rate_error_ppm": round(float(ppm), 3),
                         "samples_nominal": n, "samples_dropped": int(n - keep.sum())}

    metadata = {**metadata, "zero": ctx.zero}
    if ctx.calibration:
        metadata["calibration"] = ctx.calibration
    spikes = ctx.spikes
    record = {
        "zero": ctx.zero,
        "calibration": ctx.calibration,
        "clocks": clocks,
        "gravel_spikes": {"t_s": np.round(spikes.t_s, 3).tolist(),
                          "fz_n": np.round(spikes.fz_n, 2).tolist(),
                          "fx_n": np.round(spikes.fx_n, 2).tolist(),
                          "tau_s": spikes.tau_s},
    }
    raw = RawRun(run_id=c.run_id, metadata=metadata, channels=channels, blocks=blocks)
    return Measurement(raw=raw, record=record)
