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
from swtlab_base.order_stats import median

MIN_SNR = 10.0
#: the smoothed signals are fitted on at most this many points (decimated after the
#: period-long moving average, which has already removed what decimation would alias)
FIT_POINTS = 5000
#: starts of the double-pole fit, ``(c/b, tau/tau_plain)``: a plain exponential, and one
#: rising past its final value (c against b) at the plain and twice the plain time constant
DOUBLE_STARTS = ((0.0, 1.0), (-1.0, 1.0), (-1.0, 2.0), (-2.0, 2.0))


class _Decay:
    """``x = max(t - t_on, 0)/tau`` and ``exp(-x)`` of the last ``(t, tau, t_on)``, kept:
    curve_fit's finite-difference steps in the linear parameters reuse them (the same
    numbers as computing them again, without most of the exponentials of its Jacobian)."""

    def __init__(self):
        self._key: tuple | None = None
        self._x: np.ndarray | None = None
        self._decay: np.ndarray | None = None

    def decay(self, t, tau, t0) -> tuple[np.ndarray, np.ndarray]:
        key = self._key
        if key is None or key[0] is not t or key[1] != tau or key[2] != t0:
            self._x = np.maximum(t - t0, 0.0) / tau
            self._decay = np.exp(-self._x)
            self._key = (t, tau, t0)
        return self._x, self._decay


class _Exponential(_Decay):
    """``a + b exp(-max(t - t_on, 0)/tau)``."""

    def __call__(self, t, a, b, tau, t0):
        return a + b * self.decay(t, tau, t0)[1]


class _RepeatedPole(_Decay):
    """``a + (b + c x) exp(-x)``, ``x = max(t - t_on, 0)/tau``."""

    def __call__(self, t, a, b, c, tau, t0):
        x, decay = self.decay(t, tau, t0)
        return a + (b + c * x) * decay


def _fit(model, t, y, p0, lower, upper):
    try:
        p, _ = curve_fit(model, t, y, p0=p0, bounds=(lower, upper))
    except (RuntimeError, ValueError):
        return None
    return p, float(np.std(y - model(t, *p)))


def fit_settling(t_s: np.ndarray, y: np.ndarray, double_pole: bool = True) -> dict | None:
    """Least-squares settling fit; None when it cannot be fitted.

    First ``a + b exp(-s/tau)`` (``s = max(t - t_on, 0)``); then (``double_pole``)
    ``a + (b + c s/tau)
    exp(-s/tau)``, the step response of a second-order system with a double pole (Ogata
    2010, Modern Control Engineering, 5th ed., sec. 5-3, critically damped case), which also
    follows a transient that rises past its final value and creeps back. ``c`` is kept
    (``c_term``) only when that term stands out from the residual as a transient must
    (peak ``|c|/e >= MIN_SNR`` sigma), else 0: a plain exponential keeps its plain fit.
    """
    ok = np.isfinite(y)
    if ok.sum() < 10:
        return None
    t, y = t_s[ok] - t_s[0], y[ok]
    span = float(t[-1])
    a0 = median(y[t >= 0.75 * span])
    plain = _fit(_Exponential(), t, y, (a0, float(y[0] - a0), span / 10.0, 0.0),
                 [-np.inf, -np.inf, 1e-3 * span, 0.0], [np.inf, np.inf, 2.0 * span, 0.5 * span])
    if plain is None:
        return None
    (a, b, tau, t0), sigma = plain
    c = 0.0
    starts = [(a, b, b * c_ratio, tau * tau_ratio, t0)
              for c_ratio, tau_ratio in (DOUBLE_STARTS if double_pole else ())]
    fits = [f for f in (_fit(_RepeatedPole(), t, y, p0, [-np.inf, -np.inf, -np.inf, 1e-3 * span,
                                                         0.0],
                             [np.inf, np.inf, np.inf, 2.0 * span, 0.5 * span]) for p0 in starts)
            if f is not None]
    double = min(fits, key=lambda f: f[1], default=None)
    if double is not None and abs(double[0][2]) / np.e >= MIN_SNR * double[1] > 0:
        (a, b, c, tau, t0), sigma = double
    return {"a": float(a), "b": float(b), "c": float(c), "tau_s": float(tau),
            "onset_s": float(t_s[0] + t0), "plain_onset_s": float(t_s[0] + plain[0][3]),
            "plain_tau_s": float(plain[0][2]), "residual_sigma": sigma,
            "snr": float(max(abs(b), abs(c) / np.e) / sigma) if sigma > 0 else float("inf")}


def settling_time_s(fit: dict, fraction: float) -> float:
    """Time from the onset after which the fitted transient ``(b + c x) exp(-x)``,
    ``x = s/tau``, stays within ``fraction`` of its largest excursion (``tau ln(1/f)`` for
    a plain exponential)."""
    x = np.linspace(0.0, 60.0, 60001)
    transient = np.abs((fit["b"] + fit["c"] * x) * np.exp(-x))
    outside = np.flatnonzero(transient > fraction * transient.max())
    return fit["tau_s"] * float(x[outside[-1]] if outside.size else 0.0)


def settled_at_s(fit: dict, fraction: float, latest_s: float = np.inf) -> float:
    """When the transient is settled: the double-pole fit's settling time, never before the
    plain exponential's (a second mode can only prolong a transient; where the double pole
    bends the fit of the early rise instead, the plain fit's time stands), and the plain
    time where the double pole's is after ``latest_s`` (a settling the record cannot follow
    by a window is not the record's)."""
    plain = fit["plain_onset_s"] + fit["plain_tau_s"] * np.log(1.0 / fraction)
    double = fit["onset_s"] + settling_time_s(fit, fraction)
    return max(double, plain) if double <= latest_s else plain


@register
class SettlingDetector:
    name = "settling"
    description = "exponential-settling fit (0.5 % band) + MSER end cut"
    double_pole = False

    def locate(self, t_s, signals, period_s, params, gate_start) -> Cut:
        dt = float(median(np.diff(t_s)))
        width = max(int(round((period_s or params.batch_s) / dt)), 1)
        step = -(-t_s.size // FIT_POINTS)
        kept = np.arange(0, t_s.size, step)
        fits = {name: fit_settling(t_s[kept], moving_average(y, width, full_only=True, at=kept),
                                   self.double_pole)
                for name, y in signals.items()}
        fits = {k: v for k, v in fits.items() if v is not None}
        best = next((k for k, v in fits.items() if v["snr"] >= MIN_SNR), None)
        start = gate_start
        if best is not None:
            fit = fits[best]
            # the window after it must survive the end cut and the whole-period trim
            room_s = params.min_window_s / (1.0 - params.end_max_cut_fraction) + (period_s or 0)
            start_s = settled_at_s(fit, params.settle_fraction, float(t_s[-1]) - room_s)
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


@register
class OvershootSettlingDetector(SettlingDetector):
    """``settling`` with the double-pole term (``fit_settling``): a transient that rises past
    its final value and creeps back opens the window later. Not the default yet: its later
    windows (12-20 s on the second rig) make the grouser-frequency check flag runs."""

    name = "settling_overshoot"
    description = "exponential/double-pole settling fit (0.5 % band) + MSER end cut"
    double_pole = True
