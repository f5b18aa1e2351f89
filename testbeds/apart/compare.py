"""Two diagnoses of the same campaigns side by side: ``python -m testbeds.apart.compare
BEFORE.json AFTER.json``, each written by ``python -m testbeds.apart.score ...
--json`` (the same processed campaigns diagnosed by two versions, ``--regap``). Prints the
calibration figures of both and every campaign whose outcome or leading hypothesis
changed: the paired check of a change to the diagnosis (docs/validation/gap-apart.md)."""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

from testbeds.apart.score import calibration, truth_label


def _fraction(pair: list[int]) -> str:
    return f"{pair[0]}/{pair[1]}"


def figures(rows: list[dict]) -> dict[str, str]:
    """The paired table's figures of one diagnosis' campaign rows."""
    cal = calibration(rows)
    top = cal["bins"][-1]
    right_top = round(top["right"] * top["n"]) if top["n"] else 0
    return {"campaigns": str(len(rows)),
            "confidently wrong": f"{cal['confident_wrong']} "
                                 f"(UB {100 * cal['confident_wrong_upper_95']:.1f} %)",
            "mean log loss of the truth (nats)": f"{cal['log_loss']:.3f}",
            "right on none and singles": _fraction(cal["right_none_and_singles"]),
            "right on pairs": _fraction(cal["right_pairs"]),
            "outside not named as one of the six": _fraction(cal["outside_not_named"]),
            "stated 0.9-1.0: leader right": f"{right_top}/{top['n']}"}


def changed(before: list[dict], after: list[dict]) -> list[tuple[dict, dict]]:
    """Campaigns (in both) whose outcome or leading hypothesis differs."""
    by_name = {r["campaign"]: r for r in after}
    return [(r, by_name[r["campaign"]]) for r in before if r["campaign"] in by_name
            and (r["outcome"], r["leading"]) != (by_name[r["campaign"]]["outcome"],
                                                 by_name[r["campaign"]]["leading"])]


def _lead(r: dict) -> str:
    p = "" if r["p_leading"] is None else f" {r['p_leading']:.2f}"
    return f"{r['leading']}{p} ({r['outcome']})"


def markdown(before: list[dict], after: list[dict]) -> str:
    """The paired table and the changed campaigns, Markdown."""
    a, b = figures(before), figures(after)
    lines = ["| | before | after |", "|---|---|---|"]
    lines += [f"| {k} | {a[k]} | {b[k]} |" for k in a]
    moved = changed(before, after)
    if moved:
        lines += ["", "| campaign | truth | before | after |", "|---|---|---|---|"]
        lines += [f"| {r['campaign']} | {truth_label(r)} | {_lead(r)} | {_lead(s)} |"
                  for r, s in moved]
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m testbeds.apart.compare",
                                     description=__doc__.split("\n\n")[0])
    parser.add_argument("before", type=Path, help="score JSON of the first diagnosis")
    parser.add_argument("after", type=Path, help="score JSON of the second diagnosis")
    args = parser.parse_args(argv)
    rows = []
    for path in (args.before, args.after):
        try:
            rows.append(json.loads(path.read_text())["campaigns"])
        except (OSError, ValueError, KeyError) as e:
            parser.error(f"{path}: not a score JSON of testbeds.apart.score ({e})")
    print(markdown(*rows))
    return 0


if __name__ == "__main__":
    sys.exit(main())
