"""Wheel angular speed, travel velocity and slip from the window's displacements.

A rate over the window is its displacement over the window's time: ``rate = (x_1 - x_0) /
(t_1 - t_0)`` from the first and last native samples of the encoder inside the window
(the angle, the sled position), or, where the source logs the rate itself (a channel map's
``wheel_surface_speed_mps``, ``sled_velocity_mps``; ingest takes it over a derivative too),
the time integral of its native samples (trapezoids) over the same span, i.e. their
time-weighted mean. Slip is the spec's
definition applied to those two rates, ``s = (r w - v)/(r w)`` driving (``r w >= v``) and
``(r w - v)/v`` skid, ``r`` the wheel radius without grousers (``ingest.derive.slip``). The
mean of per-sample ratios ``1 - v/(r w)`` of quantised finite differences is not used: the
mean of a ratio of noisy quantities is not the ratio of their means (Jensen's inequality),
which biases it at low speed, where each sample's change is a count or two.

Uncertainty terms of a rate (GUM, JCGM 100:2008), in :class:`RateEstimate`:

- ``statistical`` (Type A): the window is cut into :data:`BATCHES` equal spans; each span's
  displacement less ``rate`` times its duration, over the mean span, is a batch residual
  ``d_b`` (``sum d_b = 0``); their variance with the lag-1 autocovariance
  (``run_results.stats.batch_se``, Satterthwaite degrees of freedom) is that of the window
  rate: it sees the drives' slow ripple, and the reading errors at the span ends telescope
  (only the window's two ends remain, which the lag-1 term takes out, up to its noise).
- ``quantisation`` (Type B, GUM 4.3.7, F.2.2.1): a position read to a step ``q`` (the
  lattice its readings lie on, ``ingest.derive.quantisation_step``; the smallest difference
  of two readings is the motion per sample where that exceeds the step) errs
  uniformly within one step, ``u = q/sqrt(12)`` per reading; the rate takes two readings
  (the window's ends), so ``u = sqrt(2) q/sqrt(12) / T = q/(sqrt(6) T)``. A logged rate of
  step ``q``: the mean of its readings errs by ``q/sqrt(12)`` where the rate holds within a
  step (the same rounding every sample), less where its own spread ``s`` dithers it
  (``rest_readings.quantisation_u``: Widrow, Kollar & Liu 1996).
- ``timing`` (Type B): each time stamp scatters by ``sigma_t``, measured from the stream's
  regular intervals (those under 1.5 median intervals, dropped samples left out): two
  independent stamps make an interval of variance ``2 sigma_t^2``, so ``sigma_t =
  std(intervals)/sqrt(2)``; the window's duration takes two stamps, ``u = |rate| sqrt(2)
  sigma_t / T``. (Scatter of the true sampling instants, correctly stamped, is no error: the
  term is then an upper bound.) A logged rate's mean weighs its samples by their intervals,
  to first order insensitive to stamp errors: no term.

Slip: its sensitivities to ``r w`` and ``v`` (``c_w, c_v``: driving ``v/(r w)^2, -1/(r w)``;
skid ``1/v, -r w/v^2``) propagate each term (GUM 5.1.2; the two encoders independent), and
its statistical term is the batch estimate of ``c_w r d_b(w) + c_v d_b(v)``, so a
correlation of the two drives' ripples is kept (the delta method on the batch residuals).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.integrate import cumulative_trapezoid

from ingest.derive import quantisation_step
from ingest.derive import slip as spec_slip
from run_results.native import channel_samples
from run_results.rest_readings import quantisation_u
from run_results.stats import QuantityStats, batch_se

#: equal spans of the window for the statistical term
BATCHES = 20
#: intervals longer than this many median intervals are dropped samples, not jitter
REGULAR_INTERVAL = 1.5
#: rate key -> (position column, logged rate columns with their divisor by the radius?)
SOURCES = {"wheel_omega_radps": ("wheel_angle_rad", (("wheel_omega_radps", False),
                                                     ("wheel_surface_speed_mps", True))),
           "travel_velocity_mps": ("sled_position_m", (("sled_velocity_mps", False),))}
UNITS = {"wheel_omega_radps": "rad/s", "travel_velocity_mps": "m/s", "slip": "1"}


@dataclass(frozen=True)
class RateEstimate:
    """A window rate and its terms (module doc): ``stats`` (mean, the readings' spread, the
    statistical SE), the statistical term's degrees of freedom, ``quantisation_u`` and
    ``timing_u`` (standard uncertainties, the rate's unit), the batch residuals ``d_b``
    (rate units) and how it was read (``source``)."""

    stats: QuantityStats
    dof: float
    quantisation_u: float
    timing_u: float
    residuals: np.ndarray | None
    source: str


def timing_scatter_s(t_s: np.ndarray) -> float:
    """``sigma_t`` of a stream's time stamps: the std of its regular intervals over sqrt(2)
    (module doc); 0 with fewer than three."""
    dt = np.diff(t_s)
    if dt.size < 2:
        return 0.0
    regular = dt[dt <= REGULAR_INTERVAL * float(np.median(dt))]
    return float(np.std(regular, ddof=1) / math.sqrt(2)) if regular.size > 1 else 0.0


def _edges(t_s: np.ndarray, start_s: float, end_s: float, batches: int) -> np.ndarray:
    """Indices of the samples nearest the ``batches + 1`` equal-time span ends of the window
    (first and last sample at the ends)."""
    targets = start_s + (end_s - start_s) * np.arange(batches + 1) / batches
    i = np.clip(np.searchsorted(t_s, targets), 1, t_s.size - 1)
    i = np.where(targets - t_s[i - 1] < t_s[i] - targets, i - 1, i)
    i[0], i[-1] = 0, t_s.size - 1
    return i


def _samples(run, key: str, start_s: float, end_s: float):
    """``(t_s, x, source, logged)``: the integral of a rate the source logs (the lab's own
    rate measurement, which ingest also takes over a derivative) with ``logged = (step,
    rate samples)``, else the window's native positions (``logged`` None); None without
    either."""
    position, logged = SOURCES[key]
    for column, per_radius in logged:
        samples = channel_samples(run, column, start_s, end_s)
        if samples is not None and samples[0].size >= 2:
            t, y = samples
            y = y / run.metadata.wheel.radius_m if per_radius else y
            return t, cumulative_trapezoid(y, t, initial=0.0), column, (quantisation_step(y), y)
    samples = channel_samples(run, position, start_s, end_s)
    if samples is not None and samples[0].size >= 2:
        return samples[0], samples[1], position, None
    return None


def window_rate(run, key: str, start_s: float, end_s: float, spread: float,
                batches: int = BATCHES) -> RateEstimate | None:
    """The window rate ``key`` (a key of :data:`SOURCES`) from the run's native samples;
    ``spread``: the standard deviation of the rate's samples (what one reading scatters by,
    reported as ``std``). None without samples or a span."""
    found = _samples(run, key, start_s, end_s)
    if found is None:
        return None
    t, x, source, logged = found
    span = float(t[-1] - t[0])
    if not span > 0:
        return None
    rate = float((x[-1] - x[0]) / span)
    residuals, se, dof = None, 0.0, math.inf
    if t.size >= 4 * batches:
        i = _edges(t, start_s, end_s, batches)
        dt = np.diff(t[i])
        residuals = (np.diff(x[i]) - rate * dt) / dt.mean()
        se, dof = batch_se(residuals)
    if logged is None:
        quantisation = quantisation_step(x) / (math.sqrt(6.0) * span)
        timing = abs(rate) * math.sqrt(2.0) * timing_scatter_s(t) / span
    else:
        quantisation, timing = quantisation_u(logged[0], float(np.std(logged[1]))), 0.0
    stats = QuantityStats(mean=rate, std=spread, se=se, n=int(t.size),
                          n_eff=_n_eff(dof, t.size), unit=UNITS[key])
    return RateEstimate(stats, dof, quantisation, timing, residuals, source)


def _n_eff(dof: float, n: int) -> float:
    """Effective samples of a statistical term with ``dof`` degrees of freedom (``n``, the
    samples, where it has none: no batches)."""
    return dof + 1.0 if math.isfinite(dof) else float(n)


def slip_sensitivities(surface_mps: float, velocity_mps: float) -> tuple[float, float]:
    """``(ds/d(r w), ds/dv)`` of the spec slip (module doc)."""
    if surface_mps >= velocity_mps:
        return velocity_mps / surface_mps**2, -1.0 / surface_mps
    return 1.0 / velocity_mps, -surface_mps / velocity_mps**2


def window_slip(omega: RateEstimate, velocity: RateEstimate, radius_m: float,
                spread: float) -> RateEstimate | None:
    """The spec slip of the window rates and its terms (module doc); None where both speeds
    are 0 (slip undefined)."""
    surface, v = radius_m * omega.stats.mean, velocity.stats.mean
    value = float(spec_slip(np.array([surface]), np.array([v]), 0.0)[0])
    if not math.isfinite(value):
        return None
    c_surface, c_v = slip_sensitivities(surface, v)
    c_w = c_surface * radius_m
    se, dof, residuals = 0.0, math.inf, None
    if omega.residuals is not None and velocity.residuals is not None:
        residuals = c_w * omega.residuals + c_v * velocity.residuals
        se, dof = batch_se(residuals)
    quantisation = math.hypot(c_w * omega.quantisation_u, c_v * velocity.quantisation_u)
    timing = math.hypot(c_w * omega.timing_u, c_v * velocity.timing_u)
    n = min(omega.stats.n, velocity.stats.n)
    stats = QuantityStats(mean=value, std=spread, se=se, n=n, n_eff=_n_eff(dof, n), unit="1")
    return RateEstimate(stats, dof, quantisation, timing, residuals,
                        f"{omega.source}, {velocity.source}")
