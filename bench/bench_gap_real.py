"""The gap diagnosis on published single-wheel data (the worked examples of
docs/gap-report.md): each source's leading effect sets with their probabilities, the learning
rate, the verdict and, where a lugged and a smooth wheel ran on one soil, the measured
contrast of drawbar pull with its 95 % interval.

``python -m bench gap_real [--markdown]`` (about 10 s); the record is
docs/validation/gap_real.md. The CMU example needs ``../shared/data`` (skipped without it).
None of these data were used to build the diagnosis; they are independent of it.
"""

from __future__ import annotations

import time
from pathlib import Path

import swtlab

ROOT = Path(__file__).resolve().parents[1]
CMU_RUNS = ROOT.parent / "shared" / "data" / "cmu-3d-terramechanics" / "smooth_runs.csv"
#: name -> (measured, simulation, candidate effects or None for every missing effect)
EXAMPLES = {
    "Ding et al. 2011, lug wheel against the smooth-calibrated simulation": (
        [ROOT / "sim_gap/data/ding2011_points.csv"],
        ROOT / "sim_gap/models/ding2011_smooth_calibrated.toml", None),
    "Ding et al. 2011, both wheels against the uncalibrated simulant": (
        [ROOT / "sim_gap/data/ding2011_points.csv"], ROOT / "sim_gap/models/ding2011_simulant.toml",
        ["grousers", "slip_sinkage"]),
    "Wang & Han 2016, KLS-1 (proxied soil)": (
        [ROOT / "sim_gap/data/wang_han2016_points.csv"], ROOT / "sim_gap/models/kls1_proxy.toml",
        None),
    "CMU smooth wheel (triplicates)": (
        [CMU_RUNS], ROOT / "sim_gap/models/cmu_smooth_sand.toml", None),
}
#: run by ``python -m bench`` on the pinned instruction set (bench/pinned_isa.py): its
#: figures are verdicts at a threshold
ON_PINNED_ISA = True
N_BOOT = 50
LEADERS = 3


def diagnose(measured: list[Path], simulation: Path, effects: list[str] | None) -> dict:
    """One example's numbers: leading sets, learning rate, verdict, drawbar-pull contrast."""
    start = time.perf_counter()
    data = swtlab.diagnose_gap([str(m) for m in measured], str(simulation), effects=effects,
                               n_boot=N_BOOT, jobs=2).data
    dp = [c for c in data["sibling_contrasts"] if c["quantity"] == "dp_n"]
    return {"verdict": data["verdict"], "learning_rate": data["learning_rate"],
            "leaders": [(s["label"], s["probability"]) for s in data["effect_sets"][:LEADERS]],
            "dp_contrast_n": dp[0]["contrast"] if dp else None,
            "dp_contrast_ci95": dp[0]["ci95"] if dp else None,
            "seconds": time.perf_counter() - start}


def main(quick: bool = False) -> dict:
    out = {}
    for name, (measured, simulation, effects) in EXAMPLES.items():
        if not all(m.exists() for m in measured):
            print(f"{name}: skipped (data not here)")
            continue
        out[name] = diagnose(measured, simulation, effects)
        r = out[name]
        print(f"{name}: {r['verdict']}, eta {r['learning_rate']:.3g}, "
              + ", ".join(f"{label} {p:.2f}" for label, p in r["leaders"]))
    return out


def markdown(numbers: dict) -> str:
    lines = ["# The gap diagnosis on published data", "",
             "`python -m bench gap_real --markdown` (docs/gap-report.md, \"Worked examples\"). "
             "Probabilities of the leading effect sets (laws summed), the learning rate η, "
             "the verdict, and the drawbar pull the lugged wheel adds over its smooth sibling "
             "at matched slips (95 % interval).", "",
             "| source | leading effect sets | η | verdict | lugs add (DP, N) |",
             "|---|---|---|---|---|"]
    for name, r in numbers.items():
        leaders = ", ".join(f"{label.replace('_', ' ')} {p:.2f}" for label, p in r["leaders"])
        verdict = r["verdict"] if isinstance(r["verdict"], str) else (
            " + ".join(r["verdict"]) or "none")
        contrast = ("—" if r["dp_contrast_n"] is None else
                    f"{r['dp_contrast_n']:.1f} [{r['dp_contrast_ci95'][0]:.1f}, "
                    f"{r['dp_contrast_ci95'][1]:.1f}]")
        lines.append(f"| {name} | {leaders} | {r['learning_rate']:.2g} | {verdict} | "
                     f"{contrast} |")
    return "\n".join(lines) + "\n"
