"""Plausibility and sensor-health checks of a run, on its calibrated, zeroed channels and its
window statistics: each check that fails is a flag with its reason (the run's status becomes
``flagged``, which keeps it out of the fits by default).

- saturation: a force or torque channel flat-topped at a rail (samples pile up at the
  extreme value instead of thinning out towards it, as a noisy signal's tail does);
- spikes: a force or torque sample more than twice the set load from the window's median,
  a hub height more than the wheel radius from it;
- dead or constant channels: a measured channel whose native samples never change over the
  whole run (a wheel that never turns, a disconnected load cell);
- a standard error of 0 of a load-cell quantity, or a statistic that is not finite;
- negative wheel load, or negative sinkage, beyond the noise; slip outside [-1, 1], a
  drawbar pull or thrust beyond any soil's traction, sinkage deeper than the wheel radius;
- the measured wheel load against the set load beyond :data:`LOAD_REL_TOL`;
- a speed that missed its set point (the gate held the run to its own plateau instead);
- metadata outside the plausible ranges of ``swtlab_base.domain.ranges`` (wheel radius, width,
  stiffness, grouser count and height, set load, gravity);
- dig-in: the drawbar pull rose to a peak after the speeds reached their set points and
  collapsed before the window (slip sinkage at high slip: Ding et al. 2011, J.
  Terramechanics 48(1)); an overshoot that is already there when the speeds are up and
  decays into the window is the run settling, not a dig-in; or sinkage grew through the
  first candidate window of which only the flat second half was kept: a tail that looks
  flat after a dig-in.
"""

from __future__ import annotations

import numpy as np

from ingest.canonical import WRENCH_COLUMNS
from run_results.native import channel_samples, hub_samples
from stable_phase.signals import grouser_period_s, moving_average
from swtlab_base.domain.ranges import METADATA, WHEEL_KEYS
from swtlab_base.order_stats import median

#: force and torque channels checked for saturation
RAIL_CHANNELS = (*WRENCH_COLUMNS.values(), "dp_n")
#: measured channels checked for a dead (constant) sensor
MEASURED_CHANNELS = (*RAIL_CHANNELS, "wheel_angle_rad", "sled_position_m",
                     "suspension_angle_rad", "hub_height_m", "wheel_surface_speed_mps",
                     "sled_velocity_mps")
#: a rail holds at least this many samples, and this share of the window ...
RAIL_MIN_SAMPLES, RAIL_MIN_FRACTION = 5, 0.02
#: ... and this many times the samples of the next level below it
RAIL_PILE_RATIO = 2.0
#: a force sample this many set loads from the window's median is a glitch
SPIKE_LOAD_RATIO = 2.0
#: measured load this far (share of the set load) from the set load is flagged
LOAD_REL_TOL = 0.25
#: a negative load or sinkage beyond max(NOISE_SIGMAS * SE, floor) is flagged
NOISE_SIGMAS = 3.0
NEGATIVE_SINKAGE_FLOOR_M = 1e-3
#: |DP| / W or |T/r| / W above this is beyond any soil's traction: DP < H <= H_max =
#: A c + W tan(phi) (Coulomb-Micklethwaite; Wong, Theory of Ground Vehicles), tan(phi) < 1
MAX_TRACTION_RATIO = 1.5
#: a drawbar pull that falls by this share of its (driving) peak has collapsed; a settling
#: transient's overshoot falls by about a tenth (virtual testbed, sample campaign)
DIG_IN_COLLAPSE_RATIO = 0.3
#: ... and it must first have risen after the speeds were up by this share of its peak: an
#: overshoot already there at the gate that decays into the window is the run settling (a
#: soft soil's slip-sinkage develops over the first metres while the DP overshoots: gap
#: bench seed 30 c013, DP 83 -> 27 N over 20 s with a stable phase in the truth)
DIG_IN_RISE_RATIO = 0.3
#: quantities from load cells, whose noise never lets a window be constant; an encoder's
#: (hub height, slip) may hold one quantisation step over a window (SE 0 from resolution)
LOAD_CELL_QUANTITIES = ("wheel_load_n", "dp_n", "torque_nm", "thrust_n", "resistance_n",
                        "side_force_n")


def _native(run, column: str):
    for topic, frame in run.streams.items():
        if column in frame.columns:
            return topic, frame["t_s"].to_numpy(), frame[column].to_numpy()
    return None


def _window_samples(run, start_s: float, end_s: float):
    """``(column, samples in the window)`` of each force/torque channel the run logs."""
    for column in RAIL_CHANNELS:
        found = channel_samples(run, column, start_s, end_s)
        if found is not None:
            yield column, found[1]


def saturation_flags(run, start_s: float, end_s: float) -> list[str]:
    """Force/torque channels whose window samples pile up at their maximum or minimum."""
    flags = []
    for column, y in _window_samples(run, start_s, end_s):
        if y.size < RAIL_MIN_SAMPLES or np.ptp(y) == 0:
            continue
        levels, counts = np.unique(y, return_counts=True)
        for name, rail, at_rail, next_level in (("maximum", levels[-1], counts[-1], counts[-2]),
                                                ("minimum", levels[0], counts[0], counts[1])):
            if (at_rail >= max(RAIL_MIN_SAMPLES, RAIL_MIN_FRACTION * y.size)
                    and at_rail > RAIL_PILE_RATIO * next_level):
                flags.append(f"{column} saturated: {100 * at_rail / y.size:.1f} % of the window's "
                             f"samples sit at its {name} {rail:.6g} (flat-topped at a rail)")
    return flags


def spike_flags(run, start_s: float, end_s: float) -> list[str]:
    """Force/torque samples that jump from the window's median by more than
    :data:`SPIKE_LOAD_RATIO` times the set load (times the radius for a torque): an electrical
    glitch, not the soil (a stone under the wheel loads it by a fraction of its load); and hub
    heights (from the arm angle) that jump by more than the wheel radius."""
    load, radius = run.metadata.run.condition.load_set_n, run.metadata.wheel.radius_m
    flags = []
    for column, y in _window_samples(run, start_s, end_s):
        scale = SPIKE_LOAD_RATIO * load * (radius if column.endswith("_nm") else 1.0)
        jumps = int(np.sum(np.abs(y - median(y)) > scale)) if y.size else 0
        if jumps:
            flags.append(f"{column}: {jumps} samples jump more than {scale:.4g} from the window's "
                         f"median ({SPIKE_LOAD_RATIO:g} x the set load): electrical spikes?")
    hub = hub_samples(run, start_s, end_s)
    if hub is not None and hub[1].size:
        jumps = int(np.sum(np.abs(hub[1] - median(hub[1])) > radius))
        if jumps:
            flags.append(f"hub_height_m: {jumps} samples jump more than the wheel radius "
                         f"{radius:g} m from the window's median: arm encoder spikes?")
    return flags


def dead_channel_flags(run) -> list[str]:
    """Measured channels whose native samples are one value over the whole run."""
    flags = []
    for column in MEASURED_CHANNELS:
        found = _native(run, column)
        if found is not None and found[2].size > 1 and np.ptp(found[2]) == 0:
            flags.append(f"{column} is constant ({found[2][0]:.6g}) over the whole run "
                         f"({found[0]}): dead or disconnected sensor")
    return flags


def statistics_flags(quantities: dict) -> list[str]:
    """Statistics that are not finite, and standard errors of 0 of load-cell quantities."""
    flags = []
    for name, q in quantities.items():
        values = (q.mean, q.std, q.se)
        if not all(v is not None and np.isfinite(v) for v in values):
            flags.append(f"{name}: mean, std or SE is not finite")
        elif q.se == 0 and name in LOAD_CELL_QUANTITIES:
            flags.append(f"{name}: SE of 0 (the channel does not vary over the window)")
    return flags


def _beyond_noise(q, floor: float) -> bool:
    return q.mean < -max(NOISE_SIGMAS * q.se, floor)


def load_flags(run, quantities: dict) -> list[str]:
    """Negative load or sinkage beyond the noise; measured against set load."""
    flags = []
    load_set = run.metadata.run.condition.load_set_n
    load = quantities.get("wheel_load_n")
    if load is not None and np.isfinite(load.mean):
        if _beyond_noise(load, 0.0):
            flags.append(f"negative wheel load {load.mean:.4g} N (SE {load.se:.2g} N)")
        elif abs(load.mean - load_set) > LOAD_REL_TOL * load_set + NOISE_SIGMAS * load.se:
            flags.append(f"measured wheel load {load.mean:.4g} N differs from the set "
                         f"{load_set:g} N by more than {100 * LOAD_REL_TOL:g} %")
    sinkage = quantities.get("sinkage_m")
    if sinkage is not None and np.isfinite(sinkage.mean) \
            and _beyond_noise(sinkage, NEGATIVE_SINKAGE_FLOOR_M):
        flags.append(f"negative sinkage {1e3 * sinkage.mean:.3g} mm (SE "
                     f"{1e3 * sinkage.se:.2g} mm): the wheel rises above the soil surface")
    return flags


def physical_flags(run, quantities: dict) -> list[str]:
    """Means no wheel on soil gives: slip outside [-1, 1] (an encoder glitch, or a wheel
    turning against its travel), |DP| or |T/r| above :data:`MAX_TRACTION_RATIO` times the
    measured load, sinkage deeper than the wheel radius."""
    flags = []

    def mean(name):
        q = quantities.get(name)
        return q.mean if q is not None and np.isfinite(q.mean) else None

    for name in ("slip", "image_slip"):
        if mean(name) is not None and abs(mean(name)) > 1.0:
            flags.append(f"{name} {mean(name):.4g} outside [-1, 1]: encoder glitch or the "
                         "wheel turning against its travel")
    load = mean("wheel_load_n")
    for name, label in (("dp_n", "drawbar pull"), ("thrust_n", "thrust T/r")):
        value = mean(name)
        if load and value is not None and abs(value) > MAX_TRACTION_RATIO * abs(load):
            flags.append(f"{label} {value:.4g} N over {MAX_TRACTION_RATIO:g} times the wheel "
                         f"load {load:.4g} N")
    radius, sinkage = run.metadata.wheel.radius_m, mean("sinkage_m")
    if sinkage is not None and sinkage > radius:
        flags.append(f"sinkage {1e3 * sinkage:.4g} mm deeper than the wheel radius "
                     f"{1e3 * radius:g} mm")
    return flags


def set_point_flags(window) -> list[str]:
    """Speeds the gate found away from their set point (held to their own plateau)."""
    flags = []
    for name, entry in window.diagnostics.get("gate", {}).items():
        if "set_point_mismatch" in entry:
            flags.append(f"{name} held {entry['reference']:.4g} m/s instead of its set point "
                         f"{entry['set_point']:.4g} m/s")
    return flags


def metadata_flags(metadata) -> list[str]:
    """Wheel geometry, set load and gravity outside their plausible ranges."""
    values = {key: getattr(metadata.wheel, field) for key, field in WHEEL_KEYS.items()}
    values.update({"run.load_N": metadata.run.condition.load_set_n,
                   "run.gravity_mps2": metadata.run.condition.gravity_mps2})
    flags = []
    for key, value in values.items():
        why = None if value is None else METADATA[key].implausible(float(value))
        if why:
            flags.append(f"metadata {key} {why}")
    wheel = metadata.wheel
    if wheel.grouser_height_m >= wheel.radius_m:
        flags.append(f"metadata grouser height {wheel.grouser_height_m:g} m not below the wheel "
                     f"radius {wheel.radius_m:g} m")
    return flags


def dig_in_flags(run, window, params) -> list[str]:
    """Drawbar pull that rose (by :data:`DIG_IN_RISE_RATIO` of its peak after the gate) and
    collapsed between the gate and the window (by more than :data:`DIG_IN_COLLAPSE_RATIO` of
    its peak and ``params.dig_in_dp_drop_ratio`` of the set load), or sinkage that grew
    significantly through the first candidate window when only its flat second half was kept
    (stable-phase slope test)."""
    ch, load = run.channels, run.metadata.run.condition.load_set_n
    t = ch["t_s"].to_numpy()
    gate_s = window.diagnostics.get("gate_start_s")
    lo, start, stop = (int(np.searchsorted(t, x)) for x in (gate_s, window.start_s,
                                                            window.end_s))
    flags = []
    period = grouser_period_s(run.metadata.wheel.grouser_count,
                              float(np.nanmedian(ch["wheel_omega_radps"].to_numpy()[start:stop])))
    dt = float(median(np.diff(t)))
    width = max(int(round(max(period or 0.0, params.batch_s) / dt)), 1)
    dp = ch["dp_n"].to_numpy()
    if run.metadata.run.condition.mode != "free_sled" and start - lo > width \
            and np.isfinite(dp[lo:stop]).mean() > 0.5:
        smooth = moving_average(dp[lo:stop], width, full_only=True)
        before, inside = smooth[:start - lo], dp[start:stop]
        if np.isfinite(before).any() and np.isfinite(inside).any():
            peak, level = float(np.nanmax(before)), float(np.nanmean(inside))
            at_gate = float(before[np.isfinite(before)][0])
            if peak > 0 and peak - at_gate > DIG_IN_RISE_RATIO * peak \
                    and peak - level > max(DIG_IN_COLLAPSE_RATIO * peak,
                                           params.dig_in_dp_drop_ratio * load):
                at = t[lo + int(np.nanargmax(before))]
                flags.append(f"dig-in: drawbar pull rose to {peak:.4g} N at {at:.1f} s, then "
                             f"collapsed to {level:.4g} N in the window")
    first = window.diagnostics.get("checks_window", {}).get("sinkage_m", {})
    if window.diagnostics.get("shrunk_to_second_half") and first.get("drifts") \
            and first["change"] > 0:
        flags.append(f"dig-in: sinkage grew by {1e3 * first['change']:.3g} mm through the first "
                     "candidate window (the window kept is its flat second half)")
    return flags


def plausibility_flags(run, window, quantities: dict, params) -> list[str]:
    """Every check above on a run whose stable window was found (``params``: the
    ``StablePhaseParams`` the window was found with)."""
    return [*metadata_flags(run.metadata), *dead_channel_flags(run),
            *saturation_flags(run, window.start_s, window.end_s),
            *spike_flags(run, window.start_s, window.end_s),
            *statistics_flags(quantities), *load_flags(run, quantities),
            *physical_flags(run, quantities),
            *set_point_flags(window), *dig_in_flags(run, window, params)]
