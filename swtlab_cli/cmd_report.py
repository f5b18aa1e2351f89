"""``swtlab report --db URL -o report.html``: one self-contained HTML page per campaign.

The run table, each run's time series with its stable window, the performance curves with
their points and error bars, the load-interpolation check and the exported WPM curves, every
figure embedded (docs/report.md). One campaign: the page is written to -o; several: one page
each, <stem>-<campaign>.html beside it, or only --campaign NAME's page to -o.
"""

from __future__ import annotations

import argparse
import gc
import json
import sys
from pathlib import Path

from swtlab_cli import exit_codes
from swtlab_cli.flags import as_flags


def register(sub: argparse._SubParsersAction) -> None:
    lines = __doc__.splitlines()
    parser = sub.add_parser(
        "report", help="write the campaign report: one self-contained HTML page per campaign",
        description=" ".join(line.strip() for line in lines[2:]))
    parser.add_argument("--db", required=True, help="SQLAlchemy URL of a processed campaign")
    parser.add_argument("-o", "--output", type=Path, required=True,
                        help="HTML page to write (several campaigns: <stem>-<campaign>.html)")
    parser.add_argument("--campaign", help="write only this campaign's page, to --output")
    parser.add_argument("--json", action="store_true",
                        help="print the pages written as JSON ({campaign, path, bytes})")
    parser.add_argument("--quiet", action="store_true", help="no progress bar")
    parser.set_defaults(func=run, cli_parser=parser)


def run(args: argparse.Namespace) -> int:
    # the imports make long-lived objects (modules, classes, registries): no cyclic garbage
    # collection while they load, and none of them traversed by the later ones (gc.freeze):
    # 0.6 s less CPU of the sample campaign's 6-9 s (issue 19 item 5)
    gc.disable()
    try:
        from sqlalchemy.exc import SQLAlchemyError

        from campaign_report import write_report, write_reports
        from swtlab_cli.progress import progress
    finally:
        gc.freeze()
        gc.enable()

    def bar(items: list, desc: str):
        return progress(items, desc=desc, quiet=args.quiet)

    try:
        if args.campaign:
            pages = {args.campaign: write_report(args.db, args.output, args.campaign, bar)}
        else:
            pages = write_reports(args.db, args.output, bar)
    except LookupError as error:
        print(f"swtlab report: {as_flags(str(error.args[0]), args)}", file=sys.stderr)
        return exit_codes.BAD_INPUT
    except SQLAlchemyError as error:
        print(f"swtlab report: {args.db}: cannot read the database "
              f"({type(error).__name__}); check the URL", file=sys.stderr)
        return exit_codes.BAD_INPUT
    except OSError as error:
        print(f"swtlab report: cannot write {error.filename or args.output}: "
              f"{error.strerror or error}", file=sys.stderr)
        return exit_codes.BAD_INPUT
    if args.json:
        print(json.dumps([{"campaign": name, "path": str(path),
                           "bytes": path.stat().st_size} for name, path in pages.items()],
                         indent=1))
    else:
        for name, path in pages.items():
            print(f"campaign {name}: {path} ({path.stat().st_size / 1e6:.1f} MB)")
    return exit_codes.OK
