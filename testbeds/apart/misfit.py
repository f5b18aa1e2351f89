"""What the soil recalibration leaves, per class of the truth, on diagnosed campaigns of the
apart testbed: ``python -m testbeds.apart.misfit DIR [DIR ...]``.

Per campaign ``DIR/cNNN``: the root-mean-square of ``(measured - soil only) / sigma`` over the
drawbar pull, torque and sinkage of every point of its report (``gap.json``: each point's
measured value, noise and the prediction after soil recalibration alone). A campaign with no
missing effect shows what the base model's own error leaves (it is another solver than the
testbed's); an effect whose campaigns leave no more than that is one the diagnosis can read as
base-model error. Printed: per class of the truth, the count and the minimum, median, 90th
percentile and maximum; and each campaign whose report calls "no missing effect" wrongly.
The reports are read as plain JSON (no import of the diagnosis; import contract in
pyproject.toml).
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

import numpy as np

from testbeds.apart.score import CLASSES

QUANTITIES = ("dp_n", "torque_nm", "sinkage_m")


def rms_after_soil(report: dict) -> float:
    """RMS of the standardised misfit after soil recalibration over the report's points."""
    z = [(p[q]["measured"] - p[q]["soil_only"]) / p[q]["sigma"]
         for p in report["points"] for q in QUANTITIES if q in p]
    return float(np.sqrt(np.mean(np.square(z))))


def misfits(folders: list[Path]) -> list[dict]:
    """One row per diagnosed campaign: its name, class, truth and the RMS misfit, and
    whether its verdict wrongly names no missing effect."""
    rows = []
    for out in folders:
        for path in sorted((out / "truth").glob("c*.json")):
            gap = out / path.stem / "gap.json"
            if not gap.exists():
                continue
            truth, report = json.loads(path.read_text()), json.loads(gap.read_text())
            missing = truth["effects"] or truth["outside"]
            rows.append({"campaign": f"{out.name}/{path.stem}", "class": truth["class"],
                         "rms": rms_after_soil(report),
                         "wrong_none": report["verdict"] == [] and bool(missing)})
    return rows


def summary(rows: list[dict]) -> str:
    """Per class the count, minimum, median, 90th percentile and maximum; then each wrong
    "no missing effect" call."""
    lines = ["| class of the truth | campaigns | min | median | 90 % | max |",
             "|---|---|---|---|---|---|"]
    for cls in CLASSES:
        values = np.array([r["rms"] for r in rows if r["class"] == cls])
        if values.size:
            q = np.percentile(values, [0, 50, 90, 100])
            lines.append(f"| {cls} | {values.size} | " + " | ".join(f"{v:.1f}" for v in q)
                         + " |")
    wrong = [r for r in rows if r["wrong_none"]]
    lines += ["", "Called \"no missing effect\" wrongly: " + (", ".join(
        f"{r['campaign']} ({r['class']}) {r['rms']:.1f}" for r in wrong) or "none")]
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m testbeds.apart.misfit",
                                     description=__doc__.split("\n\n")[0])
    parser.add_argument("out", type=Path, nargs="+",
                        help="folders of diagnosed campaigns (testbeds.apart.score)")
    args = parser.parse_args(argv)
    print(summary(misfits(args.out)))
    return 0


if __name__ == "__main__":
    sys.exit(main())
