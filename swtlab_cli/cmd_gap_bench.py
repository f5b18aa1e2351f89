"""``swtlab gap-bench --n N --seed S``: the blind gap-diagnosis check (validation.gap_bench)."""

from __future__ import annotations

import argparse
import importlib.util
import json
import sys
import tempfile
from dataclasses import replace
from pathlib import Path

from swtlab_cli import exit_codes
from swtlab_base.atomic import write_atomically


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "gap-bench", help="blind check of `swtlab gap` on virtual campaigns with hidden effects",
        description="Make N virtual-testbed campaigns, each from the model with a hidden effect "
                    "set (none, one or two effects at random strengths); process and diagnose "
                    "each in separate processes that never see the hidden labels; score the "
                    "verdicts against the labels file (docs/gap-report.md).")
    p.add_argument("--n", type=int, default=40, help="number of campaigns (default 40)")
    p.add_argument("--seed", type=int, default=0)
    p.add_argument("--workdir", type=Path, help="keep campaigns, reports and labels here "
                                                "(default: a temporary folder)")
    where = p.add_mutually_exclusive_group()
    where.add_argument("--jobs", type=int, default=2, help="campaigns diagnosed at a time")
    where.add_argument("--dask", metavar="SCHEDULER_ADDRESS",
                       help="make and diagnose the campaigns on this dask.distributed "
                            "scheduler's workers, one task each (they must see --workdir at "
                            "the same path; docs/scale-out.md)")
    p.add_argument("--boot", type=int, default=50, help="bootstrap replicates per diagnosis")
    p.add_argument("--fast", action="store_true",
                   help="small campaigns (2 loads x 3 slips x 2 multipass x 2 gravity)")
    p.add_argument("--smooth-wheel", action="store_true",
                   help="also run every condition with a smooth wheel of the same size on the "
                        "same soil and diagnose both wheels together (what separates the "
                        "soil's slip-sinkage from the lugs')")
    p.add_argument("--truth-laws", choices=("in-family", "held-out"), default="in-family",
                   help="in-family: the diagnosis may use every law of each effect; held-out: "
                        "the law that made each campaign's truth (and its load-varying form) is "
                        "removed from the laws it may use, for every effect (one law of each "
                        "family left out in turn)")
    p.add_argument("--signal-model", choices=("testbed", "second"), default="testbed",
                   help="raw-run generator: the virtual testbed, or the second rig written "
                        "apart from it (validation.second_rig)")
    p.add_argument("--json", type=Path, help="write the score JSON here")
    p.set_defaults(func=run)


def _checkout_on_path() -> bool:
    """The bench's generators (``validation``, ``virtual_testbed``) live in the repository and
    are not installed with swtlab: put the checkout this command runs from (an editable
    install) on the import path. False when there is none (swtlab installed from a wheel)."""
    root = Path(__file__).resolve().parents[1]
    if (root / "validation").is_dir() and (root / "virtual_testbed").is_dir():
        if str(root) not in sys.path:
            sys.path.insert(0, str(root))
        return True
    return importlib.util.find_spec("validation") is not None


def run(args: argparse.Namespace) -> int:
    if not _checkout_on_path():
        print("swtlab gap-bench: the bench's generators (validation, virtual_testbed) are not "
              "installed with swtlab; run it from a swtlab repository checkout "
              "(pip install -e .)")
        return exit_codes.USAGE
    from swtlab_base.cluster import connect
    from validation.gap_bench import FAST_DESIGN, Design, format_score, run_bench

    if args.n < 1:
        print("swtlab gap-bench: --n must be >= 1")
        return exit_codes.USAGE
    design = replace(FAST_DESIGN if args.fast else Design(), smooth_wheel=args.smooth_wheel)
    with tempfile.TemporaryDirectory(prefix="gap-bench-") as tmp:
        workdir = args.workdir or Path(tmp)
        client = None
        try:
            client = connect(args.dask) if args.dask else None
            result = run_bench(args.n, args.seed, workdir, design, args.jobs, args.boot,
                               args.truth_laws, args.signal_model, client)
        except ValueError as exc:
            print(f"swtlab gap-bench: {exc}")
            return exit_codes.BAD_INPUT
        finally:
            if client is not None:
                client.close()
    print(format_score(result))
    t = result["timing_s"]
    print(f"time: generate {t['generate']:.0f} s, process + diagnose "
          f"{t['process_and_diagnose']:.0f} s ({t['jobs']} at a time)")
    if args.json:
        write_atomically(args.json, json.dumps(result, indent=1) + "\n")
    return exit_codes.OK
