"""Run the full chain on the apart testbed's campaigns and score the verdicts against the truth:
``python -m testbeds.apart.score DIR [--jobs J] [--boot B] [--redo] [--json OUT] [--markdown]``.

Per campaign ``DIR/cNNN``: ``swtlab process`` of ``campaign/`` (and ``smooth/campaign/``)
into ``cNNN/main.sqlite`` (``smooth.sqlite``), then ``swtlab gap --measured ... --sim
cNNN/sim.toml --json cNNN/gap.json``, each a separate process that is given the campaign's
folder only; the truth (``DIR/truth/``) is read by this scorer alone, after the diagnosis. A
step that fails writes its one-line error to ``cNNN/failure.txt`` and the bench goes on.

``chosen`` (the leading candidate, named whatever the verdict) is compared with the truth's
effects of the six: whether the ranking puts the truth first. The report is read
defensively: ``verdict`` (a list of effects, ``[]``, or a string such as ``inconclusive``)
and, where the diagnosis gives them, ``probabilities`` (a mapping or a list
of hypotheses with probabilities): the probability of the leading hypothesis and of the true
one are tabulated when they can be read.

Outcomes: a campaign whose gap is within the six is ``right`` when the verdict names exactly
its effects, ``inconclusive``, or ``wrong`` (a named set that is not the truth: confidently
wrong); a campaign with an effect outside the six is ``right`` when the verdict is not a set of
effects (inconclusive, or outside the candidates) and ``wrong`` when it names effects.
"""

from __future__ import annotations

import argparse
import json
import os
import re
import subprocess
import sys
import tempfile
import time
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import numpy as np
from scipy.stats import beta

from testbeds.apart.detectability import TELLABLE_D, effect_distances, tellable
from testbeds.apart.effects import SIX

CLASSES = ("none", "single", "pair", "outside")
#: a probability below this counts as this in a log (the log loss; a truth given 0)
P_FLOOR = 1e-12


def _write(path: Path, text: str) -> None:
    with tempfile.NamedTemporaryFile("w", dir=path.parent, delete=False, suffix=".tmp") as f:
        f.write(text)
    os.chmod(f.name, 0o644)
    os.replace(f.name, path)


def diagnose(folder: Path, boot: int, redo: bool = False, regap: bool = False,
             process_only: bool = False) -> float:
    """``swtlab process`` then ``swtlab gap`` on one campaign folder; seconds taken.
    ``regap``: diagnose again from the databases already processed (a new diagnosis on the
    same processed runs); ``process_only``: process, do not diagnose."""
    start = time.perf_counter()
    gap, failure = folder / "gap.json", folder / "failure.txt"
    if gap.exists() and not (redo or regap):
        return 0.0
    failure.unlink(missing_ok=True)
    cli = [sys.executable, "-m", "swtlab_cli.main"]
    sources = [(folder / "campaign", folder / "main.sqlite"),
               (folder / "smooth" / "campaign", folder / "smooth.sqlite")]
    measured = []
    step = "process"
    try:
        for runs, db in sources:
            if not runs.is_dir():
                continue
            if not (regap and db.exists()):
                subprocess.run(cli + ["process", str(runs), "--db", f"sqlite:///{db}",
                                      "--quiet", "--jobs", "1"], check=True,
                               capture_output=True)
            measured += ["--measured", f"sqlite:///{db}"]
        if process_only:
            return time.perf_counter() - start
        step = "gap"
        subprocess.run(cli + ["gap", *measured, "--sim", str(folder / "sim.toml"), "--json",
                              str(gap), "--boot", str(boot)], check=True, capture_output=True)
    except subprocess.CalledProcessError as e:
        gap.unlink(missing_ok=True)
        lines = (e.stderr or b"").decode(errors="replace").strip().splitlines()
        _write(failure, f"{step}: {lines[-1] if lines else 'no message'}\n")
    return time.perf_counter() - start


def effects_of(label) -> tuple[str, ...] | None:
    """The effect set a hypothesis label or verdict names (vocabulary order), ``()`` for no
    missing effect, None when it names no set (inconclusive, outside the candidates)."""
    if isinstance(label, list | tuple):
        names = [str(x) for x in label]
    elif isinstance(label, str):
        text = label.strip().lower()
        if text in ("", "none", "[]", "soil_only", "soil only", "no_missing_effect"):
            return ()
        names = [re.sub(r"\(.*?\)", "", part).strip() for part in re.split(r"[+,]", text)]
    else:
        return None
    if not names or any(n not in SIX for n in names):
        return None
    return tuple(e for e in SIX if e in names)


def probabilities(report: dict) -> dict[tuple[str, ...] | str, float]:
    """Hypothesis -> probability, summed per effect set, from whichever form the report
    gives (``{label: p}``, ``[{label|hypothesis|effects, probability|p}]``); {} if none."""
    raw = report.get("probabilities", report.get("effect_sets"))
    items = []
    if isinstance(raw, dict):
        for key in ("hypotheses", "by_hypothesis", "sets", "by_set"):
            if isinstance(raw.get(key), dict | list):
                raw = raw[key]
                break
    if isinstance(raw, dict):
        items = [(k, v) for k, v in raw.items() if isinstance(v, int | float)]
    elif isinstance(raw, list):
        for entry in raw:
            if isinstance(entry, dict):
                label = next((entry[k] for k in ("label", "effects", "hypothesis", "name")
                              if k in entry), None)
                p = next((entry[k] for k in ("probability", "p", "posterior") if k in entry),
                         None)
                if label is not None and isinstance(p, int | float):
                    items.append((label, p))
    out: dict = {}
    for label, p in items:
        key = effects_of(label)
        key = key if key is not None else str(label)
        out[key] = out.get(key, 0.0) + float(p)
    return out


#: how a hypothesis stands to a truth of the six (:func:`relation`)
RELATIONS = ("truth", "larger", "smaller", "other", "outside")


def relation(key: tuple[str, ...] | str, truth_set: tuple[str, ...]) -> str:
    """How the hypothesis ``key`` (an effect set, or a label naming no set) stands to the
    truth's effect set: the truth itself, a larger set holding it (an effect too many), a
    smaller set within it (an effect missed), another set, or outside the candidates."""
    if isinstance(key, str):
        return "outside"
    have, want = set(key), set(truth_set)
    return ("truth" if have == want else "larger" if want < have
            else "smaller" if have < want else "other")


def score_campaign(folder: Path, truth: dict) -> dict:
    """One row: the truth, the verdict, the outcome and the probabilities read."""
    row = {"campaign": truth["campaign"], "class": truth["class"],
           "effects": truth["effects"], "outside": truth["outside"],
           "runs": len(truth["runs"]),
           "sources": 1 + (truth["plan"]["twin"] is not None),
           "verdict": None, "chosen": None, "outcome": "failed", "failed": None,
           "p_leading": None, "leading": None, "p_true": None}
    failure, gap = folder / "failure.txt", folder / "gap.json"
    if failure.exists() or not gap.exists():
        row["failed"] = failure.read_text().strip() if failure.exists() else "no report"
        return row
    report = json.loads(gap.read_text())
    verdict = report.get("verdict")
    row["verdict"] = verdict if isinstance(verdict, str) else list(verdict or [])
    row["chosen"] = report.get("chosen")
    called = () if verdict == [] else effects_of(verdict)
    truth_set = tuple(e for e in SIX if e in truth["effects"])
    if truth["outside"]:
        row["outcome"] = "wrong" if called is not None else "right"
    elif verdict == "outside_candidates":  # a confident call, and not the truth
        row["outcome"] = "wrong"
    elif called is None:
        row["outcome"] = "inconclusive"
    else:
        row["outcome"] = "right" if called == truth_set else "wrong"
    chosen = effects_of(row["chosen"]) if row["chosen"] else None
    row["chosen_is_truth"] = chosen is not None and chosen == truth_set
    probs = probabilities(report)
    if probs:
        leading = max(probs, key=probs.get)
        row["leading"] = "+".join(leading) or "none" if isinstance(leading, tuple) else leading
        row["p_leading"] = probs[leading]
        row["p_true"] = probs.get("outside_candidates" if truth["outside"] else truth_set, 0.0)
        if not truth["outside"]:
            where = dict.fromkeys(RELATIONS, 0.0)
            for key, p in probs.items():
                where[relation(key, truth_set)] += p
            row["p_where"] = where
    return row


def leading_is_right(r: dict) -> bool | None:
    """Whether the most probable hypothesis (effect set, or outside the candidates) is the
    truth: the truth's six exactly, or outside the candidates for a campaign with an effect
    outside the six. None without probabilities."""
    if r["p_leading"] is None:
        return None
    if r["outside"]:
        return r["leading"] == "outside_candidates"
    return r["leading"] == ("+".join(e for e in SIX if e in r["effects"]) or "none")


def upper_95(k: int, n: int) -> float:
    """One-sided 95 % upper bound of a rate seen ``k`` times in ``n`` (Clopper & Pearson
    1934, exact)."""
    return 1.0 if n == 0 or k >= n else float(beta.ppf(0.95, k + 1, n - k))


def calibration(rows: list[dict]) -> dict:
    """Reliability of the stated probabilities: per decile of the leading hypothesis'
    probability, how many campaigns, their mean stated probability and the fraction whose
    leading hypothesis is the truth; the same per class of truth (``by_class``: a
    reliability table pooled over classes can hide probabilities too low on one class and
    too high on another); confident wrong calls (a named verdict, probability >=
    0.9, that is not the truth) with their 95 % upper bound; the issue's rates."""
    scored = [r for r in rows if r["p_leading"] is not None]
    bins = []
    for lo in np.arange(0.0, 1.0, 0.1):
        sub = [r for r in scored if lo <= r["p_leading"] < lo + 0.1 or (lo >= 0.9 and
                                                                    r["p_leading"] >= 1.0)]
        right = [bool(leading_is_right(r)) for r in sub]
        bins.append({"bin": f"{lo:.1f}-{lo + 0.1:.1f}", "n": len(sub),
                     "stated": float(np.mean([r["p_leading"] for r in sub])) if sub else None,
                     "right": float(np.mean(right)) if sub else None})
    n = len(rows)
    wrong = sum(r["outcome"] == "wrong" for r in rows)

    def rate(cls, outcome, tellable_only=False):
        sub = [r for r in rows if r["class"] in cls
               and (r.get("tellable", True) or not tellable_only)]
        return (sum(r["outcome"] == outcome for r in sub), len(sub))

    by_class = {}
    for cls in CLASSES:
        sub = [r for r in scored if r["class"] == cls]
        if sub:
            by_class[cls] = {"n": len(sub),
                             "stated": float(np.mean([r["p_leading"] for r in sub])),
                             "right": float(np.mean([bool(leading_is_right(r))
                                                     for r in sub]))}
    groups: dict[str, list[dict]] = {}
    for r in scored:
        if r.get("p_where"):
            groups.setdefault(r["class"], []).append(r)
            if r["class"] == "single":
                groups.setdefault(f"single: {r['effects'][0]}", []).append(r)
    order = [*CLASSES, *(f"single: {e}" for e in SIX)]
    where = {}
    for name in (g for g in order if g in groups):
        sub = groups[name]
        where[name] = {"n": len(sub)} | {k: float(np.mean([r["p_where"][k] for r in sub]))
                                         for k in RELATIONS}
        if name.startswith("single: ") and all("distances" in r for r in sub):
            where[name]["median_d"] = float(np.median(
                [r["distances"][r["effects"][0]] for r in sub]))
    p_true = np.array([r["p_true"] for r in scored], float)
    return {"bins": bins, "by_class": by_class, "where": where,
            "confident_wrong": wrong, "n": n,
            "log_loss": float(np.mean(-np.log(np.maximum(p_true, P_FLOOR)))) if scored else None,
            "confident_wrong_upper_95": upper_95(wrong, n),
            "right_none_and_singles": rate(("none", "single"), "right"),
            "right_pairs": rate(("pair",), "right"),
            "right_none_and_singles_tellable": rate(("none", "single"), "right", True),
            "right_pairs_tellable": rate(("pair",), "right", True),
            "untellable": [{"campaign": r["campaign"], "distances": r["distances"]}
                           for r in rows if not r.get("tellable", True)],
            "outside_not_named": rate(("outside",), "right")}


def score(out: Path) -> dict:
    """Rows of every campaign with a truth file under ``out`` and the counts per class; a
    campaign of one or two of the six also gets each effect's oracle distance and whether its
    design can tell every effect from its absence (:mod:`testbeds.apart.detectability`)."""
    rows = []
    for path in sorted((out / "truth").glob("c*.json")):
        truth = json.loads(path.read_text())
        row = score_campaign(out / path.stem, truth)
        row["campaign"] = f"{out.name}/{row['campaign']}"
        if truth["class"] in ("single", "pair"):
            row["distances"] = effect_distances(truth["seed"], truth["index"])
            row["tellable"] = tellable(row["distances"])
        rows.append(row)
    return summarise(rows)


def summarise(rows: list[dict]) -> dict:
    """The counts per class and the calibration of ``rows``."""
    by_class = {}
    for cls in CLASSES:
        sub = [r for r in rows if r["class"] == cls]
        by_class[cls] = {"n": len(sub)} | {k: sum(r["outcome"] == k for r in sub)
                                            for k in ("right", "inconclusive", "wrong", "failed")}
        by_class[cls]["chosen_is_truth"] = sum(bool(r.get("chosen_is_truth")) for r in sub)
    return {"n": len(rows), "by_class": by_class, "calibration": calibration(rows),
            "campaigns": rows}


def truth_label(r: dict) -> str:
    """A campaign's truth in words: its effects of the six, and those outside them."""
    six = "+".join(r["effects"]) or "none"
    return six + (" + outside: " + "+".join(r["outside"]) if r["outside"] else "")


def markdown(result: dict) -> str:
    """The per-campaign table and the counts per class, in Markdown."""
    lines = ["| campaign | truth | runs (sources) | verdict | chosen | leading (p) | outcome |",
             "|---|---|---|---|---|---|---|"]
    for r in result["campaigns"]:
        verdict = (r["failed"] and f"failed: {r['failed'][:60]}") or (
            r["verdict"] if isinstance(r["verdict"], str) else "+".join(r["verdict"]) or "none")
        lead = "-" if r["p_leading"] is None else f"{r['leading']} ({r['p_leading']:.2f})"
        lines.append(f"| {r['campaign']} | {truth_label(r)} | {r['runs']} ({r['sources']}) | "
                     f"{verdict} | {r['chosen'] or '-'} | {lead} | {r['outcome']} |")
    lines += ["", "| class | n | right | inconclusive | wrong | failed | chosen = truth's six |",
              "|---|---|---|---|---|---|---|"]
    for cls, v in result["by_class"].items():
        if v["n"]:
            lines.append(f"| {cls} | {v['n']} | {v['right']} | {v['inconclusive']} | "
                         f"{v['wrong']} | {v['failed']} | {v['chosen_is_truth']} |")
    return "\n".join(lines + ["", calibration_markdown(result["calibration"])])


def calibration_markdown(cal: dict) -> str:
    """The reliability table and the issue's rates, in Markdown."""
    lines = ["| stated probability of the leading hypothesis | campaigns | mean stated | "
             "leading is the truth |", "|---|---|---|---|"]
    for b in cal["bins"]:
        if b["n"]:
            lines.append(f"| {b['bin']} | {b['n']} | {b['stated']:.2f} | {b['right']:.2f} |")

    lines += ["", "| class of the truth | campaigns | mean stated | leading is the truth |",
              "|---|---|---|---|"]
    lines += [f"| {cls} | {v['n']} | {v['stated']:.2f} | {v['right']:.2f} |"
              for cls, v in cal["by_class"].items()]

    if cal.get("where"):
        lines += ["", "Where the probability goes (mean per class of the truth, and per effect "
                  "of a single): the truth's effect set, larger sets holding it (an effect too "
                  "many), smaller ones within it (an effect missed), other sets, outside the "
                  "candidates.", "",
                  "| class of the truth | campaigns | " + " | ".join(RELATIONS)
                  + " | median D of the effect (design check) |",
                  "|---|---|" + "---|" * (len(RELATIONS) + 1)]
        lines += [f"| {cls} | {v['n']} | " + " | ".join(f"{v[k]:.2f}" for k in RELATIONS)
                  + (f" | {v['median_d']:,.0f} |" if "median_d" in v else " | - |")
                  for cls, v in cal["where"].items()]

    def frac(pair):
        k, n = pair
        return f"{k}/{n} ({100 * k / n:.0f} %)" if n else "-"

    lines += ["", f"- confident wrong (a named verdict that is not the truth): "
              f"{frac((cal['confident_wrong'], cal['n']))}, 95 % upper bound "
              f"{100 * cal['confident_wrong_upper_95']:.1f} %",
              f"- mean log loss of the true hypothesis (nats; lower is better): "
              f"{cal['log_loss']:.2f}" if cal["log_loss"] is not None else "- no probabilities",
              f"- right on none and singles: {frac(cal['right_none_and_singles'])}",
              f"- right on pairs: {frac(cal['right_pairs'])}",
              f"- the same where the design can tell each effect from its absence "
              f"(testbeds.apart.detectability): none and singles "
              f"{frac(cal['right_none_and_singles_tellable'])}, pairs "
              f"{frac(cal['right_pairs_tellable'])}",
              f"- an effect outside the six not named as one of the six: "
              f"{frac(cal['outside_not_named'])}"]
    if cal["untellable"]:
        lines += ["", "Campaigns whose design cannot tell an effect from its absence (an oracle "
                  f"that knows the truth's laws expects less than 2 ln 9 = {TELLABLE_D:.2f} of "
                  "evidence; each effect's distance D):", ""]
        lines += [f"- {u['campaign']}: " + ", ".join(f"{e} {d:.1f}"
                                                     for e, d in u["distances"].items())
                  for u in cal["untellable"]]
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m testbeds.apart.score",
                                     description=__doc__.split("\n\n")[0])
    parser.add_argument("out", type=Path, nargs="+",
                        help="folders written by testbeds.apart.campaigns (scored together)")
    parser.add_argument("--jobs", type=int, default=1, help="campaigns diagnosed at a time")
    parser.add_argument("--boot", type=int, default=50, help="swtlab gap --boot")
    parser.add_argument("--redo", action="store_true", help="diagnose again where a report is")
    parser.add_argument("--regap", action="store_true",
                        help="run swtlab gap again on the databases already processed")
    parser.add_argument("--process-only", action="store_true",
                        help="process the runs into the databases, diagnose nothing")
    parser.add_argument("--json", type=Path, help="write the scores here")
    parser.add_argument("--markdown", action="store_true", help="print Markdown tables")
    args = parser.parse_args(argv)
    folders = [out / p.stem for out in args.out for p in sorted((out / "truth").glob("c*.json"))]
    if not folders:
        parser.error(f"{' '.join(map(str, args.out))}: no campaign (truth/cNNN.json) found")
    start = time.perf_counter()
    with ThreadPoolExecutor(max(args.jobs, 1)) as pool:
        list(pool.map(lambda f: diagnose(f, args.boot, args.redo, args.regap,
                                         args.process_only), folders))
    if args.process_only:
        print(f"{len(folders)} campaigns processed, {time.perf_counter() - start:.0f} s")
        return 0
    result = summarise([r for out in args.out for r in score(out)["campaigns"]])
    result["seconds"] = time.perf_counter() - start
    if args.json:
        _write(args.json, json.dumps(result, indent=1) + "\n")
    if args.markdown:
        print(markdown(result))
    else:
        for r in result["campaigns"]:
            print(f"{r['campaign']}: truth {truth_label(r)}; verdict {r['verdict'] or r['failed']}"
                  f" -> {r['outcome']}")
        for cls, v in result["by_class"].items():
            if v["n"]:
                print(f"{cls}: {v}")
    print(f"{result['n']} campaigns, {result['seconds']:.0f} s")
    return 0


if __name__ == "__main__":
    sys.exit(main())
