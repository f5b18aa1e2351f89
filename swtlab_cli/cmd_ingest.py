"""``swtlab ingest CAMPAIGN --db URL``: read every run and record it in the traceability database."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from swtlab_cli import exit_codes
from swtlab_cli.progress import progress


def register(sub: argparse._SubParsersAction) -> None:
    parser = sub.add_parser(
        "ingest", help="read every run of a campaign folder and record it in the database",
        description="Read every run under CAMPAIGN (MCAP files, CSV run folders, or a lab's own "
                    "files through --channel-map), record raw files, conditions and calibrations "
                    "in the database, and list the runs that could not be read with the reason.")
    parser.add_argument("campaign", type=Path, help="folder of runs (any depth)")
    parser.add_argument("--db", required=True, help="SQLAlchemy URL, e.g. sqlite:///swtlab.sqlite")
    parser.add_argument("--channel-map", type=Path, help="TOML channel map for a lab's own names")
    parser.add_argument("--quiet", action="store_true", help="no progress bar")
    parser.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    import ingest
    from ingest.inspect_report import report
    from traceability import open_database, store_ingested_run
    from traceability.store import StoreOutcome

    if not args.campaign.exists():
        print(f"swtlab ingest: {args.campaign}: no such folder", file=sys.stderr)
        return exit_codes.BAD_INPUT
    paths = ingest.find_runs(args.campaign, channel_map=args.channel_map)
    if not paths:
        print(f"swtlab ingest: {args.campaign}: no runs found (MCAP files or folders with run.json)",
              file=sys.stderr)
        return exit_codes.BAD_INPUT
    session_factory = open_database(args.db)
    counts = {outcome: 0 for outcome in StoreOutcome}
    failures: list[str] = []
    for path in progress(paths, desc="ingest", quiet=args.quiet):
        try:
            run_read = ingest.read_run(path, channel_map=args.channel_map)
        except ingest.IngestError as error:
            failures.append(str(error))
            continue
        parameters = {"channel_map": str(args.channel_map) if args.channel_map else None,
                      "derivation": run_read.derivation}
        with session_factory.begin() as session:
            _, outcome = store_ingested_run(session, run_read, report(run_read)["streams"],
                                            parameters)
        counts[outcome] += 1
    read = sum(counts.values())
    print(f"ingested {read} of {len(paths)} runs: {counts[StoreOutcome.NEW_RUN]} new, "
          f"{counts[StoreOutcome.NEW_VERSION]} new versions, "
          f"{counts[StoreOutcome.UNCHANGED]} unchanged; {len(failures)} failed")
    for line in failures:
        print(f"  failed: {line}")
    print(f"database: {args.db}")
    return exit_codes.OK if read else exit_codes.BAD_INPUT
