"""How far each effect's other law can stand in for the law that made the data.

The held-out gap bench (``swtlab gap-bench --truth-laws held-out``) removes the truth's law
from each family, so with two laws per family the diagnosis has the other one only. Its
calls then hold only where that law, with the soil recalibrated, mimics the truth's within
the unexplained bound (:data:`UNEXPLAINED_RMS_SIGMA`, sqrt(2) sigma RMS held out: a right
model leaves about 1 sigma, and the mean of ~100 squared standardised residuals exceeds 2
with a chance below 1e-6).
This bench measures that ceiling without the signal chain: per family and truth law, the
truth at 10, 50 and 90 % of the bench's strength range (``validation.gap_bench.STRENGTHS``)
on the bench's full design (lugged and smooth wheel, noise-free), fitted by soil-only
recalibration and by the effect under each law, scored by the diagnosis's own held-out
folds and sigmas. A sibling law above the bound means the held-out bench cannot call that
truth, whatever the decision rule: the family needs a law of that shape.
"""

from __future__ import annotations

import csv
import tempfile
import time
from pathlib import Path

import numpy as np

import terramechanics as tm
from sim_gap import candidates as cands
from sim_gap.crossval import cross_validate
from sim_gap.fit import sigmas
from sim_gap.measured import from_points_csv
from sim_gap.simulated import Simulated
from validation.gap_bench import (KPHI_RELATIVE, STRENGTHS, Design, base_model, conditions,
                                  smooth_wheel)

QUANTILES = (0.1, 0.5, 0.9)
HEADER = ("source", "wheel_radius_m", "wheel_width_m", "grouser_count", "grouser_height_m",
          "load_set_n", "multipass", "gravity_mps2", "slip", "dp_n", "dp_n_se", "torque_nm",
          "torque_nm_se", "sinkage_m", "sinkage_m_se")

#: held-out RMS (sigma) a right model stays under (module docstring)
UNEXPLAINED_RMS_SIGMA = float(np.sqrt(2.0))


def truth_model(family: str, law: str, quantile: float) -> tm.WheelModel:
    """The base model with ``family`` under ``law`` at ``quantile`` of each strength range."""
    base = base_model()
    params = {k: lo + quantile * (hi - lo) for k, (lo, hi) in STRENGTHS[family][law].items()}
    scaled = KPHI_RELATIVE.get((family, law))
    if scaled:
        params[scaled] *= base.soil.kphi
    return base.with_effects(**{family: {"law": law, **params}})


def write_points(model: tm.WheelModel, path: Path) -> None:
    """The model's DP, torque and sinkage at the full design, lugged and smooth wheel, as a
    points CSV (docs/points-csv.md) with negligible SEs (the diagnosis adds its floor)."""
    from virtual_testbed.rig import BB2_WHEEL

    conds = conditions(Design())
    load, slip, mp, g = (np.array([getattr(c, a) for c in conds], float) for a in
                         ("load_set_n", "slip_setpoint", "multipass", "gravity_mps2"))
    with open(path, "w", newline="") as f:
        out = csv.writer(f)
        out.writerow(HEADER)
        for name, wheel in (("lugged", BB2_WHEEL), ("smooth", smooth_wheel())):
            m = model.with_wheel(radius_m=wheel.radius_m, width_m=wheel.width_m,
                                 grouser_count=wheel.grouser_count,
                                 grouser_height_m=wheel.grouser_height_m)
            pred = m.curves(load, slip, mp, g)
            for i in range(len(conds)):
                out.writerow([name, wheel.radius_m, wheel.width_m, wheel.grouser_count,
                              wheel.grouser_height_m, load[i], int(mp[i]), g[i], slip[i],
                              pred["dp_n"][i], 1e-3, pred["torque_nm"][i], 1e-4,
                              pred["sinkage_m"][i], 1e-6])


def held_out_rms(model: tm.WheelModel, effects: tuple[str, ...], laws: dict[str, str],
                 points, sim: Simulated, sigma) -> tuple[float, dict[str, float]]:
    """Held-out RMS (sigma) of the candidate and its full fit's parameters."""
    cv = cross_validate(sim, cands.candidate(model, effects, laws), points, sigma,
                        max_nfev=40, fold_nfev=12)
    values = {k: float(v) for k, v in cv.full.values.items() if not isinstance(v, str)}
    return float(np.sqrt(cv.run_losses(len(points)).mean())), values


def main(quick: bool = False) -> dict:
    quantiles = (0.5,) if quick else QUANTILES
    bound = UNEXPLAINED_RMS_SIGMA
    base = base_model()
    rows, t0 = [], time.process_time()
    print(f"held-out RMS (sigma) of each law on truths of another; unexplained bound {bound:.2f}")
    print(f"{'family':18s} {'truth law':22s} {'q':>4s} {'soil only':>9s} {'own law':>8s}  "
          "other law: RMS (fitted strengths)")
    with tempfile.TemporaryDirectory() as tmp:
        for family in STRENGTHS:
            for law in sorted(STRENGTHS[family]):
                for q in quantiles:
                    path = Path(tmp) / f"{family}-{law}-{q}.csv"
                    write_points(truth_model(family, law, q), path)
                    points = from_points_csv(path)
                    sim = Simulated(base, wheel_per_row=True)
                    sigma = sigmas(points, sim.radius_m)
                    soil, _ = held_out_rms(base, (), {}, points, sim, sigma)
                    own, _ = held_out_rms(base, (family,), {family: law}, points, sim, sigma)
                    others = {}
                    for other in sorted(tm.LAWS[family]):
                        if tm.published_law(family, other) != law:
                            rms, values = held_out_rms(base, (family,), {family: other},
                                                       points, sim, sigma)
                            others[other] = {"rms_sigma": rms, "values": values}
                    rows.append({"family": family, "truth_law": law, "quantile": q,
                                 "soil_only_rms_sigma": soil, "own_law_rms_sigma": own,
                                 "other_laws": others})
                    text = "  ".join(
                        f"{o}: {v['rms_sigma']:.2f}"
                        + (" (above the bound)" if v["rms_sigma"] > bound else "")
                        for o, v in others.items())
                    print(f"{family:18s} {law:22s} {q:4.1f} {soil:9.2f} {own:8.2f}  {text}",
                          flush=True)
    return {"unexplained_bound_sigma": bound, "rows": rows,
            "cpu_s": time.process_time() - t0}
