"""Speed gate: keep the samples where the measured wheel and sled speeds hold their set points.

Set points by test mode (raw-run spec):

- speed control / steered: travel velocity ``v = velocity_mps`` and wheel surface speed
  ``r*omega = v/(1-s)`` (driving) or ``v*(1+s)`` (skid), or the logged
  ``wheel_surface_speed_setpoint_mps`` where a rig imposes that;
- free sled: the wheel speed is imposed but not recorded as a set point, and the sled
  travels as fast as the slip lets it: both references are the plateau medians;
- towed: ``v = velocity_mps``; the unpowered wheel's speed is its plateau median.

Speeds are smoothed over ``gate_smooth_s``; a sample passes when every speed lies within
``max(gate_rel_tol * scale, gate_sigmas * sigma)`` of its reference (scale: the larger
reference speed; sigma: robust spread of the smoothed speed about it). A speed whose plateau
misses its set point by more than the tolerance (a rig that ran at another speed than its
file says) is held to its plateau instead, and the mismatch is reported. Dropouts shorter
than ``gate_bridge_s`` between passing samples (encoder glitches) are bridged. The gate is
the longest run of passing samples. Its *ramp start* is where the speeds began to move to
their set points: the last sample, within ``ramp_lookback_s`` before the gate, whose
deviation (relative to the scale) was still 95 % of the largest one there.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from stable_phase.params import StablePhaseParams
from stable_phase.signals import longest_true_run, moving_average, robust_sigma
from swtlab_base.order_stats import median


@dataclass(frozen=True)
class Gate:
    """Longest gated segment ``[start, stop)`` (sample indices) and how it was found."""

    start: int | None
    stop: int | None
    ramp_start: int | None
    diagnostics: dict


def surface_speed_setpoint_mps(velocity_mps: float, slip: float) -> float:
    """``r*omega`` that gives ``slip`` at travel velocity ``v`` (spec slip definitions)."""
    if slip >= 0:
        return velocity_mps / (1.0 - slip) if slip < 1.0 else float("inf")
    return velocity_mps * (1.0 + slip)


def _plateau(x: np.ndarray, rel_tol: float) -> float:
    """The level a speed holds longest: the median around the mode of its histogram
    (bins of ``rel_tol`` times its 99th-percentile magnitude)."""
    finite = x[np.isfinite(x)]
    if finite.size == 0:
        return float("nan")
    width = max(rel_tol * float(np.percentile(np.abs(finite), 99)), 1e-12)
    edges = np.arange(finite.min(), finite.max() + 2 * width, width)
    counts, edges = np.histogram(finite, edges)
    centre = edges[np.argmax(counts)] + width / 2
    return float(median(finite[np.abs(finite - centre) <= width]))


def references(run, surface_mps: np.ndarray, velocity_mps: np.ndarray,
               rel_tol: float) -> dict[str, float]:
    """Reference speeds (m/s) the gate holds the run to, by test mode."""
    info = run.metadata.run
    c = info.condition
    if c.mode == "free_sled":
        return {"wheel_surface_speed_mps": _plateau(surface_mps, rel_tol),
                "sled_velocity_mps": _plateau(velocity_mps, rel_tol)}
    if c.mode == "towed" or (c.slip_setpoint is None
                                and info.wheel_surface_speed_setpoint_mps is None):
        return {"wheel_surface_speed_mps": _plateau(surface_mps, rel_tol),
                "sled_velocity_mps": c.velocity_set_mps}
    surface = info.wheel_surface_speed_setpoint_mps
    if surface is None:
        surface = surface_speed_setpoint_mps(c.velocity_set_mps, c.slip_setpoint)
    return {"wheel_surface_speed_mps": surface, "sled_velocity_mps": c.velocity_set_mps}


def speed_gate(run, params: StablePhaseParams) -> Gate:
    """Gate a run on its measured speeds (see module doc)."""
    ch = run.channels
    t = ch["t_s"].to_numpy()
    rate_hz = 1.0 / float(median(np.diff(t)))
    width = max(int(round(params.gate_smooth_s * rate_hz)), 1)
    speeds = {"wheel_surface_speed_mps": moving_average(ch["wheel_surface_speed_mps"], width),
              "sled_velocity_mps": moving_average(ch["sled_velocity_mps"], width)}
    refs = references(run, speeds["wheel_surface_speed_mps"], speeds["sled_velocity_mps"],
                      params.gate_rel_tol)
    scale = max(abs(v) for v in refs.values())
    moving = np.abs(speeds["sled_velocity_mps"]) > 0.5 * abs(refs["sled_velocity_mps"])
    passing = np.ones(t.size, bool)
    relative = np.zeros(t.size)
    tolerances = {}
    for name, x in speeds.items():
        deviation = x - refs[name]
        sigma = robust_sigma(deviation[moving]) if moving.any() else float("nan")
        tol = max(params.gate_rel_tol * scale, params.gate_sigmas * np.nan_to_num(sigma))
        entry = {"set_point": refs[name], "reference": refs[name], "tolerance": tol,
                 "noise_sigma": sigma}
        plateau = _plateau(x[moving], params.gate_rel_tol)
        if abs(plateau - refs[name]) > tol:
            entry.update(reference=plateau, set_point_mismatch=plateau - refs[name])
            deviation = x - plateau
        tolerances[name] = entry
        passing &= np.abs(deviation) <= tol
        relative = np.fmax(relative, np.abs(deviation) / scale)
    passing = bridge_dropouts(passing, int(round(params.gate_bridge_s * rate_hz)))
    segment = longest_true_run(passing)
    diagnostics = {"gate": tolerances, "gate_pass_fraction": float(passing.mean()),
                   "gate_smooth_samples": width}
    if segment is None:
        return Gate(None, None, None, diagnostics)
    ramp = ramp_start(relative, segment[0], int(round(params.ramp_lookback_s * rate_hz)))
    diagnostics.update({"gate_start_s": float(t[segment[0]]),
                        "gate_end_s": float(t[segment[1] - 1]), "ramp_start_s": float(t[ramp])})
    return Gate(segment[0], segment[1], ramp, diagnostics)


def bridge_dropouts(mask: np.ndarray, max_samples: int) -> np.ndarray:
    """Set to True the runs of False no longer than ``max_samples`` with True on both sides."""
    edges = np.diff(np.concatenate([[1], mask.astype(np.int8), [1]]))
    starts, stops = np.flatnonzero(edges == -1), np.flatnonzero(edges == 1)
    inner = (starts > 0) & (stops < mask.size) & (stops - starts <= max_samples)
    index = np.arange(mask.size)
    fill = ((index[:, None] >= starts[inner]) & (index[:, None] < stops[inner])).any(axis=1)
    return mask | fill


def ramp_start(relative_deviation: np.ndarray, gate_start: int, lookback: int) -> int:
    """Last sample before ``gate_start`` still at 95 % of the largest deviation in the lookback."""
    lo = max(gate_start - lookback, 0)
    before = relative_deviation[lo:gate_start]
    if before.size == 0 or not np.isfinite(before).any():
        return gate_start
    far = np.flatnonzero(before >= 0.95 * np.nanmax(before))
    return lo + int(far[-1])
