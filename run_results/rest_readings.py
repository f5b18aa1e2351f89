"""Rest readings: the seconds at rest before and after the drive (raw-run spec, "What a run
contains in time"), where drawbar pull, torque and the horizontal forces read only offset,
drift and noise and ``fz`` reads the load.

The drive starts at the first native sample where the wheel or the sled encoder has left its
first reading by more than :data:`MOVE_STEPS` of its resolution, and ends at the last sample
where either still differs from its final reading by as much. The rests are the native
samples before the start and after the end, :data:`MARGIN_S` away from them; a rest shorter
than :data:`MIN_REST_S` is not used. Their means carry an autocorrelation-corrected SE
(``run_results.stats``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from run_results.stats import QuantityStats, quantity_stats

#: the encoders must move this many steps of their resolution to count as moving
MOVE_STEPS = 3
#: rest samples are kept this far from the drive's start and end (forces settle)
MARGIN_S = 0.3
#: a rest shorter than this is not used
MIN_REST_S = 0.5
#: channels whose rest readings are taken (canonical columns)
REST_CHANNELS = ("dp_n", "ty_nm", "fz_n", "fx_n", "fy_n")


@dataclass(frozen=True)
class Rest:
    """One channel's rest reading: mean time and statistics of its samples."""

    t_s: float
    stats: QuantityStats


@dataclass(frozen=True)
class RestReadings:
    """Drive span ``(start_s, end_s)`` and per channel the rests before and after (None when
    the run has none there)."""

    drive_s: tuple[float, float]
    before: dict[str, Rest]
    after: dict[str, Rest]

    def to_dict(self) -> dict:
        def part(rests: dict[str, Rest]) -> dict:
            return {c: {"t_s": r.t_s, "mean": r.stats.mean, "se": r.stats.se, "n": r.stats.n}
                    for c, r in rests.items()}
        return {"drive_start_s": self.drive_s[0], "drive_end_s": self.drive_s[1],
                "before": part(self.before), "after": part(self.after)}


def resolution(values) -> float:
    """The smallest step between distinct finite values (an ADC's or encoder's step; about 0
    for unquantised data)."""
    v = np.unique(np.asarray(values, float)[np.isfinite(values)])
    if v.size < 2:
        return 0.0
    steps = np.diff(v)
    steps = steps[steps > 1e-9 * float(np.max(np.abs(v)))]
    return float(steps.min()) if steps.size else 0.0


def quantisation_u(q: float, spread: float) -> float:
    """Standard uncertainty of the mean of readings rounded to a step ``q``: ``q/sqrt(12)``
    (one uniform rounding error, GUM F.2.2.1) damped by ``exp(-2 pi^2 s^2 / q^2)`` for
    readings spread by ``s`` (dithered by their own noise: the first harmonic of the
    quantiser's mean error for Gaussian input, Widrow, Kollar & Liu 1996, IEEE Trans.
    Instrum. Meas. 45(2) 353); 0 for ``q`` 0."""
    if q <= 0:
        return 0.0
    return q / math.sqrt(12) * math.exp(-2 * math.pi**2 * (spread / q) ** 2)


def _moving_span(t_s: np.ndarray, x: np.ndarray) -> tuple[float, float] | None:
    ok = np.isfinite(x)
    t_s, x = t_s[ok], x[ok]
    if x.size < 4:
        return None
    tol = MOVE_STEPS * max(resolution(x), 1e-12)
    away_first = np.flatnonzero(np.abs(x - x[0]) > tol)
    away_last = np.flatnonzero(np.abs(x - x[-1]) > tol)
    if not away_first.size:
        return None
    return float(t_s[away_first[0]]), float(t_s[away_last[-1]])


def drive_span(run) -> tuple[float, float] | None:
    """``(start_s, end_s)`` of the drive from the wheel and sled encoders, None when neither
    is logged as a position or neither moves."""
    spans = []
    for column in ("wheel_angle_rad", "sled_position_m"):
        for frame in run.streams.values():
            if column in frame.columns:
                span = _moving_span(frame["t_s"].to_numpy(), frame[column].to_numpy())
                if span is not None:
                    spans.append(span)
    if not spans:
        return None
    return min(s[0] for s in spans), max(s[1] for s in spans)


def _rest(t_s: np.ndarray, y: np.ndarray, inside: np.ndarray, unit: str) -> Rest | None:
    keep = inside & np.isfinite(y)
    if keep.sum() < 4 or np.ptp(t_s[keep]) < MIN_REST_S:
        return None
    stats = quantity_stats(y[keep], unit)
    return None if stats is None else Rest(t_s=float(np.mean(t_s[keep])), stats=stats)


def rest_readings(run) -> RestReadings | None:
    """The run's rest readings of :data:`REST_CHANNELS`, None without a drive span."""
    span = drive_span(run)
    if span is None:
        return None
    before, after = {}, {}
    for column in REST_CHANNELS:
        frame = next((f for f in run.streams.values() if column in f.columns), None)
        if frame is None:
            continue
        t, y = frame["t_s"].to_numpy(), frame[column].to_numpy()
        unit = "N*m" if column.endswith("_nm") else "N"
        first = _rest(t, y, t <= span[0] - MARGIN_S, unit)
        last = _rest(t, y, t >= span[1] + MARGIN_S, unit)
        if first is not None:
            before[column] = first
        if last is not None:
            after[column] = last
    return RestReadings(drive_s=span, before=before, after=after)


def ends_moving(run) -> str | None:
    """The flag of a run that rests before its drive and not after it: the raw-run spec's run
    ends at rest, so a file whose encoders still move at its last sample, after a rest reading
    at its start, was cut short (``ingest.cut_short``); None otherwise. A rest counts when it
    could give a rest reading (:data:`MIN_REST_S` beyond :data:`MARGIN_S`)."""
    from ingest.cut_short import message

    span = drive_span(run)
    if span is None:
        return None
    times = [frame["t_s"].to_numpy() for frame in run.streams.values() if len(frame)]
    t0, t1 = min(float(t[0]) for t in times), max(float(t[-1]) for t in times)
    rest = MARGIN_S + MIN_REST_S
    if span[0] - t0 < rest or t1 - span[1] >= rest:
        return None
    return message(run.source, t1, f"the run rests {span[0] - t0:.1f} s before its drive and "
                   f"{max(t1 - span[1], 0.0):.1f} s after it (a rest reading needs {rest:g} s): "
                   "its end-of-run rest reading is missing")
