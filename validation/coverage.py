"""Coverage of the uncertainty budgets against known truths (issue 18, docs/run-results.md).

Campaigns of varied conditions (speed control at random loads, slips and passes; towed and
free-sled runs) from either generator, processed by ``swtlab.process_campaign`` like a lab's,
then each run's ``mean +- u95`` is checked against its truth:

- ``virtual``: the virtual testbed (in-family: the estimators were built beside it); truth the
  law's steady values (wheel load: the set load; speeds: the noise-free window means);
- ``second``: the second rig (validation/second_rig, independent of the estimators), with the
  spec's calibration-uncertainty keys written; truth the caller's steady values (the shipped
  ``bb2_sand`` model, ``ModelTruth``);
- ``low_speed``: the same rig in its low-speed coarse-encoder mode
  (``validation.second_rig.low_speed_rig``: a 14-bit wheel encoder and the sled encoder at
  500 Hz), sled speeds 5-20 mm/s (log-uniform), where a wheel turns zero or one count a
  sample.

The campaign's ``swtlab.toml`` states the loggers' clock tolerance the way a lab states its
logger's datasheet value, and the shortest and longest time from zeroing the load cells to a
run's start the way a lab states its procedure: the generator's own bounds (200 ppm and 0 s
virtual: its drift starts at the run's start; 150 ppm and 30-180 s second rig).
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pandas as pd

import swtlab
import terramechanics as tm
from validation.model_truth import ModelTruth
from validation.second_rig import Rig, SensorModel, WheelGeometry, low_speed_rig, write_campaign
from validation.second_rig import RunCondition as RigCondition
from virtual_testbed import RunCondition, generate_campaign
from virtual_testbed.sample_campaign import SAMPLE_RATES
from virtual_testbed.sensors import SensorModel as VirtualSensors

#: the issue's quantities first, then the derived ones
QUANTITIES = ("dp_n", "torque_nm", "wheel_load_n", "slip", "sinkage_m", "resistance_n",
              "travel_velocity_mps", "thrust_n", "wheel_omega_radps")
GENERATORS = ("virtual", "second", "low_speed")
#: sled speeds of the ``low_speed`` generator (m/s, drawn log-uniform)
LOW_SPEEDS_MPS = (0.005, 0.02)


def _draws(n: int, seed: int, loads: tuple[float, float]):
    """``(kind, load, multipass, slip)`` of ``n`` runs: 70 % speed control (slip -0.2..0.7),
    15 % towed, 15 % free sled."""
    rng = np.random.default_rng(seed)
    for i in range(n):
        r, load = rng.random(), float(np.round(rng.uniform(*loads)))
        mp, slip = int(rng.integers(0, 3)), float(np.round(rng.uniform(-0.2, 0.7), 3))
        kind = "speed_control" if r < 0.7 else "towed" if r < 0.85 else "free_sled"
        yield i, kind, load, mp, slip


def _settings(folder: Path, clock_ppm: float, zero_age_s: tuple[float, float]) -> None:
    (folder / "swtlab.toml").write_text(f"[uncertainty]\nclock_rate_bound_ppm = {clock_ppm}\n"
                                        f"zero_age_min_s = {zero_age_s[0]}\n"
                                        f"zero_age_s = {zero_age_s[1]}\n")


def write_virtual(out: Path, n: int, seed: int, duration_s: float = 60.0) -> dict[str, dict]:
    """A virtual-testbed campaign in ``out/campaign`` (CSV runs); returns the truths."""
    conds = []
    for i, kind, load, mp, slip in _draws(n, seed, (60.0, 320.0)):
        conds.append(RunCondition.of(f"{kind[:2]}{i:03d}", kind, load, mp,
                                     slip if kind == "speed_control" else None))
    generate_campaign(out, conds, seed=seed, rates=SAMPLE_RATES, form="csv",
                      duration_s=duration_s)
    _settings(out / "campaign", VirtualSensors().clock_rate_error_ppm, (0.0, 0.0))
    truths = {}
    for c in conds:
        t = json.loads((out / "truth" / f"{c.run_id}.json").read_text())
        if t["stable_means"] is None:
            continue
        law, means = t["law_steady"], t["stable_means"]
        truths[c.run_id] = {**{k: law[k] for k in ("dp_n", "torque_nm", "thrust_n",
                                                   "resistance_n", "sinkage_m", "slip")},
                            "wheel_load_n": c.load_set_n,
                            **{k: means[k] for k in ("travel_velocity_mps",
                                                     "wheel_omega_radps")}}
    return truths


def write_second(out: Path, n: int, seed: int, low_speed: bool = False) -> dict[str, dict]:
    """A second-rig campaign in ``out/campaign`` (CSV runs), truth from ``bb2_sand``;
    ``low_speed``: in the rig's low-speed coarse-encoder mode at :data:`LOW_SPEEDS_MPS`."""
    model = tm.shipped_model("bb2_sand")
    w, flex = model.wheel, model.effects.get("wheel_flexibility")
    wheel = WheelGeometry(name="bb2", radius_m=w.radius_m, width_m=w.width_m,
                          grouser_count=w.grouser_count, grouser_height_m=w.grouser_height_m,
                          stiffness_n_per_mm=flex.radial_stiffness_n_m / 1000 if flex else None)
    speeds = np.exp(np.random.default_rng([seed, 1]).uniform(*np.log(LOW_SPEEDS_MPS), n))
    conds = [RigCondition(f"{kind[:2]}{i:03d}", kind, load,
                          slip if kind == "speed_control" else None, multipass=min(mp, 1),
                          wheel=wheel, **({"velocity_mps": float(np.round(speeds[i], 4))}
                                          if low_speed else {}))
             for i, kind, load, mp, slip in _draws(n, seed, (80.0, 300.0))]
    sensors = SensorModel(write_calibration_uncertainty=True)
    rig = Rig(sensors=sensors)
    write_campaign(out, conds, ModelTruth(model), seed, form="csv",
                   rig=low_speed_rig(rig) if low_speed else rig)
    _settings(out / "campaign", sensors.clock_ppm_max, sensors.zero_lead_s)
    return {c.run_id: json.loads((out / "truth" / f"{c.run_id}.json").read_text())["steady"]
            for c in conds}


def score(results: pd.DataFrame, truths: dict[str, dict]) -> pd.DataFrame:
    """One row per (run, quantity): error, u, u95, ``z = error/u``, covered; free-sled DP and
    resistance left out (no tether: the DP cell carries no force)."""
    rows = []
    for row in results.to_dict("records"):
        truth = truths.get(row["run_id"])
        if truth is None or row["status"] == "no_stable_phase":
            continue
        for q in QUANTITIES:
            mean, u, u95 = (row.get(f"{q}_{s}") for s in ("mean", "u", "u95"))
            if (mean is None or u is None or not np.isfinite(mean) or q not in truth
                    or (row["mode"] == "free_sled" and q in ("dp_n", "resistance_n"))):
                continue
            error = mean - truth[q]
            rows.append({"run_id": row["run_id"], "mode": row["mode"], "quantity": q,
                         "error": error, "u": u, "u95": u95, "z": error / u if u > 0 else np.inf,
                         "covered": abs(error) <= u95})
    return pd.DataFrame(rows)


def wilson(k: int, n: int, z: float = 1.96) -> tuple[float, float]:
    """Wilson score interval of a binomial proportion ``k/n`` (Wilson 1927, JASA 22, 209)."""
    if n == 0:
        return float("nan"), float("nan")
    p, d = k / n, 1 + z * z / n
    centre = (p + z * z / (2 * n)) / d
    half = z * np.sqrt(p * (1 - p) / n + z * z / (4 * n * n)) / d
    return float(centre - half), float(centre + half)


def coverage(scores: pd.DataFrame) -> pd.DataFrame:
    """Per quantity: runs, coverage of ``mean +- u95`` with its Wilson 95 % interval
    (``coverage_lo``, ``coverage_hi``), spread (std) and median of ``z``, median coverage
    factor ``k``."""
    def summary(g: pd.DataFrame) -> pd.Series:
        lo, hi = wilson(int(g["covered"].sum()), len(g))
        return pd.Series({"runs": len(g), "coverage": g["covered"].mean(),
                          "coverage_lo": lo, "coverage_hi": hi,
                          "z_std": g["z"].std(), "z_median": g["z"].median(),
                          "k_median": (g["u95"] / g["u"]).median()})
    table = scores.groupby("quantity")[["covered", "z", "u", "u95"]].apply(summary)
    return table.loc[[q for q in QUANTITIES if q in table.index]]


def run_coverage(out: str | Path, generator: str, n: int, seed: int) -> pd.DataFrame:
    """Write a campaign of ``generator``, process it, return its :func:`score` rows."""
    if generator not in GENERATORS:
        raise ValueError(f"generator {generator!r} not in {GENERATORS}")
    out = Path(out)
    truths = (write_virtual(out, n, seed) if generator == "virtual"
              else write_second(out, n, seed, low_speed=generator == "low_speed"))
    campaign = swtlab.process_campaign(out / "campaign", soil_flow=False)
    return score(campaign.results, truths)
