"""Wheel angular speed, travel velocity and slip from the window's displacements.

A rate over the window is its displacement over the window's time, ``rate = (x(t_1) -
x(t_0)) / (t_1 - t_0)``, of the encoder's position (the angle, the sled position) or, where
the source logs the rate itself (a channel map's
``wheel_surface_speed_mps``, ``sled_velocity_mps``; ingest takes it over a derivative too),
the time integral of its native samples (trapezoids), i.e. their time-weighted mean. The
window is cut into :data:`BATCHES` equal spans; the position at each span end ``e_k`` is the
value there of a least-squares line through the native samples within half a span of it
(inside the window: one-sided at the window's two ends), a local regression of position on
time, so that no single reading's quantisation carries the rate. Slip is the spec's
definition applied to those two rates, ``s = (r w - v)/(r w)`` driving (``r w >= v``) and
``(r w - v)/v`` skid, ``r`` the wheel radius without grousers (``ingest.derive.slip``). The
mean of per-sample ratios ``1 - v/(r w)`` of quantised finite differences is not used: the
mean of a ratio of noisy quantities is not the ratio of their means (Jensen's inequality),
which biases it at low speed, where each sample's change is a count or two.

Uncertainty terms of a rate (GUM, JCGM 100:2008), in :class:`RateEstimate`:

- ``statistical`` (Type A): each span's displacement less ``rate`` times its duration,
  over the span, is a batch residual ``d_b`` (``sum d_b = 0``); their variance with the
  lag-1 autocovariance (``run_results.stats.batch_se``, Satterthwaite degrees of freedom)
  is that of the window rate: it sees the drives' slow ripple, and the reading errors at
  the span ends telescope. Single readings at the span ends made those errors dominate the
  residuals of a rig logging a few counts a sample (second rig, 48 Hz: their share 4 times
  the ripple's in variance), and the lag-1 estimate, which must then cancel them, came out
  non-positive in about one window in eight (slip covered 90.7 % on 600 runs); the local
  lines cut their variance by the samples they average.
- ``quantisation`` (Type B, GUM 4.3.7, F.2.2.1): a position read to a step ``q`` (the
  lattice its readings lie on, ``ingest.derive.quantisation_step``; the smallest difference
  of two readings is the motion per sample where that exceeds the step) errs
  uniformly within one step, ``u = q/sqrt(12)`` per reading. A line's value at ``e`` from
  ``N`` readings with independent errors of that size has ``u^2 = (q^2/12) h``, ``h = 1/N +
  (e - tbar)^2 / sum (t_i - tbar)^2`` its leverage there (``4/N`` or so at the end of a
  one-sided fit); the rate takes the window's two end values: ``u = (q/sqrt(12))
  sqrt(h_0 + h_B) / T``. (Readings of a moving encoder err by a sawtooth, whose mean over
  ``K`` counts errs by about ``q/K``, less than independent errors would: an upper bound.)
  A logged rate of
  step ``q``: the mean of its readings errs by ``q/sqrt(12)`` where the rate holds within a
  step (the same rounding every sample), less where its own spread ``s`` dithers it
  (``rest_readings.quantisation_u``: Widrow, Kollar & Liu 1996).
- ``timing`` (Type B): each time stamp scatters by ``sigma_t``, measured from the stream's
  regular intervals (those under 1.5 median intervals, dropped samples left out): two
  independent stamps make an interval of variance ``2 sigma_t^2``, so ``sigma_t =
  std(intervals)/sqrt(2)``; a stamp's error moves its reading by ``rate`` times it, so as
  quantisation, ``u = |rate| sigma_t sqrt(h_0 + h_B) / T``. (Scatter of the true sampling
  instants, correctly stamped, is no error: the term is then an upper bound.) A logged
  rate's mean weighs its samples by their intervals, to first order insensitive to stamp
  errors: no term.

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


def edge_values(t_s: np.ndarray, x: np.ndarray, edges_s: np.ndarray
                ) -> tuple[np.ndarray, np.ndarray]:
    """``(values, leverages)`` at ``edges_s`` (ascending, the window's span ends) of
    least-squares lines through the samples within half a span of each edge, inside the
    first and last edge (module doc); NaN where fewer than two samples are there."""
    half = np.diff(edges_s) / 2.0
    lo = edges_s - np.concatenate([[0.0], half])
    hi = edges_s + np.concatenate([half, [0.0]])
    first = np.searchsorted(t_s, lo, "left")
    last = np.searchsorted(t_s, hi, "left")
    last[-1] = np.searchsorted(t_s, hi[-1], "right")
    values, leverage = np.full(edges_s.size, np.nan), np.full(edges_s.size, np.nan)
    for k, (i, j) in enumerate(zip(first, last)):
        if j - i < 2:
            continue
        dt = t_s[i:j] - edges_s[k]
        mean_t, mean_x = dt.mean(), x[i:j].mean()
        sxx = float(((dt - mean_t) ** 2).sum())
        if not sxx > 0:
            continue
        slope = float(((dt - mean_t) * (x[i:j] - mean_x)).sum()) / sxx
        values[k] = mean_x - slope * mean_t
        leverage[k] = 1.0 / (j - i) + mean_t**2 / sxx
    return values, leverage


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
    x = x - x[0]
    span = float(end_s - start_s)
    edges = start_s + span * np.arange(batches + 1) / batches
    values, leverage = edge_values(t, x, edges)
    if not (span > 0 and np.isfinite(values[[0, -1]]).all()):
        return None
    rate = float((values[-1] - values[0]) / span)
    residuals, se, dof = None, 0.0, math.inf
    if np.isfinite(values).all():
        residuals = np.diff(values) / (span / batches) - rate
        se, dof = batch_se(residuals)
    ends = math.sqrt(leverage[0] + leverage[-1]) / span
    if logged is None:
        quantisation = quantisation_step(x) / math.sqrt(12.0) * ends
        timing = abs(rate) * timing_scatter_s(t) * ends
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
