"""``swtlab process CAMPAIGN --db URL``: ingest every run, find its stable phase, store its results.

Each run is one transaction: a batch killed midway loses nothing stored, and the
next call finishes it without duplicates (a file already processed with the same
parameters is skipped without being read). Each result is stored with its decimated
traces (``run_results.traces``), which the report draws. A run with side-camera frames
also gets its soil flow over the stable window (``softflow.flow_run``); frames that cannot
be analysed are reported and recorded, and the run's other results are kept.

Runs are computed in ``--jobs`` worker processes (default: the cores this process may run
on), or on a dask.distributed cluster with ``--dask ADDRESS`` (docs/scale-out.md); this
process is the one writer, storing each run in the order of the files as it comes back.
Runs are processed outside any transaction and stored under the database's write lock
(``traceability.database``), so several ``swtlab process`` may write one database at once.
Versions (docs/results.md): a changed file is its run's new current version, another file
claiming a stored run_id is refused unless ``--allow-run-id-reuse``, and stored files gone
from CAMPAIGN are marked missing.

A run that fails at any stage (it cannot be read, its results cannot be computed, the
database refuses it) is listed with file, stage and reason, recorded (``swtlab results``
shows it as ``failed``) and the batch goes on. Exit 0 when at least one run was processed
or already up to date, 3 when none could be, 4 only for a fault outside any run (the
database cannot be opened, for one).
"""

from __future__ import annotations

import argparse
import sys
import tomllib
from pathlib import Path

from swtlab.pipeline.process import CAMPAIGN_SETTINGS
from swtlab_cli import exit_codes
from swtlab_cli.flags import as_flags
from swtlab_cli.progress import progress

def register(sub: argparse._SubParsersAction) -> None:
    parser = sub.add_parser(
        "process", help="ingest and process every run of a campaign into the database",
        description="Read every run under CAMPAIGN (MCAP files, CSV run folders, or a lab's own "
                    "files through --channel-map), find its stable phase, compute its results "
                    "with uncertainties (and the soil flow under the wheel where side-camera "
                    "frames lie in the stable phase) and store everything in the database. "
                    "Runs that cannot be read or have no stable phase, and frames that cannot "
                    "be analysed, are listed with the reason; the batch goes on. Rig compliance: "
                    f"[rig_compliance] in CAMPAIGN/{CAMPAIGN_SETTINGS} or "
                    "--rig-compliance FILE (docs/run-results.md).")
    parser.add_argument("campaign", type=Path, help="folder of runs (any depth)")
    parser.add_argument("--db", required=True,
                        help="database: SQLAlchemy URL (sqlite:///swtlab.sqlite, "
                             "postgresql://user@host/db) or a SQLite file path; created or "
                             "upgraded")
    parser.add_argument("--channel-map", help="TOML channel map (path or shipped name)")
    parser.add_argument("--rig-compliance", type=Path,
                        help="TOML file with a [rig_compliance] table (overrides the campaign's)")
    parser.add_argument("--allow-run-id-reuse", action="store_true",
                        help="store a file that claims the run_id of a run stored from another "
                             "file as that run's new version (default: refused, naming both "
                             "files)")
    where = parser.add_mutually_exclusive_group()
    where.add_argument("--jobs", type=_jobs, default=None,
                       help="worker processes computing runs (default: the cores available "
                            "to this process); 1: all in this process")
    where.add_argument("--dask", metavar="SCHEDULER_ADDRESS",
                       help="compute the runs on this dask.distributed scheduler's workers "
                            "(e.g. tcp://10.0.0.5:8786; they must see CAMPAIGN at the same "
                            "path); this process stores them (docs/scale-out.md)")
    parser.add_argument("--quiet", action="store_true", help="no progress bar")
    parser.set_defaults(func=run, cli_parser=parser)


def _jobs(text: str) -> int:
    try:
        jobs = int(text)
    except ValueError:
        jobs = 0
    if jobs < 1:
        raise argparse.ArgumentTypeError(f"{text!r} is not a whole number >= 1")
    return jobs


def _where(db: str) -> str:
    """``--db`` as given and, for a SQLite file, the file it resolves to (a relative path
    under ``sqlite:///`` said to be one)."""
    from traceability.database import database_file

    found = database_file(db)
    if found is None:
        return db
    path, relative = found
    if not relative:
        return f"{db} = {path}"
    meant = "/" + db.partition(":///")[2]
    return (f"{db} = {path} (sqlite:/// and a relative path: from the working directory; "
            f"an absolute path takes four slashes: sqlite:///{meant})")


def run(args: argparse.Namespace) -> int:
    import ingest
    from swtlab.pipeline.into import process_into
    from swtlab_base.cluster import connect
    from swtlab_base.cores import available_cores

    try:
        client = connect(args.dask) if args.dask else None
    except (OSError, ValueError) as error:
        print(f"swtlab process: {as_flags(str(error), args)}", file=sys.stderr)
        return exit_codes.BAD_INPUT
    try:
        batch = process_into(args.db, args.campaign, args.channel_map,
                             args.jobs or available_cores(),
                             rig_compliance_file=args.rig_compliance,
                             allow_run_id_reuse=args.allow_run_id_reuse, client=client,
                             progress=lambda runs, total: progress(
                                 runs, desc="process", total=total, quiet=args.quiet))
    except (OSError, ValueError, tomllib.TOMLDecodeError, ingest.IngestError) as error:
        print(f"swtlab process: {as_flags(str(error), args)}", file=sys.stderr)
        return exit_codes.BAD_INPUT
    finally:
        if client is not None:
            client.close()
    statuses: dict[str, list[str]] = {"ok": [], "flagged": [], "no_stable_phase": []}
    for processed in batch.stored:
        result = processed.result
        reasons = "; ".join(result.flags)
        statuses.setdefault(result.status, []).append(
            f"{result.run_id}: {reasons}" if reasons else result.run_id)
    failed = [f.line for f in batch.failures]
    done = len(batch.stored)
    print(f"processed {done} of {batch.found} runs ({batch.up_to_date} already up to date): "
          f"{len(statuses['ok'])} ok, {len(statuses['flagged'])} flagged, "
          f"{len(statuses['no_stable_phase'])} without a stable phase, {len(failed)} failed")
    for status in ("flagged", "no_stable_phase"):
        for line in statuses[status]:
            print(f"  {status}: {line}")
    for line in failed:
        print(f"  failed: {as_flags(line, args)}")
    for line in batch.missing:
        print(f"  missing: {line}: stored, but no longer in {args.campaign}; its results stay "
              "listed, marked raw_file_missing")
    if batch.flows or batch.flow_failures:
        print(f"soil flow under the wheel (side camera): measured in {batch.flows} runs"
              + (f", not measured in {len(batch.flow_failures)}" if batch.flow_failures
                 else ""))
    for line in batch.flow_failures:
        print(f"  soil flow not measured: {line}")
    print(f"database: {_where(args.db)}  (list the results: swtlab results --db {args.db})")
    return exit_codes.OK if done + batch.up_to_date else exit_codes.BAD_INPUT
