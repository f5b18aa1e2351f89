"""Window statistics from the native stream samples rather than the common time base.

Ingest puts every stream on one uniform grid by linear interpolation. Between two samples
of a waveform with a sharp edge (the grouser load builds up, then drops as a grouser
leaves the soil) the interpolated line adds about ``drop * dt / 2`` per period: a bias of
the mean of ``drop * dt / (2 T)`` (tens of um of hub height for a 10 Hz arm encoder at
0.5 Hz grouser passing), and residuals the harmonic model cannot follow, which inflate the
SE. So the single-channel quantities (wheel load, drawbar pull, torque, thrust, side force,
hub height) are computed from the native samples. Combinations of channels logged at
different instants (``R = T/r - DP``, the flexible wheel's sinkage ``-h - fz/(1000 k)``)
take their mean from the channels' native means (they are linear) and their spread and SE
from the common-grid series, where the channels line up in time.

Samples lost in a gap would take part of a grouser period out of the window and bias a
plain mean by up to the oscillation amplitude times the share lost, so with grousers the
mean is the mean of the phase-averaged waveform (``phase_average``), which weights every
phase equally whichever samples are missing.
Left over: a slow sensor sampling nearly commensurate with the grouser period sees the same
few phases of a sharp-edged waveform in every period; the resulting quadrature error (up to
``drop / (2 * samples per period)``) is constant over the window and not in the SE.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from run_results.phase_average import phase_average
from run_results.stats import QuantityStats, quantity_stats

#: fewer native samples than this per phase bin: plain mean instead of the phase average
MIN_SAMPLES_PER_BIN = 4
#: quantity -> (canonical column, divide by the wheel radius?)
SINGLE_CHANNEL = {"wheel_load_n": ("fz_n", False), "dp_n": ("dp_n", False),
                  "torque_nm": ("ty_nm", False), "thrust_n": ("ty_nm", True),
                  "side_force_n": ("fy_n", False)}


def channel_samples(run, column: str, start_s: float, end_s: float):
    """``(t_s, values)`` of ``column``'s native samples from ``start_s`` to ``end_s``
    (inclusive, finite values only), or None. The stream's ``t_s`` ascend (ingest refuses
    others), so the window is one slice found by bisection."""
    for frame in run.streams.values():
        if column in frame.columns:
            t, y = frame["t_s"].to_numpy(), frame[column].to_numpy()
            lo, hi = np.searchsorted(t, start_s, "left"), np.searchsorted(t, end_s, "right")
            t, y = (t[lo:hi], y[lo:hi]) if start_s <= end_s else (t[:0], y[:0])  # NaN: none
            finite = np.isfinite(y)
            return (t, y) if finite.all() else (t[finite], y[finite])
    return None


def hub_samples(run, start_s: float, end_s: float):
    """A logged hub height, or the arm angle through ``L (sin(angle) - sin(angle_zero))``."""
    direct = channel_samples(run, "hub_height_m", start_s, end_s)
    angle = channel_samples(run, "suspension_angle_rad", start_s, end_s)
    if direct is not None or angle is None or run.metadata.suspension is None:
        return direct
    s = run.metadata.suspension
    return angle[0], s.arm_length_m * (np.sin(angle[1]) - np.sin(s.angle_zero_rad))


def native_stats(t_s: np.ndarray, y: np.ndarray, frequency_hz: float | None,
                 unit: str) -> QuantityStats | None:
    """Stats of native samples: mean of the phase-averaged waveform (plain mean without
    grousers or with too few samples), SE from the residual about the waveform."""
    if y.size < 2:
        return None
    if frequency_hz:
        average = phase_average(t_s, y, frequency_hz)
        if y.size >= MIN_SAMPLES_PER_BIN * average["bins"]:
            return quantity_stats(y, unit, average)
    return quantity_stats(y, unit)


def native_quantities(run, start_s: float, end_s: float, units: dict[str, str],
                      frequency_hz: float | None = None,
                      rig=None) -> tuple[dict[str, QuantityStats], dict[str, float]]:
    """``(stats, combined_means)``: full stats of the single-channel quantities, and the
    means of resistance and sinkage combined from the channels' native means."""
    radius = run.metadata.wheel.radius_m
    stats = {}
    for key, (column, per_radius) in SINGLE_CHANNEL.items():
        samples = channel_samples(run, column, start_s, end_s)
        if key in units and samples is not None:
            t, y = samples
            result = native_stats(t, y / radius if per_radius else y, frequency_hz, units[key])
            if result is not None:
                stats[key] = result
    hub = hub_samples(run, start_s, end_s)
    if hub is not None and (rig is None or rig.kind == "linear"):
        result = native_stats(*hub, frequency_hz, units["hub_height_m"])
        if result is not None:
            load = (stats["wheel_load_n"].mean if "wheel_load_n" in stats
                    else run.metadata.run.condition.load_set_n)
            shift = 0.0 if rig is None else float(rig.correction(load))
            stats["hub_height_m"] = replace(result, mean=result.mean + shift)
    means = {}
    if "thrust_n" in stats and "dp_n" in stats:
        means["resistance_n"] = stats["thrust_n"].mean - stats["dp_n"].mean
    if "hub_height_m" in stats:
        stiffness = run.metadata.wheel.stiffness_n_per_mm
        if stiffness is None:
            means["sinkage_m"] = -stats["hub_height_m"].mean
        elif "wheel_load_n" in stats:
            means["sinkage_m"] = (-stats["hub_height_m"].mean
                                  - stats["wheel_load_n"].mean / (1000.0 * stiffness))
    return stats, means
