"""Uncertainty budget of every run quantity (GUM, JCGM 100:2008): the terms, their
combination, the effective degrees of freedom and the 95 % expanded uncertainty.

Terms (standard uncertainties in the quantity's unit, each with its degrees of freedom):

- ``statistical``: the window's autocorrelation-corrected SE (``run_results.stats``),
  ``nu = n_eff - 1`` (Type A, GUM 4.2). For the rates (slip, travel velocity, wheel speed),
  which come from the window's displacements (``run_results.rates``), the batch-means SE of
  their displacements with its lag-1 autocovariance (``run_results.stats.batch_se``,
  Satterthwaite degrees of freedom): it sees a slow ripple of the drives, which an
  autocorrelation sum ends before. The other grousered quantities' by whole-pitch overlapping batch
  means with the wave's end effect separated (``run_results.stats.pitch_batch_means_se``):
  a real grouser wave wanders in phase (passage by passage) but averages to zero over each
  pitch, so it reaches the window mean only at the window's ends, while batch means count
  it at every batch end. The load cells' drift inside the window, a walk whose window mean
  the ``zero_drift`` bridge below already holds, is left out of these batch means once its
  diffusion is known (:class:`BatchStatistical`, ``run_results.stats.PitchBatches.se``).
- ``zero_drift``: the load cells' zero at the window, from the rest readings
  (``run_results.rest_readings``). DP, torque and side force read zero at rest; the zero is
  taken as linear in time between the two rests and subtracted (the ``correction``, GUM
  3.2.3). ``fz`` carries the wheel's actual load at rest, which is what it measures, so only
  its change between the rests is drift: the line starts at zero at the first rest (the
  spec's ``swt.zero`` stays its absolute zero; taking the set load as the rest value would
  make the measured load equal the set load by construction, and hide a saturated cell).
  Its uncertainty: the rests' SEs, and the drift's
  departure from the line over the window, modelled as a Brownian bridge between the rests
  (variance ``beta sigma^2 T`` of its window mean, :func:`bridge_factor`). The diffusion
  ``sigma^2`` of each cell is pooled over the runs of a campaign from their changes between
  the rests, ``sum(D^2 - se0^2 - se1^2) / sum(T)`` (:func:`pooled_diffusion`, one degree of
  freedom per run, GUM 4.2.4); a run alone has only its own ``D^2 / T``, one degree of freedom.
  Without two rests nothing is subtracted and the term is listed as not measured
  (``swt.zero`` alone says nothing about the drift since the zeroing). ``fz``'s zero is
  ``swt.zero``'s, taken with the wheel lifted before the run: its drift from that zeroing to
  the first rest is a random walk with the same diffusion over the zero's age, variance
  ``sigma^2 (E[age] + t_rest)`` (``zero_age_s``: the lab's stated longest time from the
  zeroing to a run's start, ``zero_age_min_s`` the shortest, 0 if not stated; the age is
  taken as rectangular between them, GUM 4.3.7, :attr:`BudgetParams.zero_age_mean_s`;
  ``zero_age_s`` not stated: listed as not measured). The other cells are re-zeroed at the
  rests.
- ``calibration``: ``gain_rel_u`` times what the gain scales (the mean) and, where the
  zero is not re-measured (``fz``, or no rests), ``offset_u`` (the spec's optional
  ``swt.calibration`` keys; not stated: not measured).
- ``quantisation``: of a step ``q`` read from the samples, ``q/sqrt(12)`` damped by
  ``exp(-2 pi^2 s^2 / q^2)`` for samples spread by ``s`` (dithered by their own noise: the
  first harmonic of the quantiser's mean error for Gaussian input, Widrow, Kollar & Liu 1996,
  IEEE Trans. Instrum. Meas. 45(2) 353; ``run_results.rest_readings.quantisation_u``); load
  cells and the suspension arm. The rates: the encoders' step in the window's two end
  values (local lines), ``(q/sqrt(12)) sqrt(h_0 + h_B) / T`` with ``h`` their leverages
  (``run_results.rates``), propagated to slip.
- ``timing``: the rates' time stamps, scattered by ``sigma_t`` measured from the stream's
  intervals, in the same end values: ``|rate| sigma_t sqrt(h_0 + h_B) / T``
  (``run_results.rates``), propagated to slip.
- ``phase_sampling``: a sensor sampling a sharp-edged grouser wave only ``m`` times a period
  sees few of its phases; the rectangle rule over a period errs by at most ``drop / (2 m)``
  for a jump ``drop`` (the largest step between adjacent phase bins of the waveform), a
  bound taken as rectangular (GUM 4.3.7). Load cells and the suspension arm, with grousers.
- ``clock``: the loggers' rate error, rectangular within ``+-clock_rate_bound_ppm`` (the
  logger's stated clock tolerance), relative on speeds, ``(1 - |s|) sqrt(2) u`` on slip (the
  wheel and sled encoders' clocks apart: ``|ds/d ln(r w)| = |ds/d ln v| = 1 - |s|`` for
  both the driving and the skid definitions).

Combined: root sum of squares of independent terms (GUM 5.1.2); effective degrees of freedom
by Welch-Satterthwaite (GUM G.4.1); ``k`` the Student-t 97.5 % point (GUM G.3.2), or, with a
rectangular clock term, the 97.5 % point of its convolution with the rest taken as normal
(scaled by the t-factor), so a dominant rectangle is not given a normal's tails.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace

import numpy as np
from scipy import optimize, special

from run_results.native import MIN_SAMPLES_PER_BIN, channel_samples, hub_samples
from run_results.phase_average import phase_average
from run_results.rest_readings import RestReadings, quantisation_u, resolution
from run_results.stats import PitchBatches, QuantityStats
from swtlab_base.domain.results import UNCERTAINTY_TERMS as TERMS
from swtlab_base.order_stats import median

#: quantity -> (load-cell column, divide by the wheel radius?) for the single-cell quantities
CELL_OF = {"dp_n": ("dp_n", False), "torque_nm": ("ty_nm", False),
           "thrust_n": ("ty_nm", True), "wheel_load_n": ("fz_n", False),
           "side_force_n": ("fy_n", False)}
#: spec topic and field of each load-cell column (for ``swt.calibration`` uncertainties)
FIELD_OF = {"dp_n": ("/tether/force", "dp"), "ty_nm": ("/hub/wrench", "ty"),
            "fz_n": ("/hub/wrench", "fz"), "fy_n": ("/hub/wrench", "fy")}
SPEEDS = ("travel_velocity_mps", "wheel_omega_radps")
#: the loggers' clock tolerance assumed where none is stated (a common quartz class)
DEFAULT_CLOCK_PPM = 100.0
INF = math.inf


@dataclass(frozen=True)
class BudgetParams:
    """What the budget is told about the rig: the loggers' clock tolerance (ppm, bound; None:
    not stated, :data:`DEFAULT_CLOCK_PPM` is used and the budget says so) and the age of the
    load cells' zero at a run's start (s: ``zero_age_s`` the longest, None: not stated,
    module doc; ``zero_age_min_s`` the shortest, None: 0)."""

    clock_rate_bound_ppm: float | None = None
    zero_age_s: float | None = None
    zero_age_min_s: float | None = None

    def __post_init__(self) -> None:
        for name in ("clock_rate_bound_ppm", "zero_age_s", "zero_age_min_s"):
            value = getattr(self, name)
            if value is not None and not (math.isfinite(value) and value >= 0):
                raise ValueError(f"{name} {value} must be >= 0")
        if self.zero_age_min_s is not None and not (self.zero_age_s is not None
                                                    and self.zero_age_min_s <= self.zero_age_s):
            raise ValueError(f"zero_age_min_s {self.zero_age_min_s} needs zero_age_s >= it "
                             f"(zero_age_s {self.zero_age_s})")

    @property
    def zero_age_mean_s(self) -> float:
        """The expected age of the zero at a run's start: only its bounds are stated, so the
        age is taken as rectangular between them (GUM 4.3.7), whose mean is their midpoint.
        A walk of diffusion ``sigma^2`` over an age ``A`` has mean 0 and variance
        ``sigma^2 A`` given ``A``; over the unknown age (law of total variance) its variance
        is ``sigma^2 E[A]``, so this mean, not the longest age, is the walk's time."""
        if self.zero_age_s is None:
            return 0.0
        return (self.zero_age_s + (self.zero_age_min_s or 0.0)) / 2.0

    @property
    def clock_ppm(self) -> float:
        return DEFAULT_CLOCK_PPM if self.clock_rate_bound_ppm is None else self.clock_rate_bound_ppm

    @property
    def clock_missing(self) -> tuple[str, ...]:
        return () if self.clock_rate_bound_ppm is not None else (
            f"clock tolerance (not stated in swtlab.toml [uncertainty]: {DEFAULT_CLOCK_PPM:g} "
            "ppm assumed)",)

    def to_dict(self) -> dict:
        return {"clock_rate_bound_ppm": self.clock_rate_bound_ppm, "zero_age_s": self.zero_age_s,
                "zero_age_min_s": self.zero_age_min_s}


@dataclass(frozen=True)
class Term:
    """One standard uncertainty with its degrees of freedom; ``rectangular``: a bound."""

    u: float
    dof: float = INF
    rectangular: bool = False


@dataclass(frozen=True)
class DriftPart:
    """A load cell's share of a quantity's zero: ``weight`` (quantity per cell unit), the
    rests' means term (cell units), the time between the rests ``span_s``, the bridge factor
    ``beta`` of the window, the run's own change ``change`` between the rests and the time
    ``age_s`` from the zeroing to the first rest over which the zero drifted unseen (0: the
    cell is re-zeroed at the rests)."""

    column: str
    weight: float
    means: Term
    span_s: float
    beta: float
    change: float
    age_s: float = 0.0

    def diffusion(self, pooled: dict[str, Term]) -> Term:
        """The cell's drift diffusion (per s): the campaign's pooled one where given, else
        the run's own ``D^2 / T`` (one degree of freedom)."""
        return pooled.get(self.column, Term(self.change**2 / self.span_s, 1.0))

    def term(self, diffusion: dict[str, Term]) -> Term:
        """The zero-drift term, with the cell's pooled diffusion (per s) where given."""
        sigma2 = self.diffusion(diffusion)
        walk = (self.beta * self.span_s + self.age_s) * max(sigma2.u, 0.0)
        return _rss([Term(abs(self.weight) * self.means.u, self.means.dof),
                     Term(abs(self.weight) * math.sqrt(walk), sigma2.dof)])


@dataclass(frozen=True)
class BatchStatistical:
    """A statistical term from whole-pitch batch means (``run_results.stats.PitchBatches``),
    ``fallback`` (the autocorrelation SE) where they resolve nothing."""

    batches: PitchBatches
    fallback: Term

    def term(self, walk_per_s: float = 0.0) -> Term:
        """With the load cells' drift, a walk of ``walk_per_s`` (quantity units^2 per s) in
        the signal, left out of the batch means: the zero-drift term's bridge holds its
        wander inside the window (module doc)."""
        se, dof = self.batches.se(walk_per_s)
        return Term(se, dof) if se > 0 else self.fallback


@dataclass(frozen=True)
class QuantityBudget:
    """One quantity's budget: the correction added to the window mean, the terms, what was
    not measured, and the combined, effective-dof, coverage factor and expanded values.
    ``drift``: the load cells' zero parts, from which the ``zero_drift`` term is made with
    ``diffusion`` (column -> pooled ``sigma^2`` per s as a :class:`Term`; empty: each run's own);
    ``batches``: where given, the ``statistical`` term, with the same drift's walk left out."""

    unit: str
    correction: float
    terms: dict[str, Term]
    not_measured: tuple[str, ...] = ()
    drift: tuple[DriftPart, ...] = ()
    diffusion: dict[str, Term] = field(default_factory=dict)
    batches: BatchStatistical | None = None
    u: float = field(init=False)
    dof: float = field(init=False)
    k: float = field(init=False)

    def __post_init__(self) -> None:
        terms = dict(self.terms)
        if self.drift:
            terms["zero_drift"] = _rss([p.term(self.diffusion) for p in self.drift])
        if self.batches is not None:
            walk = sum(p.weight**2 * max(p.diffusion(self.diffusion).u, 0.0) for p in self.drift)
            terms["statistical"] = self.batches.term(walk)
        object.__setattr__(self, "terms", terms)
        u, dof, k = combine(list(self.terms.values()))
        object.__setattr__(self, "u", u)
        object.__setattr__(self, "dof", dof)
        object.__setattr__(self, "k", k)

    @property
    def u95(self) -> float:
        return self.k * self.u

    def to_dict(self) -> dict:
        """JSON-ready: correction, ``u_<term>`` (None: not in the budget), u, dof (None:
        infinite), k, u95, not_measured."""
        return {"unit": self.unit, "correction": self.correction,
                **{f"u_{name}": (self.terms[name].u if name in self.terms else None)
                   for name in TERMS},
                "u": self.u, "dof": None if math.isinf(self.dof) else self.dof, "k": self.k,
                "u95": self.u95, "not_measured": list(self.not_measured)}


def _rss(terms: list[Term]) -> Term:
    """Root sum of squares, Welch-Satterthwaite degrees of freedom."""
    u2 = sum(t.u**2 for t in terms)
    den = sum(t.u**4 / t.dof for t in terms if t.u > 0 and not math.isinf(t.dof))
    return Term(math.sqrt(u2), u2**2 / den if den > 0 else INF)


def _t97(dof: float) -> float:
    return 1.959963984540054 if math.isinf(dof) else float(special.stdtrit(max(dof, 1.0), 0.975))


SQRT_2PI = math.sqrt(2.0 * math.pi)


def rect_normal_quantile(a: float, sigma: float, p: float = 0.975) -> float:
    """``x`` with ``P(X <= x) = p`` for ``X = N(0, sigma^2) + U(-a, a)`` (exact CDF:
    ``sigma/(2a) [G((x+a)/sigma) - G((x-a)/sigma)]``, ``G(z) = z Phi(z) + phi(z)``)."""
    if a <= 0:
        return float(special.ndtri(p)) * sigma
    if sigma <= 0:
        return a * (2 * p - 1)

    def cdf(x: float) -> float:
        g = lambda z: z * special.ndtr(z) + math.exp(-z * z / 2.0) / SQRT_2PI  # noqa: E731
        return sigma / (2 * a) * (g((x + a) / sigma) - g((x - a) / sigma)) - p
    hi = a + 10 * sigma
    if not cdf(hi) > 0:  # sigma so small against a that the difference cancels: rectangular
        return a * (2 * p - 1)
    return float(optimize.brentq(cdf, 0.0, hi))


def combine(terms: list[Term]) -> tuple[float, float, float]:
    """``(u_c, nu_eff, k)`` of independent terms (module doc)."""
    total = _rss(terms)
    if total.u == 0:
        return 0.0, INF, _t97(INF)
    rect = [t for t in terms if t.rectangular]
    if len(rect) != 1:
        return total.u, total.dof, _t97(total.dof)
    rest = _rss([t for t in terms if not t.rectangular])
    sigma = rest.u * _t97(rest.dof) / _t97(INF)
    return total.u, total.dof, rect_normal_quantile(rect[0].u * math.sqrt(3), sigma) / total.u


def bridge_factor(p: float, q: float) -> float:
    """Variance of the mean over ``[p, q]`` of a standard Brownian bridge on ``[0, 1]``
    (``cov = min(u, v) - u v``): ``[q^3/3 - q p^2 + 2p^3/3 - ((q^2 - p^2)/2)^2] / (q - p)^2``."""
    p, q = min(max(p, 0.0), 1.0), min(max(q, 0.0), 1.0)
    if q <= p:
        return p * (1 - p)
    double = -(q**3 - p**3) / 6 + q * (q**2 - p**2) / 2 - p**2 * (q - p) / 2
    return max(double - ((q**2 - p**2) / 2) ** 2, 0.0) / (q - p) ** 2


@dataclass(frozen=True)
class ZeroAtWindow:
    """A cell's zero over the window: value and its drift part, or why it is not measured."""

    zero: float
    part: DriftPart | None
    missing: str | None = None


def zero_at_window(rests: RestReadings | None, column: str, window_s: tuple[float, float],
                   rest_value: float | None, zero_age_mean_s: float = 0.0) -> ZeroAtWindow:
    """The zero of ``column`` over the window: the rests' means less ``rest_value`` (what the
    cell carries at rest; None: not known, only the change since the first rest is drift,
    and the zero, on average ``zero_age_mean_s`` old at the run's start
    (:attr:`BudgetParams.zero_age_mean_s`), drifted unseen until the first rest), linear in
    time between the rests, with its uncertainty (module doc)."""
    if rests is None or column not in rests.before or column not in rests.after:
        return ZeroAtWindow(0.0, None, "zero drift (no rest readings before and after the drive)")
    b, a = rests.before[column], rests.after[column]
    span = a.t_s - b.t_s
    w = ((window_s[0] + window_s[1]) / 2 - b.t_s) / span
    reference = b.stats.mean if rest_value is None else rest_value
    d0, d1 = b.stats.mean - reference, a.stats.mean - reference
    zero = d0 + (d1 - d0) * w
    # the zero is (1 - w) d0 + w d1; fz's d0 = 0 is the first rest itself, so its zero
    # w (mean_after - mean_before) carries the first rest's noise with weight w, not 1 - w
    w_before = (1 - w) if rest_value is not None else w
    means = _rss([Term(w_before * b.stats.se, max(b.stats.n_eff - 1, 1)),
                  Term(w * a.stats.se, max(a.stats.n_eff - 1, 1))])
    beta = bridge_factor((window_s[0] - b.t_s) / span, (window_s[1] - b.t_s) / span)
    age = 0.0 if rest_value is not None else zero_age_mean_s + max(b.t_s, 0.0)
    return ZeroAtWindow(zero, DriftPart(column, 1.0, means, span, beta, d1 - d0, age))


def pooled_diffusion(rest_records: list[dict]) -> dict[str, Term]:
    """Per cell, the drift diffusion (per s) pooled over runs, ``sum(D^2 - se0^2 - se1^2) /
    sum(T)`` with one degree of freedom per run; ``rest_records``: the runs'
    ``RestReadings.to_dict()`` (None for a run without rests is skipped)."""
    sums: dict[str, list[float]] = {}
    for record in rest_records:
        if not record:
            continue
        for column, b in record["before"].items():
            a = record["after"].get(column)
            if a is None or a["t_s"] <= b["t_s"]:
                continue
            acc = sums.setdefault(column, [0.0, 0.0, 0])
            acc[0] += (a["mean"] - b["mean"]) ** 2 - b["se"] ** 2 - a["se"] ** 2
            acc[1] += a["t_s"] - b["t_s"]
            acc[2] += 1
    return {c: Term(max(num, 0.0) / span, float(runs)) for c, (num, span, runs) in sums.items()}


def phase_sampling(t_s: np.ndarray, y: np.ndarray, frequency_hz: float | None) -> Term | None:
    """Bound ``drop / (2 m)`` on the window mean of a periodic wave sampled ``m`` times a
    period (module doc), as a rectangular term; None without a frequency or samples."""
    if not frequency_hz or y.size < 2:
        return None
    average = phase_average(t_s, y, frequency_hz)
    if y.size < MIN_SAMPLES_PER_BIN * average["bins"]:
        return None
    wave = average["waveform"][np.isfinite(average["waveform"])]
    if wave.size < 2:
        return None
    drop = float(np.max(np.abs(np.diff(np.append(wave, wave[0])))))
    per_period = 1.0 / (frequency_hz * float(median(np.diff(t_s))))
    return Term(drop / (2.0 * per_period) / math.sqrt(3.0), rectangular=True)


def _statistical(s: QuantityStats) -> Term:
    return Term(float(s.se), max(float(s.n_eff) - 1.0, 1.0))


def _cell_budget(run, rests, window_s, key: str, s: QuantityStats,
                 frequency_hz: float | None, params: BudgetParams,
                 batch: PitchBatches | None) -> QuantityBudget:
    """Budget of a single-cell quantity (thrust: the torque cell over the radius)."""
    column, per_radius = CELL_OF[key]
    scale = run.metadata.wheel.radius_m if per_radius else 1.0
    absolute = column != "fz_n"  # fz at rest reads the actual load, which it measures
    z = zero_at_window(rests, column, window_s, 0.0 if absolute else None,
                       params.zero_age_mean_s)
    missing = [] if z.missing is None else [z.missing]
    if z.part is not None and not absolute and params.zero_age_s is None:
        missing.append("fz zero drift since the zeroing (zero_age_s not stated in "
                       "swtlab.toml [uncertainty])")
    terms = {"statistical": _statistical(s)}
    drift = () if z.part is None else (replace(z.part, weight=1.0 / scale),)
    mean = s.mean - z.zero / scale
    gain_u, offset_u = run.metadata.calibration_u.get(FIELD_OF[column], (None, None))
    if gain_u is None:
        missing.append("calibration (no gain_rel_u / offset_u in swt.calibration)")
    else:
        offset = 0.0 if drift and absolute else offset_u / scale
        terms["calibration"] = Term(math.hypot(gain_u * abs(mean), offset))
    native = channel_samples(run, column, *window_s)
    if native is not None:
        terms["quantisation"] = Term(quantisation_u(resolution(native[1]) / scale, s.std))
        sampling = phase_sampling(native[0], native[1] / scale, frequency_hz)
        if sampling is not None:
            terms["phase_sampling"] = sampling
    return QuantityBudget(s.unit, -z.zero / scale, terms, tuple(missing), drift,
                          batches=_batch_statistical(s, batch))


def _sum_budget(s: QuantityStats, parts: list[tuple[QuantityBudget, float]],
                batch: PitchBatches | None) -> QuantityBudget:
    """Budget of ``sum(sign * part)`` with its own statistical term (cells independent)."""
    terms = {"statistical": _statistical(s)}
    for name in ("calibration", "quantisation", "phase_sampling"):
        found = [Term(abs(sign) * b.terms[name].u, b.terms[name].dof) for b, sign in parts
                 if name in b.terms]
        if found:
            terms[name] = _rss(found)
    drift = tuple(replace(p, weight=sign * p.weight) for b, sign in parts for p in b.drift)
    missing = tuple(sorted({m for b, _ in parts for m in b.not_measured}))
    return QuantityBudget(s.unit, sum(sign * b.correction for b, sign in parts), terms,
                          missing, drift, batches=_batch_statistical(s, batch))


def _batch_statistical(s: QuantityStats, batch: PitchBatches | None) -> BatchStatistical | None:
    """The whole-pitch batch-means statistical term, the autocorrelation one where they
    resolve nothing; None without batches (the autocorrelation term alone)."""
    return None if batch is None else BatchStatistical(batch, _statistical(s))


def _rate_terms(rate, clock_rel_u: float) -> dict[str, Term]:
    """A rate's terms (``run_results.rates.RateEstimate``): statistical, quantisation, timing,
    and the clock, ``clock_rel_u`` (standard, of a rectangle) times the rate for a speed."""
    return {"statistical": Term(rate.stats.se, rate.dof),
            "quantisation": Term(rate.quantisation_u), "timing": Term(rate.timing_u),
            "clock": Term(clock_rel_u, rectangular=True)}


def run_budget(run, window_s: tuple[float, float], quantities: dict[str, QuantityStats],
               rests: RestReadings | None, params: BudgetParams | None = None,
               batches: dict | None = None, frequency_hz: float | None = None,
               rates: dict | None = None) -> tuple[dict[str, QuantityStats],
                                                   dict[str, QuantityBudget]]:
    """``(corrected quantities, budgets)``: every quantity's budget and its mean with the
    re-zeroing correction added (module doc); ``batches``: the grousered quantities'
    ``run_results.stats.PitchBatches``; ``frequency_hz``: the grouser passing frequency
    (None: no grousers); ``rates``: speeds and slip from displacements
    (``run_results.rates.RateEstimate``)."""
    params = params or BudgetParams()
    batches, rates = batches or {}, rates or {}
    budgets: dict[str, QuantityBudget] = {}
    for key, s in quantities.items():
        if key in CELL_OF:
            budgets[key] = _cell_budget(run, rests, window_s, key, s, frequency_hz, params,
                                        batches.get(key))
    if "resistance_n" in quantities and "thrust_n" in budgets and "dp_n" in budgets:
        budgets["resistance_n"] = _sum_budget(quantities["resistance_n"],
                                              [(budgets["thrust_n"], 1.0),
                                               (budgets["dp_n"], -1.0)],
                                              batches.get("resistance_n"))
    for key in ("hub_height_m", "sinkage_m"):
        if key in quantities:
            budgets[key] = _height_budget(run, key, quantities[key], window_s, budgets,
                                          frequency_hz, batches.get(key))
    clock_rel = params.clock_ppm * 1e-6 / math.sqrt(3)
    for key in SPEEDS:
        if key in rates:
            budgets[key] = QuantityBudget(
                rates[key].stats.unit, 0.0,
                _rate_terms(rates[key], abs(rates[key].stats.mean) * clock_rel),
                params.clock_missing)
    if "slip" in rates:
        s = rates["slip"].stats
        terms = _rate_terms(rates["slip"], 0.0)
        # two independent clocks: the sum of two rectangles is not one
        terms["clock"] = Term((1 - min(abs(s.mean), 1.0)) * math.sqrt(2) * clock_rel)
        budgets["slip"] = QuantityBudget(s.unit, 0.0, terms, params.clock_missing)
    for key, s in quantities.items():
        budgets.setdefault(key, QuantityBudget(s.unit, 0.0, {"statistical": _statistical(s)},
                                               ("only the window statistics",)))
    corrected = {k: replace(s, mean=s.mean + budgets[k].correction) if budgets[k].correction
                 else s for k, s in quantities.items()}
    return corrected, budgets


def _height_budget(run, key: str, s: QuantityStats, window_s, budgets: dict,
                   frequency_hz: float | None,
                   batch: PitchBatches | None) -> QuantityBudget:
    """Hub height: statistics and the arm encoder's quantisation; sinkage of a flexible wheel
    also the wheel load's zero and calibration through ``fz / (1000 k)``."""
    terms = {"statistical": _statistical(s)}
    hub = hub_samples(run, *window_s)
    if hub is not None:
        terms["quantisation"] = Term(quantisation_u(resolution(hub[1]), s.std))
        sampling = phase_sampling(hub[0], hub[1], frequency_hz)
        if sampling is not None:
            terms["phase_sampling"] = sampling
    stiffness = run.metadata.wheel.stiffness_n_per_mm
    batches = _batch_statistical(s, batch)
    if key == "hub_height_m" or stiffness is None or "wheel_load_n" not in budgets:
        return QuantityBudget(s.unit, 0.0, terms, batches=batches)
    load = budgets["wheel_load_n"]
    scale = -1.0 / (1000.0 * stiffness)
    if "calibration" in load.terms:
        terms["calibration"] = Term(load.terms["calibration"].u * abs(scale))
    return QuantityBudget(s.unit, load.correction * scale, terms, load.not_measured,
                          tuple(replace(p, weight=scale * p.weight) for p in load.drift),
                          batches=batches)


def with_diffusion(budgets: dict[str, QuantityBudget],
                   diffusion: dict[str, Term]) -> dict[str, QuantityBudget]:
    """The budgets with the campaign's pooled drift diffusion (:func:`pooled_diffusion`)."""
    return {k: replace(b, diffusion=diffusion) if b.drift else b for k, b in budgets.items()}



def pool_drift(results: list) -> list:
    """``run_results.RunResult`` s with the drift diffusion pooled over the rest readings of
    the runs of each campaign (``RunResult.campaign``, one rig's cells;
    :func:`pooled_diffusion`); the means are unchanged."""
    campaigns: dict = {}
    for r in results:
        campaigns.setdefault(r.campaign, []).append(
            r.corrections.get("rest_readings"))
    diffusion = {c: pooled_diffusion(records) for c, records in campaigns.items()}
    return [replace(r, uncertainty=with_diffusion(r.uncertainty,
                                                  diffusion[r.campaign]))
            for r in results]
