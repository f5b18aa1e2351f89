"""Follow-up tests on the apart testbed's inconclusive campaigns: ``python -m
testbeds.apart.followup DIR --out OUT [--seed S] [--only cNNN,...] [--boot B] [--json F]``;
``--summarise F [F ...]`` prints the tables of kept results (:func:`markdown`).

For each campaign ``DIR/cNNN`` whose report (``gap.json``, diagnosed again from the processed
databases when it lists no ``admissible_tests``) is ``inconclusive``, two follow-ups are
written under ``OUT``: ``cNNN_top``, the campaign plus the runs of the report's top-ranked
test, and ``cNNN_random``, plus the runs of a test drawn at random (seed ``S``) among the
report's admissible ones. The tests come as plain data (each run's source, set load, slip,
multipass and gravity level, wheel), so this package reads them without importing the
diagnosis (import contract in pyproject.toml). The new runs are the same campaign's: its
truth, soil and rig, their own per-run soil scatter, new run ids (``...F_r000``); a run the
wheel cannot carry (no equilibrium) is left out, as a lab would. Each follow-up is processed
and diagnosed like a campaign (:func:`testbeds.apart.score.diagnose`) and scored against the
truth (:func:`testbeds.apart.score.score_campaign`).

A campaign is *resolved* when the follow-up's verdict is a call and right: the truth's
effects of the six, or "outside the candidates" for a truth outside them.
docs/validation/gap-apart.md.
"""

from __future__ import annotations

import argparse
import json
import shutil
import sys
import tempfile
import zlib
from dataclasses import replace
from datetime import datetime, timedelta
from pathlib import Path

import numpy as np

from testbeds.apart.campaign import (RESET_MIN, campaign_names, draw_campaign, lab_rig,
                                     rig_inputs, run_row, start_times, truth_document,
                                     write_text)
from testbeds.apart.effects import SIX
from testbeds.apart.score import P_FLOOR, diagnose, score_campaign
from testbeds.apart.solver import NoEquilibrium
from testbeds.apart.truth import REFERENCE_VELOCITY_MPS, RunSpec, WheelSpec
from validation.second_rig import write_campaign

ARMS = ("top", "random")
#: the files of a campaign folder a follow-up does not copy (the diagnosis' outputs)
NOT_COPIED = ("*.sqlite", "gap*.json", "gap*.html", "failure.txt")


def _wheel(plan, condition: dict) -> tuple[str, WheelSpec]:
    """The source and wheel a condition runs on: the smooth twin (or, where the campaign has
    none, a smooth wheel of the same rim) for a condition without grousers on a campaign of
    a lugged wheel, else the campaign's wheel."""
    smooth = (plan.wheel.grouser_count > 0 and condition.get("grouser_count", 1) == 0)
    if not smooth:
        return "main", plan.wheel
    twin = plan.twin or WheelSpec(plan.wheel.name.replace("_wheel", "_smooth"),
                                  plan.wheel.radius_m, plan.wheel.width_m, 0, 0.0,
                                  plan.wheel.stiffness_n_per_mm)
    return "smooth", twin


def followup_rows(drawn: dict, conditions: list[dict], tag: str) -> tuple[list[dict], int]:
    """The steady rows of the runs at ``conditions`` in the campaign ``drawn``
    (:func:`draw_campaign`) and how many could not run (no equilibrium)."""
    rng = np.random.default_rng([drawn["seed"], drawn["index"], 2, zlib.crc32(tag.encode())])
    rows, failed = [], 0
    counters = {"main": 0, "smooth": 0}
    for c in conditions:
        source, wheel = _wheel(drawn["plan"], c)
        letter = "S" if source == "smooth" else "L" if wheel.grouser_count else "W"
        run = RunSpec(run_id=f"{drawn['name']}{letter}F_r{counters[source]:03d}", wheel=wheel,
                      load_n=float(c["load_set_n"]), slip=float(c["slip"]),
                      multipass=int(c.get("multipass", 0)),
                      gravity_mps2=float(c["gravity_mps2"]),
                      velocity_mps=REFERENCE_VELOCITY_MPS, order=1.0)
        try:
            rows.append(run_row(drawn["truth"], source, run, drawn["scatter_sd"], rng))
        except NoEquilibrium:
            failed += 1
            continue
        counters[source] += 1
    return rows, failed


def followup_start_times(drawn: dict, rows: list[dict]) -> dict[str, str]:
    """When each follow-up run started: one after the other from the campaign's last run on,
    as :func:`testbeds.apart.campaign.start_times` spaces a campaign's runs (their truth is the
    soil at the campaign's end, run order 1.0). A lab's log shows the same."""
    plan = drawn["plan"]
    run_s = lab_rig(drawn["seed"], drawn["index"], plan).timeline.duration_s
    last = max(datetime.fromisoformat(t)
               for t in start_times(drawn["seed"], drawn["index"], plan, run_s).values())
    step = timedelta(seconds=run_s + 60.0 * RESET_MIN)
    return {r["run"].run_id: (last + (k + 1) * step).isoformat() for k, r in enumerate(rows)}


def write_followup(src: Path, out: Path, truth: dict, tag: str, test: dict) -> dict:
    """``src`` (a campaign folder) plus the runs of ``test`` (a report's ``{test,
    conditions}``) as ``out/<campaign>_<tag>``; its truth (the campaign's, with the new runs
    and the test) as ``out/truth/<campaign>_<tag>.json``, which is returned."""
    drawn = draw_campaign(truth["seed"], truth["index"])
    name, plan = drawn["name"], drawn["plan"]
    folder = out / f"{name}_{tag}"
    if folder.exists():
        shutil.rmtree(folder)
    shutil.copytree(src, folder, ignore=shutil.ignore_patterns(*NOT_COPIED))
    rows, failed = followup_rows(drawn, test["conditions"], tag)
    runs = plan.runs + tuple((r["source"], r["run"]) for r in rows)
    rig = lab_rig(drawn["seed"], drawn["index"], replace(plan, runs=runs))
    names = campaign_names(name, plan)
    started = followup_start_times(drawn, rows)
    for source, part in (("main", folder), ("smooth", folder / "smooth")):
        mine = [r for r in rows if r["source"] == source]
        if not mine:
            continue
        with tempfile.TemporaryDirectory(dir=out) as staging:
            write_campaign(staging, *rig_inputs(mine, names[source]),
                           drawn["seed"] * 1000 + drawn["index"] + 500, rig=rig,
                           started_at=started)
            (part / "campaign").mkdir(parents=True, exist_ok=True)
            for f in (Path(staging) / "campaign").iterdir():
                shutil.move(str(f), str(part / "campaign" / f.name))
            target = out / "truth" / folder.name / f"rig-{source}"
            shutil.rmtree(target, ignore_errors=True)
            target.parent.mkdir(parents=True, exist_ok=True)
            shutil.move(str(Path(staging) / "truth"), str(target))
    document = truth_document({**drawn, "rows": drawn["rows"] + rows})
    document.update(campaign=folder.name, followup={
        "of": name, "arm": tag, "test": test["test"], "runs": len(rows),
        "runs_without_equilibrium": failed})
    write_text(out / "truth" / f"{folder.name}.json", json.dumps(document, indent=1) + "\n")
    return document


def resolved(row: dict, truth: dict) -> bool:
    """The verdict is a call and right (module docstring)."""
    verdict = row["verdict"]
    if truth["outside"]:
        return verdict == "outside_candidates"
    return isinstance(verdict, list) and tuple(e for e in SIX if e in verdict) == tuple(
        e for e in SIX if e in truth["effects"]) and row["outcome"] == "right"


def kind_of(test: dict) -> str:
    """The report's kind of ``test`` (a report's ``{kind, conditions}``), a slip test named by
    its band: braked (every slip below zero), high (every slip from 0.5 up) or low."""
    if test["kind"] != "slips":
        return test["kind"]
    slips = [c["slip"] for c in test["conditions"]]
    band = "braked" if max(slips) < 0 else "high" if min(slips) >= 0.5 else "low"
    return f"{band} slips"


def by_kind(results: list[dict]) -> list[dict]:
    """Per kind of test (both arms pooled): how often it was run, its mean expected gain and
    what it did to the truth's probability (median change of its log, how often it rose,
    how often it resolved). Under a model that holds, the truth's log probability rises on
    average with any test (the expected log posterior of the truth grows with data); a kind
    whose runs lower it tells the hypotheses apart by what the base model gets wrong."""
    rows: dict[str, list] = {}
    for r in results:
        for arm in ARMS:
            a = r[arm]
            change = np.log(max(a["p_true"], P_FLOOR)) - np.log(max(r["p_true"], P_FLOOR))
            rows.setdefault(a["kind"], []).append((a["gain_bits"], change, a["resolved"]))
    out = []
    for kind, v in sorted(rows.items(), key=lambda kv: -len(kv[1])):
        gain, change, done = (np.array(x, float) for x in zip(*v))
        out.append({"kind": kind, "n": len(v), "gain_bits": float(gain.mean()),
                    "median_log_change": float(np.median(change)),
                    "rises": int((change > 0).sum()), "resolved": int(done.sum())})
    return out


def markdown(results: list[dict]) -> str:
    """The arms' resolution and :func:`by_kind` as markdown tables."""
    n = len(results)
    lines = ["| | resolved to the right answer | the truth's probability rises |",
             "|---|---|---|"]
    for arm in ARMS:
        k = sum(r[arm]["resolved"] for r in results)
        up = sum(r[arm]["p_true"] > r["p_true"] for r in results)
        lines.append(f"| {arm} | {k} / {n} | {up} / {n} |")
    lines += ["", "| kind of test (both arms) | run | mean expected gain (bits) | median change "
              "of ln P(truth) | P(truth) rises | resolved |", "|---|---|---|---|---|---|"]
    lines += [f"| {k['kind']} | {k['n']} | {k['gain_bits']:.2f} | {k['median_log_change']:+.2f} "
              f"| {k['rises']} | {k['resolved']} |" for k in by_kind(results)]
    return "\n".join(lines) + "\n"


def run_campaign(folder: Path, out: Path, seed: int, boot: int) -> dict | None:
    """Both arms of one campaign; None when its report is not inconclusive."""
    truth = json.loads((folder.parent / "truth" / f"{folder.name}.json").read_text())
    gap = folder / "gap.json"
    if not gap.exists() or "admissible_tests" not in json.loads(gap.read_text()):
        diagnose(folder, boot, regap=True)
    report = json.loads(gap.read_text()) if gap.exists() else {}
    tests = report.get("admissible_tests") or []
    if report.get("verdict") != "inconclusive" or not tests:
        return None
    rng = np.random.default_rng([seed, truth["index"]])
    picks = {"top": tests[0], "random": tests[int(rng.integers(len(tests)))]}
    result = {"campaign": folder.name, "class": truth["class"],
              "truth": "+".join(truth["effects"] + truth["outside"]) or "none",
              "p_true": score_campaign(folder, truth)["p_true"]}
    for arm, test in picks.items():
        document = write_followup(folder, out, truth, arm, test)
        diagnose(out / document["campaign"], boot)
        row = score_campaign(out / document["campaign"], document)
        result[arm] = {"test": test["test"], "kind": kind_of(test),
                       "gain_bits": test["gain_bits"],
                       "runs": document["followup"]["runs"], "verdict": row["verdict"],
                       "outcome": row["outcome"], "resolved": resolved(row, truth),
                       "p_leading": row["p_leading"], "leading": row["leading"],
                       "p_true": row["p_true"]}
    return result


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m testbeds.apart.followup",
                                     description=__doc__.split("\n\n")[0])
    parser.add_argument("dir", type=Path, nargs="?",
                        help="folder written by testbeds.apart.campaigns")
    parser.add_argument("--out", type=Path, help="where the follow-ups go")
    parser.add_argument("--seed", type=int, default=0, help="seed of the random arm")
    parser.add_argument("--only", help="comma-separated campaigns (default: every one)")
    parser.add_argument("--boot", type=int, default=20, help="swtlab gap --boot")
    parser.add_argument("--json", type=Path, help="write the results here")
    parser.add_argument("--summarise", type=Path, nargs="+", metavar="JSON",
                        help="print the tables of results written by --json, and stop")
    args = parser.parse_args(argv)
    if args.summarise:
        print(markdown([r for f in args.summarise
                        for r in json.loads(f.read_text())["campaigns"]]), end="")
        return 0
    if args.dir is None or args.out is None:
        parser.error("DIR and --out are needed to run follow-ups")
    names = (args.only.split(",") if args.only else
             [p.stem for p in sorted((args.dir / "truth").glob("c*.json"))])
    if not names:
        parser.error(f"{args.dir}: no campaign (truth/cNNN.json) found")
    args.out.mkdir(parents=True, exist_ok=True)
    results = []
    for name in names:
        r = run_campaign(args.dir / name, args.out, args.seed, args.boot)
        if r is None:
            continue
        results.append(r)
        print(f"{name} ({r['truth']}): " + "; ".join(
            f"{arm}: {r[arm]['test']} ({r[arm]['gain_bits']:.2f} bit) -> {r[arm]['verdict']}"
            f"{' RESOLVED' if r[arm]['resolved'] else ''}" for arm in ARMS), flush=True)
    print(markdown(results), end="")
    if args.json:
        write_text(args.json, json.dumps({"campaigns": results}, indent=1) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
