"""``process_run``: a run -> stable window -> corrected channels -> ``RunResult``.

Quantities over the window (keys match the virtual testbed's truth where they overlap):
slip, travel velocity, wheel angular velocity, wheel load ``fz``, drawbar pull, input
torque ``ty``, thrust ``H = T/r``, motion resistance ``R = T/r - DP`` (Wong, Theory of
Ground Vehicles, 4th ed., ch. 4), sinkage and hub height after the rig correction; for
steered runs also the side force ``fy`` and the slip angle (logged channel, else the
set steering angle). Plausibility and sensor health (``plausibility``: saturation, dead
channels, SE of 0, negative load or sinkage, set against measured load, metadata ranges,
dig-in) are checked on the calibrated, zeroed channels and flag the run. Wheel speed, travel
velocity and slip come from the window's displacements (``rates``). Single-channel
quantities come from the native samples, the means of resistance and sinkage from the
channels' native means (``native``). Given the run's track photos as measured
(``image_slip``: the slip read from the grouser marks by ``softflow.track_run``, which the
pipeline calls; this module opens no photo), the result also reports ``image_slip`` beside
the encoder slip. Every result carries its channels' decimated traces of DP, torque,
sinkage and slip (``run_results.traces``), so plots need not read the raw file again.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from ingest.run import DP_FROM_HUB
from run_results import oscillation as osc
from run_results.corrections import RigCompliance, corrected_heights, tare_record
from run_results.native import native_quantities
from run_results.phase_average import phase_average, phase_bins
from run_results.plausibility import plausibility_flags
from run_results.rest_readings import ends_moving, rest_readings
from run_results.result import RunResult
from run_results.rates import SOURCES, window_rate, window_slip
from run_results.stats import QuantityStats, pitch_batches, quantity_stats
from run_results.traces import run_traces
from run_results.uncertainty_budget import BudgetParams, run_budget
from stable_phase import StablePhaseParams, detect_stable_phase
from stable_phase.signals import decimate_mean
from swtlab_base.order_stats import median

#: quantities from the window's displacements (``run_results.rates``)
RATES = ("slip", "travel_velocity_mps", "wheel_omega_radps")
FORCE_CHANNELS = ("fx_n", "fy_n", "fz_n", "tx_nm", "ty_nm", "tz_nm", "dp_n")
#: a measured passing frequency this far from n*omega/2pi is flagged
GROUSER_MISMATCH_RATIO = 0.05
DP_TRACE_POINTS = 500


def _series(run, rig: RigCompliance | None) -> tuple[dict[str, tuple[np.ndarray, str]], dict]:
    """Every quantity's per-sample series (after corrections) with its unit."""
    ch, meta = run.channels, run.metadata
    radius = meta.wheel.radius_m
    fz = ch["fz_n"].to_numpy()
    fz_for_rig = np.where(np.isfinite(fz), fz, meta.run.condition.load_set_n)
    hub, sinkage, correction = corrected_heights(ch["hub_height_m"].to_numpy(), fz_for_rig,
                                                 meta.wheel.stiffness_n_per_mm, rig)
    if rig is None:
        sinkage = ch["sinkage_m"].to_numpy()
    torque = ch["ty_nm"].to_numpy()
    dp = ch["dp_n"].to_numpy()
    series = {
        "slip": (ch["slip"].to_numpy(), "1"),
        "travel_velocity_mps": (ch["sled_velocity_mps"].to_numpy(), "m/s"),
        "wheel_omega_radps": (ch["wheel_omega_radps"].to_numpy(), "rad/s"),
        "wheel_load_n": (fz, "N"),
        "dp_n": (dp, "N"),
        "torque_nm": (torque, "N*m"),
        "thrust_n": (torque / radius, "N"),
        "resistance_n": (torque / radius - dp, "N"),
        "sinkage_m": (sinkage, "m"),
        "hub_height_m": (hub, "m"),
    }
    if meta.run.condition.mode == "steered":
        series["side_force_n"] = (ch["fy_n"].to_numpy(), "N")
        if "slip_angle_rad" in ch and np.isfinite(ch["slip_angle_rad"].to_numpy()).any():
            series["slip_angle_deg"] = (np.degrees(ch["slip_angle_rad"].to_numpy()), "deg")
        else:
            steer_deg = float(meta.run.condition.steer_deg)
            series["slip_angle_deg"] = (np.full(len(ch), steer_deg), "deg")
    return series, {"correction_m": correction}


def _oscillation(run, t, lo, hi, series) -> tuple[dict, float | None]:
    """Passing frequency measured in the forces against ``n omega/2pi``; waveform peaks."""
    n = run.metadata.wheel.grouser_count
    omega = series["wheel_omega_radps"][0][lo:hi]
    expected = n * abs(float(np.nanmean(omega))) / (2.0 * np.pi) if np.isfinite(omega).any() else 0
    out = {"grouser_expected_hz": _frequency(expected) if n > 0 else None,
           "grouser_measured_hz": None, "grouser_signal": None}
    candidates = [k for k in ("dp_n", "torque_nm", "wheel_load_n")
                  if np.isfinite(series[k][0][lo:hi]).mean() > 0.5
                  and not (k == "dp_n" and run.metadata.run.condition.mode == "free_sled")]
    if out["grouser_expected_hz"] and candidates:
        signal = candidates[0]
        out["grouser_signal"] = signal
        out["grouser_measured_hz"] = _frequency(osc.measure_frequency_hz(
            t[lo:hi], series[signal][0][lo:hi], out["grouser_expected_hz"]))
    frequency = out["grouser_measured_hz"] or out["grouser_expected_hz"]
    for key, name, unit in (("dp_n", "dp", "n"), ("torque_nm", "torque", "nm")):
        y = series[key][0][lo:hi]
        if frequency and np.isfinite(y).mean() > 0.5 and key in candidates:
            wave = phase_average(t[lo:hi], y, frequency)["waveform"]
            out[f"{name}_peak_{unit}"] = float(np.nanmax(wave))
            out[f"{name}_peak_to_peak_{unit}"] = float(np.nanmax(wave) - np.nanmin(wave))
        else:
            out[f"{name}_peak_{unit}"] = out[f"{name}_peak_to_peak_{unit}"] = None
    out["method"] = (f"least squares on a {osc.HARMONICS}-harmonic series, global minimum on a "
                     "grid over +-40 % of n*omega/2pi refined by Brent; peaks from the "
                     "phase-averaged waveform")
    return out, frequency


def _frequency(hz: float) -> float | None:
    """A passing frequency that can be used (finite, > 0), else None (a wheel that does not
    turn has none)."""
    return float(hz) if np.isfinite(hz) and hz > 0 else None


def _flags(run, window, oscillation: dict) -> list[str]:
    flags = [f for f in (run.cut_short or ends_moving(run),) if f]
    missing = [c for c in FORCE_CHANNELS if not np.isfinite(run.channels[c].to_numpy()).any()]
    if missing:
        hint = ("; a rig without a drawbar-pull cell feeds dp_n from the hub's force channel "
                "in its channel map (docs/channel-map.md)"
                if "dp_n" in missing and "fx_n" not in missing else "")
        flags.append(f"no force channels ({', '.join(missing)}): forces, torque, thrust and "
                     "resistance not reported; window found from speeds and hub height "
                     f"alone{hint}")
    dp = run.derivation.get("dp_n", {})
    if dp.get("method") == DP_FROM_HUB:
        flags.append(f"drawbar pull from the hub's force channel {dp['channel']} (as "
                     f"{', '.join(dp['same_as'])}; no drawbar-pull cell): DP is the hub's "
                     "horizontal force")
    if window.diagnostics.get("shrunk_to_second_half"):
        flags.append("window shrunk to its second half: the first half drifted (slope test)")
    if window.found and not window.diagnostics.get("r_hat_ok", True):
        shifts = ", ".join(f"{k} by {v:.3g}" for k, v in window.diagnostics["level_shifts"].items())
        flags.append(f"split-window R statistic {window.diagnostics['r_hat_max']:.3f} above "
                     f"{window.parameters['r_hat_limit']}: the halves' means differ ({shifts}) "
                     "by more than the practical drift limit")
    expected, measured = oscillation["grouser_expected_hz"], oscillation["grouser_measured_hz"]
    if expected and measured and abs(measured / expected - 1.0) > GROUSER_MISMATCH_RATIO:
        flags.append(f"grouser passing frequency {measured:.4g} Hz differs from n*omega/2pi = "
                     f"{expected:.4g} Hz by more than {100 * GROUSER_MISMATCH_RATIO:g} %")
    return flags


def _rates(run, window, series, lo: int, hi: int) -> dict:
    """Wheel speed, travel velocity and slip from the window's displacements
    (``run_results.rates``); ``std``: the spread of the per-sample series (what one reading
    scatters by)."""
    def spread(key: str) -> float:
        y = series[key][0][lo:hi]
        return float(np.nanstd(y, ddof=1)) if np.isfinite(y).sum() > 1 else float("nan")

    out = {}
    for key in SOURCES:
        found = window_rate(run, key, window.start_s, window.end_s, spread(key))
        if found is not None:
            out[key] = found
    if len(out) == len(SOURCES):
        found = window_slip(out["wheel_omega_radps"], out["travel_velocity_mps"],
                            run.metadata.wheel.radius_m, spread("slip"))
        if found is not None:
            out["slip"] = found
    return out


def _image_slip(image) -> tuple[dict[str, QuantityStats], list[str]]:
    """``image_slip`` from the measured track photos (beside the encoder slip), and its flags;
    ``image``: a ``softflow.track_run.RunImageSlip`` or None."""
    if image is None:
        return {}, []
    flags = [f"image slip: {reason}" for reason in image.refusals]
    if image.slip is None:
        return {}, flags
    return {"image_slip": QuantityStats(mean=image.slip, std=image.slip_spread, se=image.slip_se,
                                        n=image.used, n_eff=float(image.used), unit="1")}, flags


def process_run(run, params: StablePhaseParams | None = None,
                rig: RigCompliance | None = None, image_slip=None,
                budget: BudgetParams | None = None) -> RunResult:
    """Stable window, corrected quantities with honest SE, oscillation and flags of one run;
    ``image_slip``, the run's track photos as measured (``softflow.track_run.run_image_slip``,
    which the pipeline calls), is reported beside the encoder slip. Every quantity has an
    uncertainty budget (``run_results.uncertainty_budget``, told the rig's clock by
    ``budget``); its mean carries the budget's re-zeroing on the rest readings."""
    window = detect_stable_phase(run, params)
    image_quantities, image_flags = _image_slip(image_slip)
    series, applied = _series(run, rig)
    t = run.channels["t_s"].to_numpy()
    corrections = {"tare": tare_record(run),
                   "rig_compliance": None if rig is None else rig.to_dict()}
    info = run.metadata.run
    common = {"run_id": run.run_id, "window": window, "campaign": info.campaign,
              "wheel": run.metadata.wheel, "soil": info.soil, "condition": info.condition,
              "traces": run_traces(t, series)}
    if not window.found:
        tb, dpb = decimate_mean(t, run.channels["dp_n"].to_numpy(), DP_TRACE_POINTS)
        trace = {"t_s": tb.tolist(), "dp_n": [None if not np.isfinite(v) else float(v)
                                              for v in dpb]}
        flags = (f"no stable phase: {window.reason}", *_flags(run, window, {
            "grouser_expected_hz": None, "grouser_measured_hz": None}), *image_flags)
        return RunResult(status="no_stable_phase", flags=flags, quantities=image_quantities,
                         oscillation={},
                         dp_trace=trace, corrections=corrections, **common)
    lo, hi = int(np.searchsorted(t, window.start_s)), int(np.searchsorted(t, window.end_s)) + 1
    oscillation, frequency = _oscillation(run, t, lo, hi, series)
    quantities, batches = {}, {}
    dt_s = float(median(np.diff(t[lo:hi])))
    pitch = round(1.0 / (frequency * dt_s)) if frequency else 0
    native, combined = native_quantities(run, window.start_s, window.end_s,
                                         {k: u for k, (_, u) in series.items()}, frequency, rig)
    phase = phase_bins(t[lo:hi], frequency) if frequency else None
    rates = _rates(run, window, series, lo, hi)
    quantities.update({k: r.stats for k, r in rates.items()})
    for key, (y, unit) in series.items():
        if key in RATES:
            continue
        average = None
        finite = int(np.isfinite(y[lo:hi]).sum())
        if frequency and finite > 16:
            average = phase_average(t[lo:hi], y[lo:hi], frequency, phase)
        # the native samples' stats replace the common grid's (their batches stay)
        stats = (native[key] if finite >= 2 else None) if key in native else quantity_stats(
            y[lo:hi], unit, average)
        if stats is not None:
            quantities[key] = stats
            if average is not None:
                batches[key] = pitch_batches(y[lo:hi], pitch, average["periodic"], dt_s)
    quantities.update({k: replace(quantities[k], mean=v) for k, v in combined.items()
                       if k in quantities})
    corrections["hub_height_correction_mean_m"] = float(np.nanmean(applied["correction_m"][lo:hi]))
    quantities.update(image_quantities)
    rests = rest_readings(run)
    corrections["rest_readings"] = None if rests is None else rests.to_dict()
    quantities, budgets = run_budget(run, (window.start_s, window.end_s), quantities, rests,
                                     budget, batches, frequency, rates)
    flags = (*_flags(run, window, oscillation), *image_flags,
             *plausibility_flags(run, window, quantities, params or StablePhaseParams()))
    return RunResult(status="flagged" if flags else "ok", flags=flags, quantities=quantities,
                     oscillation=oscillation, dp_trace=None, corrections=corrections,
                     uncertainty=budgets, **common)
