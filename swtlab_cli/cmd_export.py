"""``swtlab export --db URL -o wpm.csv``: fit the performance curves and write the WPM CSV.

Fits every quantity of every (wheel, soil, multipass, load) group from the newest
results (docs/fitting.md), stores the fits linked to their run results, writes the
WPM CSV (docs/wpm-csv.md) and, once the file is in place, records the export with its sha256
and its fits.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from swtlab_cli import exit_codes


def _degree(text: str) -> int | str:
    if text in ("loo", "aicc"):
        return text
    try:
        return int(text)
    except ValueError:
        raise argparse.ArgumentTypeError("degree is 3..7, 'loo' or 'aicc'") from None


def register(sub: argparse._SubParsersAction) -> None:
    parser = sub.add_parser(
        "export", help="fit the performance curves and write the WPM CSV",
        description=__doc__.splitlines()[2].strip() + " " + " ".join(
            line.strip() for line in __doc__.splitlines()[3:]))
    parser.add_argument("--db", required=True, help="SQLAlchemy URL of a processed campaign")
    parser.add_argument("-o", "--output", type=Path, required=True, help="WPM CSV to write")
    parser.add_argument("--degree", type=_degree, default="loo",
                        help="polynomial degree 3..7, or the automatic choice by 'loo' "
                             "(leave-one-out cross-validation, default) or 'aicc'")
    parser.add_argument("--include-flagged", action="store_true",
                        help="also fit runs whose checks flagged them (default: status ok only)")
    parser.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    from fitting import FittingError
    from swtlab.pipeline.curves import export_from_database

    statuses = ("ok", "flagged") if args.include_flagged else ("ok",)
    try:  # the file is renamed into place before it is recorded
        curves, file_hash = export_from_database(args.db, args.output, degree=args.degree,
                                                 statuses=statuses)
    except (FittingError, ValueError) as error:
        print(f"swtlab export: {args.db}: {error}", file=sys.stderr)
        return exit_codes.BAD_INPUT
    except OSError as error:
        print(f"swtlab export: cannot write {args.output}: {error.strerror or error}",
              file=sys.stderr)
        return exit_codes.BAD_INPUT
    for error in curves.not_fitted:
        print(f"  not fitted: {error}")
    print(f"{len(curves.fits)} curves from {len(curves.table)} runs written to {args.output} "
          f"(sha256 {file_hash[:12]}, inputs {curves.inputs_sha256[:12]})")
    for fit in curves.flagged:
        print(f"  flagged: {fit.quantity} at {fit.load_n:g} N, multipass {fit.multipass}: "
              "the polynomial oscillates between its points; try a lower --degree")
    return exit_codes.OK
