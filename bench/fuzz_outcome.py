"""Run one fuzzed input through the pipeline the way ``swtlab process`` does, under a time
limit, and say what came of it: a clean refusal, a result, or one of the three faults the
reliability bench counts (unhandled exception, hang, nonsense stored as ok).

"Nonsense" is judged here from physics alone, not from the flags of the code under test: a
run marked ``ok`` whose statistics are not finite, whose load-cell quantities have an SE of
0, or whose values no
single-wheel test can give (|slip| > 1, wheel load <= 0 or over 10 times the set load,
|DP| or |thrust| over 3 times the measured load, |torque| over 3 load-radii, sinkage below
-1 mm or over the wheel diameter, speeds over 10 m/s or 1000 rad/s).
"""

from __future__ import annotations

import math
import signal
import tempfile
from dataclasses import dataclass
from pathlib import Path

from bench.fuzz_inputs import Case
from swtlab.pipeline.campaign import FailureKind
from swtlab.pipeline.process import ProcessSettings, process_file

TIME_LIMIT_S = 20.0
#: quantities measured by load cells: their noise never gives a window an SE of 0 (an
#: encoder's may hold one quantisation step)
LOAD_CELL = ("wheel_load_n", "dp_n", "torque_nm", "thrust_n", "resistance_n", "side_force_n")


class Hang(BaseException):
    """Raised by the alarm when an input runs past its time limit (not an ``Exception``, so
    no ``except Exception`` in the pipeline swallows it)."""


@dataclass(frozen=True)
class Outcome:
    """``kind``: ``refused``, ``ok``, ``flagged``, ``no_stable_phase``, ``unhandled``,
    ``hang`` or ``nonsense``; ``detail``: the reason."""

    kind: str
    detail: str = ""


def _alarm(signum, frame):  # signal handler signature
    raise Hang()


def nonsense(result) -> str | None:
    """Why an ``ok`` result is physically impossible, or None."""
    q = {k: v for k, v in result.quantities.items()}
    for name, stats in q.items():
        values = (stats.mean, stats.std, stats.se)
        if not all(v is not None and math.isfinite(v) for v in values):
            return f"{name}: non-finite statistic {values}"
        if stats.se == 0 and name in LOAD_CELL:
            return f"{name}: SE of 0"
    radius, load_set = result.wheel.radius_m, result.condition.load_set_n

    def mean(name):
        return q[name].mean if name in q else None

    load = mean("wheel_load_n")
    checks = [
        ("slip", lambda v: abs(v) <= 1.0),
        ("image_slip", lambda v: abs(v) <= 1.0),
        ("wheel_load_n", lambda v: 0.0 < v <= 10.0 * load_set),
        ("sinkage_m", lambda v: -1e-3 <= v <= 2.0 * radius),
        ("travel_velocity_mps", lambda v: abs(v) <= 10.0),
        ("wheel_omega_radps", lambda v: abs(v) <= 1000.0),
    ]
    scale = abs(load) if load else load_set
    checks += [(k, lambda v: abs(v) <= 3.0 * scale) for k in ("dp_n", "thrust_n")]
    checks.append(("torque_nm", lambda v: abs(v) <= 3.0 * scale * radius))
    for name, fine in checks:
        value = mean(name)
        if value is not None and not fine(value):
            return f"{name} = {value:.4g} impossible (set load {load_set:g} N, r {radius:g} m)"
    return None


def run_case(case: Case, time_limit_s: float = TIME_LIMIT_S) -> Outcome:
    """Write ``case`` to a temporary folder and process it (no soil flow), within
    ``time_limit_s`` (SIGALRM; main thread only)."""
    with tempfile.TemporaryDirectory(prefix="swtlab-fuzz-") as tmp:
        previous = signal.signal(signal.SIGALRM, _alarm)
        signal.setitimer(signal.ITIMER_REAL, time_limit_s)
        try:
            try:
                path, cmap = case.write(Path(tmp))
            except Exception as error:  # the map itself may be unparseable
                return Outcome("refused", f"not written: {type(error).__name__}")
            settings = _settings(cmap)
            if isinstance(settings, Outcome):
                return settings
            done = process_file(path, settings)
        except Hang:
            return Outcome("hang", f"over {time_limit_s:g} s")
        finally:
            signal.setitimer(signal.ITIMER_REAL, 0)
            signal.signal(signal.SIGALRM, previous)
    # the pipeline's own clean refusal is ingest's, one line naming file and channel
    wild = [f for f in done.failures if f.kind is not FailureKind.REFUSED]
    if wild:
        return Outcome("unhandled", f"{wild[0].stage}: {wild[0].reason}")
    if done.result is None:
        return Outcome("refused", done.failures[0].reason if done.failures else "")
    if done.result.status == "ok":
        why = nonsense(done.result)
        if why:
            return Outcome("nonsense", why)
    return Outcome(done.result.status, "; ".join(done.result.flags)[:200])


def _settings(cmap: str | None):
    """The batch's settings; a channel map the CLI refuses is a clean refusal (exit 3)."""
    import ingest

    try:
        if cmap is not None:
            ingest.load_channel_map(cmap)
        return ProcessSettings(channel_map=cmap, max_frames=0)
    except ingest.IngestError as error:
        return Outcome("refused", str(error))
    except Exception as error:  # anything else from a map is a fault
        return Outcome("unhandled", f"channel map: {type(error).__name__}: {error}")
