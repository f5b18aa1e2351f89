"""``swtlab export --db URL -o wpm.csv``: fit the performance curves and write the WPM CSV.

Fits every quantity of every (wheel, soil, multipass, load) group from the newest
results (docs/fitting.md), stores the fits linked to their run results, writes the
WPM CSV (docs/wpm-csv.md) and records the export with its sha256 and its fits.
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
    from swtlab.pipeline.curves import export_wpm, fit_curves
    from traceability import open_database
    from traceability.queries import latest_results
    from traceability.store_fits import store_export, store_fits
    from wpm_export.schema import FORMAT

    statuses = ("ok", "flagged") if args.include_flagged else ("ok",)
    session_factory = open_database(args.db)
    with session_factory.begin() as session:
        try:
            curves = fit_curves(latest_results(session), degree=args.degree, statuses=statuses)
        except (FittingError, ValueError) as error:
            print(f"swtlab export: {args.db}: {error}", file=sys.stderr)
            return exit_codes.BAD_INPUT
        stored = store_fits(session, curves.table, curves.fits, curves.options)
        file_hash = export_wpm(curves, args.output)
        store_export(session, args.output, file_hash, curves.inputs_sha256, FORMAT, stored,
                     curves.options)
    for error in curves.not_fitted:
        print(f"  not fitted: {error}")
    print(f"{len(curves.fits)} curves from {len(curves.table)} runs written to {args.output} "
          f"(sha256 {file_hash[:12]}, inputs {curves.inputs_sha256[:12]})")
    for fit in curves.flagged:
        print(f"  flagged: {fit.quantity} at {fit.load_n:g} N, multipass {fit.multipass}: "
              "the polynomial oscillates between its points; try a lower --degree")
    return exit_codes.OK
