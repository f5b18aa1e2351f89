"""``swtlab sim MODEL.toml``: terramechanics curves of a model file, as a long CSV."""

from __future__ import annotations

import argparse
import re
import sys

import numpy as np
import pandas as pd

from swtlab_cli import exit_codes
from swtlab_base.atomic import atomic_file

COLUMNS = ["load_n", "multipass", "gravity_mps2", "slip", "dp_n", "torque_nm", "sinkage_m",
           "resistance_n", "thrust_n", "compaction_resistance_n", "fz_n", "fz_residual_n",
           "converged", "theta1_rad", "theta2_rad", "thetam_rad"]


def parse_values(text: str) -> np.ndarray:
    """``"70,180,300"`` or ``"start:stop:step"`` (stop included) -> array."""
    try:
        if ":" in text:
            start, stop, step = (float(v) for v in text.split(":"))
            if step <= 0 or stop < start:
                raise ValueError
            return np.round(np.arange(start, stop + step / 2, step), 12)
        return np.array([float(v) for v in text.split(",") if v.strip()])
    except ValueError:
        raise argparse.ArgumentTypeError(
            f"{text!r}: expected a list 'a,b,c' or a range 'start:stop:step' (step > 0)") from None


def register(subparsers: argparse._SubParsersAction) -> None:
    p = subparsers.add_parser(
        "sim", help="terramechanics curves of a model file (docs/model-file.md)",
        description="Drawbar pull, torque, sinkage and resistance against slip for every "
                    "load, multipass level and gravity; one CSV row per (load, multipass, "
                    "gravity, slip), SI units in the column names.")
    # let a range that starts negative (--slips -0.1:0.9:0.05) read as a value, not an option
    p._negative_number_matcher = re.compile(r"^-\d*\.?\d")
    p.add_argument("model", help="model file (TOML)")
    p.add_argument("--loads", type=parse_values, required=True,
                   help="wheel loads in N, e.g. 70,180,300")
    p.add_argument("--slips", type=parse_values, required=True,
                   help="slips, a list or start:stop:step, e.g. -0.1:0.9:0.05")
    p.add_argument("--multipass", type=parse_values, default=np.array([0.0]),
                   help="multipass levels (previous passes), default 0")
    p.add_argument("--gravity", type=parse_values, default=None,
                   help="gravity in m/s^2 (default: the model file's)")
    p.add_argument("-o", "--output", help="CSV to write (default: standard output)")
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    from terramechanics import load_model
    from terramechanics.model_file import ModelFileError

    try:
        model = load_model(args.model)
    except (OSError, ModelFileError) as exc:
        print(f"swtlab sim: {exc}", file=sys.stderr)
        return exit_codes.BAD_INPUT
    if np.any(args.loads <= 0) or np.any(args.slips < -1) or np.any(args.slips > 1):
        print("swtlab sim: loads must be > 0 N and slips within [-1, 1]", file=sys.stderr)
        return exit_codes.USAGE
    gravity = np.array([model.gravity_mps2]) if args.gravity is None else args.gravity
    for flag, effect, given in (("--gravity", "reduced_gravity", args.gravity is not None),
                                ("--multipass", "multipass", np.any(args.multipass != 0))):
        if given and effect not in model.effects:
            print(f"swtlab sim: note: {flag} changes nothing while the {effect} effect is off",
                  file=sys.stderr)
    grid = np.meshgrid(args.loads, args.multipass, gravity, args.slips, indexing="ij")
    load, multipass, g, slip = (a.ravel() for a in grid)
    curves = model.curves(load, slip, multipass=multipass, gravity_mps2=g)
    extra = [k for k in curves if k not in COLUMNS]
    table = pd.DataFrame({k: curves[k] for k in COLUMNS + extra})
    if np.all(args.multipass == np.round(args.multipass)):
        table["multipass"] = table["multipass"].astype(int)
    if args.output:
        with atomic_file(args.output, newline="") as stream:
            table.to_csv(stream, index=False, float_format="%.6g")
    else:
        table.to_csv(sys.stdout, index=False, float_format="%.6g")
    failed = int((~table["converged"]).sum())
    if args.output:
        print(f"swtlab sim: {len(table)} rows to {args.output}"
              + (f"; {failed} without vertical equilibrium (converged = False)" if failed else ""),
              file=sys.stderr)
    return exit_codes.OK
