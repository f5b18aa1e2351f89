"""Coverage of swtlab's run results on raw runs of the second rig (validation/second_rig):
an INDEPENDENT signal model (underdamped transients, shark-fin grouser load, coloured noise,
drift since zeroing, gain errors, spikes, other rates), through ``swtlab process``.

Truth law: the shipped ``bb2_sand`` terramechanics model (towed: the slip where its torque is
0; free sled: where its DP is 0), passed to the rig as a plain callable. The estimators are
not tuned here: the numbers are what the chain gives. Per quantity: the fraction of runs
whose ``mean +- 1.96 SE`` covers the true steady value (``coverage_window_means``: the rig's
true window mean instead; validation/second_rig/score.py says why they differ), the median
and spread of ``(mean - truth)/SE``, the coverage with the instruments' true errors taken out
(diagnostic only: it reads the truth), which says how much of the miss the instruments cause;
and the coverage of the uncertainty budget's ``mean +- u95`` (``coverage_u95``; the means are
re-zeroed on the rest readings; no calibration-uncertainty keys in these runs, and the clock
at its default bound: ``bench coverage`` gives the budget its inputs).
"""

from __future__ import annotations

import contextlib
import io
import json
import tempfile
import time
from pathlib import Path

import numpy as np

import terramechanics as tm
from swtlab_cli.main import main as swtlab
from validation.model_truth import ModelTruth
from validation.second_rig import RunCondition, WheelGeometry, write_campaign
from validation.second_rig.score import coverage, score

SEED = 18


def conditions(model: tm.WheelModel, quick: bool) -> list[RunCondition]:
    """60 runs (quick: 12): loads x slips x multipass, a Mars-gravity series, towed and free
    sled at every load and multipass."""
    w = model.wheel
    flex = model.effects.get("wheel_flexibility")
    wheel = WheelGeometry(name="bb2", radius_m=w.radius_m, width_m=w.width_m,
                          grouser_count=w.grouser_count, grouser_height_m=w.grouser_height_m,
                          stiffness_n_per_mm=flex.radial_stiffness_n_m / 1000 if flex else None)
    loads = (80.0, 180.0, 300.0)
    slips = (0.15, 0.45) if quick else (-0.2, 0.05, 0.15, 0.3, 0.45, 0.6, 0.75)
    out = []
    for load in loads:
        for mp in (0,) if quick else (0, 1):
            out += [RunCondition(f"L{load:03.0f}_MP{mp}_SC_s{100 * s:+04.0f}", "speed_control",
                                 load, s, multipass=mp, wheel=wheel) for s in slips]
            out += [RunCondition(f"L{load:03.0f}_MP{mp}_{m}", mode, load, multipass=mp,
                                 wheel=wheel) for m, mode in (("TW", "towed"),
                                                              ("FS", "free_sled"))]
        if not quick:
            out += [RunCondition(f"L{load:03.0f}_MP0_SC_s{100 * s:+04.0f}_mars", "speed_control",
                                 load, s, gravity_mps2=3.71, wheel=wheel) for s in (0.1, 0.3)]
    return out


def main(quick: bool = False) -> dict:
    model = tm.shipped_model("bb2_sand")
    runs = conditions(model, quick)
    with tempfile.TemporaryDirectory() as tmp:
        out = Path(tmp)
        t0 = time.perf_counter()
        forms = {c.run_id: "csv" for c in runs[::4]}
        write_campaign(out, runs, ModelTruth(model), SEED, form=forms)
        t1 = time.perf_counter()
        url = f"sqlite:///{out / 'swtlab.sqlite'}"
        with contextlib.redirect_stdout(io.StringIO()):
            assert swtlab(["process", str(out / "campaign"), "--db", url, "--quiet"]) == 0
        t2 = time.perf_counter()
        with contextlib.redirect_stdout(io.StringIO()) as listing:
            assert swtlab(["results", "--db", url, "--json"]) == 0
        rows = json.loads(listing.getvalue())
        ok = [r for r in rows if r["status"] == "ok"]
        scores = score(ok, out / "truth")
        windowed = coverage(score(ok, out / "truth", target="window_means"))
        truth_start = {p.stem: json.loads(p.read_text())["window"]["start_s"]
                       for p in (out / "truth").glob("*.json")}
        start_error = np.array([r["window_start_s"] - truth_start[r["run_id"]] for r in ok])
    table = coverage(scores)
    table["coverage_window_means"] = windowed["coverage"]
    statuses = {s: sum(r["status"] == s for r in rows) for s in {r["status"] for r in rows}}
    print(f"second rig: {len(runs)} runs, generated in {t1 - t0:.1f} s, processed in "
          f"{t2 - t1:.1f} s; status {statuses}")
    print(f"window start - truth start (s): median {np.median(start_error):+.1f}, "
          f"range {start_error.min():+.1f}..{start_error.max():+.1f}")
    print(table.round(3).to_string())
    return {"runs": len(runs), "statuses": statuses, "generate_s": t1 - t0,
            "process_s": t2 - t1, "window_start_error_s": {
                "median": float(np.median(start_error)), "min": float(start_error.min()),
                "max": float(start_error.max())},
            "by_quantity": table.round(4).to_dict(orient="index")}
