"""Exponential-settling detector: the transient ends when it has decayed to a set fraction.

Sinkage and the forces settle roughly exponentially after the wheel reaches its set
speeds (soil compaction under the passing wheel; raw-run spec: "about 25 s at 40 m/h on
ES-3"). Each signal, averaged over one grouser period, is fitted with
``y = a + b exp(-max(t - t_on, 0)/tau)`` (onset ``t_on`` fitted too) from the ramp start
(where the speeds began to move to their set points) to the gate's end.

The first signal, in the order hub height, sinkage, drawbar pull, torque, whose transient
stands out from its residual (``|b|/sigma >= 10``) sets the start ``t_on + tau ln(1/f)``
with ``f = settle_fraction`` (0.5 %: ``5.3 tau``, the settling-time convention with a
0.5 % band), never before the gate opens. The hub height comes first: it is the soil's
state seen by the suspension encoder alone, free of the load-cell drift that enters a
flexible wheel's sinkage; resistance follows it, and DP mixes the fast shear build-up in.
Without a clear transient the window opens at the gate. Where the transient is no
exponential (a rig lowering the wheel in steps) and the fitted start leaves less than
``min_window_s``, the two-sided MSER cut of that signal is used instead (``fallback``).

The end is cut by two-sided MSER with the start held (see ``mser``), by at most
``end_max_cut_fraction`` of the rest: the speed gate has already removed the deceleration,
and MSER over-truncates autocorrelated batch means.
"""

from __future__ import annotations

import numpy as np
from scipy.optimize import curve_fit

from stable_phase.mser import MserDetector, batch_means, mser_two_sided
from stable_phase.registry import Cut, register
from stable_phase.signals import moving_average

MIN_SNR = 10.0
#: the smoothed signals are fitted on at most this many points (decimated after the
#: period-long moving average, which has already removed what decimation would alias)
FIT_POINTS = 5000


def _exponential(t, a, b, tau, t0):
    return a + b * np.exp(-np.clip(t - t0, 0.0, None) / tau)


def fit_settling(t_s: np.ndarray, y: np.ndarray) -> dict | None:
    """Least-squares exponential settling fit; None when it cannot be fitted."""
    ok = np.isfinite(y)
    if ok.sum() < 10:
        return None
    t, y = t_s[ok] - t_s[0], y[ok]
    span = float(t[-1])
    a0 = float(np.median(y[t >= 0.75 * span]))
    p0 = (a0, float(y[0] - a0), span / 10.0, 0.0)
    try:
        p, _ = curve_fit(_exponential, t, y, p0=p0,
                         bounds=([-np.inf, -np.inf, 1e-3 * span, 0.0],
                                 [np.inf, np.inf, 2.0 * span, 0.5 * span]))
    except (RuntimeError, ValueError):
        return None
    sigma = float(np.std(y - _exponential(t, *p)))
    return {"a": float(p[0]), "b": float(p[1]), "tau_s": float(p[2]),
            "onset_s": float(t_s[0] + p[3]), "residual_sigma": sigma,
            "snr": float(abs(p[1]) / sigma) if sigma > 0 else float("inf")}


@register
class SettlingDetector:
    name = "settling"
    description = "exponential-settling fit (0.5 % band) + MSER end cut"

    def locate(self, t_s, signals, period_s, params, gate_start) -> Cut:
        dt = float(np.median(np.diff(t_s)))
        width = max(int(round((period_s or params.batch_s) / dt)), 1)
        step = -(-t_s.size // FIT_POINTS)
        fits = {name: fit_settling(t_s[::step], moving_average(y, width, full_only=True)[::step])
                for name, y in signals.items()}
        fits = {k: v for k, v in fits.items() if v is not None}
        best = next((k for k, v in fits.items() if v["snr"] >= MIN_SNR), None)
        start = gate_start
        if best is not None:
            fit = fits[best]
            start_s = fit["onset_s"] + fit["tau_s"] * np.log(1.0 / params.settle_fraction)
            start = max(gate_start, int(np.searchsorted(t_s, start_s)))
        fallback = None
        min_samples = int(round(params.min_window_s / dt))
        if best is not None and start > t_s.size - min_samples:
            fallback = "mser"
            start = MserDetector().locate(t_s, {best: signals[best]}, period_s, params,
                                          gate_start).start
        stop = t_s.size
        if best is not None and start < t_s.size:
            centres, means = batch_means(t_s, signals[best], period_s, params.batch_s)
            first = int(np.searchsorted(centres, start))
            if centres.size - first >= 4:
                _, d2, _ = mser_two_sided(means, params.end_max_cut_fraction, fixed_start=first)
                stop = int(centres[centres.size - 1 - d2]) + 1
        return Cut(start, max(stop, start),
                   {"settling_fits": fits, "settling_signal": best, "fallback": fallback})
