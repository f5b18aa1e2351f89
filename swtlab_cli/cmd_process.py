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
    from swtlab.pipeline.database import store_one
    from swtlab_base.cluster import connect
    from swtlab_base.cores import available_cores
    from swtlab.pipeline.process import (ProcessSettings, budget_params, find_runs,
                                         process_files, rig_compliance)
    from traceability import open_database
    from traceability.database import in_transaction
    from traceability.hashing import content_sha256
    from traceability.store import mark_missing
    from traceability.store_flow import stored_flow_failure
    from traceability.store_results import params_sha256, processed_file, replace_uncertainty
    from run_results.uncertainty_budget import pool_drift

    try:
        paths = find_runs(args.campaign, args.channel_map)
        settings = ProcessSettings(channel_map=args.channel_map,
                                   rig=rig_compliance(args.campaign, args.rig_compliance),
                                   budget=budget_params(args.campaign))
        client = connect(args.dask) if args.dask else None
    except (OSError, ValueError, tomllib.TOMLDecodeError, ingest.IngestError) as error:
        print(f"swtlab process: {as_flags(str(error), args)}", file=sys.stderr)
        return exit_codes.BAD_INPUT
    parameters = settings.parameters()
    params_hash = params_sha256(parameters)
    session_factory = open_database(args.db)
    statuses: dict[str, list[str]] = {"ok": [], "flagged": [], "no_stable_phase": []}
    failed: list[str] = []
    flow_failed: list[str] = []
    flows = up_to_date = 0
    new: list[tuple] = []   # (path, sha256, result) stored now: their drift is pooled below
    todo: list[tuple] = []  # (path, (sha256, size) or None): not yet processed
    for path in paths:
        try:
            content = content_sha256(path)
        except OSError:
            content = None  # unreadable: process_file records why

        def known(session, path=path, sha256=content and content[0]):
            if sha256 is None or not processed_file(session, path, sha256, params_hash):
                return None
            failure = stored_flow_failure(session, path, sha256, params_hash)
            return [] if failure is None else [f"{path}: {failure.channel}: {failure.problem}"]

        known_flow_failures = in_transaction(session_factory, known)
        if known_flow_failures is not None:
            up_to_date += 1
            flow_failed += known_flow_failures
        else:
            todo.append((path, content))
    # computed by the workers (outside any transaction: no lock held), stored here in order
    computed = process_files([p for p, _ in todo], settings, args.jobs or available_cores(),
                             client=client, contents=[c for _, c in todo], keep_samples=False)
    try:
        for processed in progress(computed, desc="process", total=len(todo), quiet=args.quiet):
            stored = store_one(session_factory, processed, parameters,
                               allow_run_id_reuse=args.allow_run_id_reuse)
            failed += [f.reason if f.error_type == "IngestError"
                       else f"{f.file}: {f.stage}: {f.reason}"
                       for f in processed.failures if f.stage != "soil_flow"]
            if processed.result is None or any(f.stage == "store" for f in processed.failures):
                continue
            if not stored:
                up_to_date += 1
                continue
            result = processed.result
            new.append((processed.path, processed.sha256, result))
            flows += processed.flow is not None
            flow_failed += [f"{processed.run.source}: /camera/side: {f.reason}"
                            for f in processed.failures if f.stage == "soil_flow"]
            reasons = "; ".join(result.flags)
            statuses.setdefault(result.status, []).append(
                f"{result.run_id}: {reasons}" if reasons else result.run_id)
    finally:
        if client is not None:
            client.close()
    missing = in_transaction(session_factory, lambda session: [
        f"{row.path} (run {row.run.run_id})" for row in mark_missing(session, args.campaign)])
    if new:
        def store_pooled(session):
            for (path, sha256, _), pooled in zip(new, pool_drift([r for *_, r in new])):
                replace_uncertainty(session, path, sha256, params_hash, pooled.uncertainty)

        in_transaction(session_factory, store_pooled)
    done = sum(len(v) for v in statuses.values())
    print(f"processed {done} of {len(paths)} runs ({up_to_date} already up to date): "
          f"{len(statuses['ok'])} ok, {len(statuses['flagged'])} flagged, "
          f"{len(statuses['no_stable_phase'])} without a stable phase, {len(failed)} failed")
    for status in ("flagged", "no_stable_phase"):
        for line in statuses[status]:
            print(f"  {status}: {line}")
    for line in failed:
        print(f"  failed: {as_flags(line, args)}")
    for line in missing:
        print(f"  missing: {line}: stored, but no longer in {args.campaign}; its results stay "
              "listed, marked raw_file_missing")
    if flows or flow_failed:
        print(f"soil flow under the wheel (side camera): measured in {flows} runs"
              + (f", not measured in {len(flow_failed)}" if flow_failed else ""))
    for line in flow_failed:
        print(f"  soil flow not measured: {line}")
    print(f"database: {_where(args.db)}  (list the results: swtlab results --db {args.db})")
    return exit_codes.OK if done + up_to_date else exit_codes.BAD_INPUT
