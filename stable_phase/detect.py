"""``detect_stable_phase``: speed gate -> transient cut -> whole grouser periods -> checks.

1. Gate (``gate``): longest segment where wheel and sled speeds hold their set points.
2. Transient cut (a registered detector, default ``settling``; ``mser`` for two-sided
   MSER) on sinkage, drawbar pull and torque (whichever the run has).
3. Trim the end so the window holds a whole number of grouser periods,
   ``T = 2 pi/(n omega)`` from the measured wheel speed.
4. Checks (``checks``): slope test of sinkage, DP and torque (statistically significant
   *and* larger than a practical limit fails; the window is shrunk once to its second half),
   split-window R statistic (flagged when above its limit *and* the halves' means differ by
   more than the same practical limit: a smooth wheel's quiet signal makes a 0.3 N shift
   between halves of a 250 N run statistically visible but physically nothing). A window
   that still drifts, or is too short, is no stable phase; its reason says what the DP(t)
   and sinkage did (dig-in: DP rises then collapses while sinkage grows).
"""

from __future__ import annotations

import numpy as np

from stable_phase import mser, settling  # noqa: F401  (register the shipped detectors)
from stable_phase.checks import half_change, slope_test, split_r_hat
from stable_phase.gate import speed_gate
from stable_phase.params import StablePhaseParams
from stable_phase.registry import get_detector
from stable_phase.signals import grouser_period_s, moving_average
from stable_phase.window import StableWindow
from swtlab_base.order_stats import median

#: signals the transient cut looks at, in order of preference, and those the checks test
SETTLING = ("hub_height_m", "sinkage_m", "dp_n", "ty_nm")
CHECKED = ("sinkage_m", "dp_n", "ty_nm")
MIN_FINITE_FRACTION = 0.5
#: fewer samples on the time base than this cannot hold a stable phase (nor a rate)
MIN_SAMPLES = 16


def _signals(run, lo: int, hi: int) -> dict[str, np.ndarray]:
    ch = run.channels
    free_sled = run.metadata.run.condition.mode == "free_sled"
    names = [c for c in SETTLING if not (c == "dp_n" and free_sled)]
    out = {}
    for name in names:
        y = ch[name].to_numpy()[lo:hi]
        if np.isfinite(y).mean() >= MIN_FINITE_FRACTION:
            out[name] = y
    return out


def _limits(run, signals: dict[str, np.ndarray], params: StablePhaseParams) -> dict[str, float]:
    """Practical drift limits over a window: a share of the load (forces) or of the sinkage."""
    load_n = run.metadata.run.condition.load_set_n
    limits = {"dp_n": params.slope_change_force_ratio * load_n,
              "ty_nm": params.slope_change_force_ratio * load_n * run.metadata.wheel.radius_m}
    if "sinkage_m" in signals:
        limits["sinkage_m"] = params.slope_change_sinkage_ratio * abs(
            float(np.nanmean(signals["sinkage_m"])))
    return limits


def _check(t: np.ndarray, signals: dict, limits: dict, params: StablePhaseParams) -> dict:
    out = {}
    for name, y in signals.items():
        test = slope_test(t, y)
        test["limit"] = limits.get(name, float("inf"))
        test["drifts"] = bool(test["p"] < params.slope_alpha
                              and abs(test["change"]) > test["limit"])
        test["r_hat"] = split_r_hat(y)
        test["half_change"] = half_change(y)
        test["level_shift"] = bool(test["r_hat"] > params.r_hat_limit
                                   and abs(test["half_change"]) > test["limit"])
        out[name] = test
    return out


def _whole_periods(t: np.ndarray, start: int, stop: int, period_s: float | None) -> tuple[int, int]:
    if period_s is None or stop - start < 2:
        return start, stop
    dt = float(median(np.diff(t)))
    periods = int(np.floor((stop - start) * dt / period_s))
    if periods < 1:
        return start, stop
    return start, start + int(round(periods * period_s / dt))


def _no_stable_reason(run, t: np.ndarray, lo: int, hi: int, period_s: float | None,
                      params: StablePhaseParams, fallback: str) -> str:
    """Describe what DP(t) and sinkage did over the gated segment.

    Dig-in: DP falls from its peak by ``dig_in_dp_drop_ratio`` of the load while sinkage
    still grows over the segment's second half (a settling transient has levelled off there).
    """
    ch = run.channels
    dt = float(median(np.diff(t)))
    width = max(int(round((period_s or params.batch_s) / dt)), 1)
    parts = []
    z = moving_average(ch["sinkage_m"].to_numpy()[lo:hi], width, full_only=True)
    finite = np.flatnonzero(np.isfinite(z))
    if finite.size > 2:
        mid, last = finite[finite.size // 2], finite[-1]
        if z[last] - z[mid] > params.slope_change_sinkage_ratio * abs(z[last]):
            parts.append(f"sinkage grows from {1e3 * z[finite[0]]:.1f} to {1e3 * z[last]:.1f} mm")
    dp = ch["dp_n"].to_numpy()[lo:hi]
    if parts and run.metadata.run.condition.mode != "free_sled" and np.isfinite(dp).mean() > 0.5:
        dp = moving_average(dp, width, full_only=True)
        peak = int(np.nanargmax(dp))
        end = float(dp[np.flatnonzero(np.isfinite(dp))[-1]])
        load_n = run.metadata.run.condition.load_set_n
        if float(dp[peak]) - end > params.dig_in_dp_drop_ratio * load_n:
            parts.insert(0, f"drawbar pull rises to {dp[peak]:.1f} N at {t[lo + peak]:.1f} s, "
                            f"then collapses to {end:.1f} N")
            return "; ".join(parts) + ": wheel digs in, no stable phase"
    return "; ".join(parts + [fallback])


def detect_stable_phase(run, params: StablePhaseParams | None = None) -> StableWindow:
    """Find the stable phase of one ``ingest.Run`` (see module doc for the method)."""
    params = params or StablePhaseParams()
    detector = get_detector(params.detector)
    method = (f"speed-gate + {detector.description} + whole grouser periods "
              "+ slope-test/R-statistic check")
    t = run.channels["t_s"].to_numpy()
    diag: dict = {}

    def not_found(reason: str) -> StableWindow:
        return StableWindow(False, None, None, method, params.to_dict(), diag, reason)

    if t.size < MIN_SAMPLES:
        return not_found(f"only {t.size} samples on the time base (needs {MIN_SAMPLES})")
    gate = speed_gate(run, params)
    diag.update(gate.diagnostics)
    if gate.start is None:
        return not_found("wheel and sled speeds never hold their set points together")
    ramp, lo, hi = gate.ramp_start, gate.start, gate.stop
    omega = float(np.nanmedian(run.channels["wheel_omega_radps"].to_numpy()[lo:hi]))
    period_s = grouser_period_s(run.metadata.wheel.grouser_count, omega)
    diag["grouser_period_s"] = period_s
    signals = _signals(run, ramp, hi)
    diag["signals"] = sorted(signals)
    if not signals:
        return not_found("no sinkage, drawbar pull or torque to find a stable phase in")
    cut = detector.locate(t[ramp:hi], signals, period_s, params, lo - ramp)
    diag.update(cut.diagnostics)
    start, stop = _whole_periods(t, ramp + cut.start, ramp + cut.stop, period_s)
    signals_checked = {k: v for k, v in signals.items() if k in CHECKED}
    limits = _limits(run, signals_checked, params)
    for attempt in ("window", "second half"):
        duration_s = float(t[stop - 1] - t[start]) if stop > start else 0.0
        if duration_s < params.min_window_s or (
                period_s is not None and duration_s < params.min_grouser_periods * period_s * 0.99):
            return not_found(_no_stable_reason(
                run, t, lo, hi, period_s, params,
                f"stable part too short ({duration_s:.1f} s; needs {params.min_window_s:g} s "
                f"and {params.min_grouser_periods} grouser periods)"))
        window_signals = {k: run.channels[k].to_numpy()[start:stop] for k in signals_checked}
        checks = _check(t[start:stop], window_signals, limits, params)
        diag[f"checks_{attempt.replace(' ', '_')}"] = checks
        drifting = [k for k, c in checks.items() if c["drifts"]]
        if not drifting:
            break
        start, stop = _whole_periods(t, (start + stop) // 2, stop, period_s)
    else:
        return not_found(_no_stable_reason(
            run, t, lo, hi, period_s, params,
            f"{', '.join(drifting)} drift significantly over every candidate window"))
    diag["grouser_periods"] = None if period_s is None else float(
        (t[stop - 1] - t[start] + median(np.diff(t))) / period_s)
    diag["window_samples"] = int(stop - start)
    diag["shrunk_to_second_half"] = attempt != "window"
    r_hats = [c["r_hat"] for c in checks.values() if np.isfinite(c["r_hat"])]
    diag["r_hat_max"] = max(r_hats) if r_hats else None
    diag["level_shifts"] = {k: c["half_change"] for k, c in checks.items() if c["level_shift"]}
    diag["r_hat_ok"] = not diag["level_shifts"]
    return StableWindow(True, float(t[start]), float(t[stop - 1]), method, params.to_dict(),
                        diag, None)
