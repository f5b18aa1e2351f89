"""``swtlab process CAMPAIGN --db URL``: ingest every run, find its stable phase, store its results.

Each run is one transaction: a batch killed midway loses nothing stored, and the
next call finishes it without duplicates (a file already processed with the same
parameters is skipped without being read). Each result is stored with its decimated
traces (``run_results.traces``), which the report draws. A run with side-camera frames
also gets its soil flow over the stable window (``softflow.flow_run``); frames that cannot
be analysed are reported and recorded, and the run's other results are kept.
"""

from __future__ import annotations

import argparse
import sys
import tomllib
from pathlib import Path

from swtlab_cli import exit_codes
from swtlab_cli.progress import progress

CAMPAIGN_SETTINGS = "swtlab.toml"


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
    parser.add_argument("--db", required=True, help="SQLAlchemy URL, e.g. sqlite:///swtlab.sqlite")
    parser.add_argument("--channel-map", help="TOML channel map (path or shipped name)")
    parser.add_argument("--rig-compliance", type=Path,
                        help="TOML file with a [rig_compliance] table (overrides the campaign's)")
    parser.add_argument("--quiet", action="store_true", help="no progress bar")
    parser.set_defaults(func=run)


def _rig_compliance(args: argparse.Namespace):
    from run_results import RigCompliance

    path = args.rig_compliance or (args.campaign / CAMPAIGN_SETTINGS)
    if not path.is_file():
        if args.rig_compliance:
            raise FileNotFoundError(f"{path}: no such file")
        return None
    table = tomllib.loads(path.read_text()).get("rig_compliance")
    if table is None:
        raise ValueError(f"{path}: no [rig_compliance] table")
    return RigCompliance.from_dict(table)


def _soil_flow(session, run_read, raw_file, window, parameters: dict) -> tuple[bool, str | None]:
    """Measure and store the run's soil flow over its stable window: whether one was measured,
    and why not when its frames could not be analysed."""
    from softflow.flow_archive import pack_flow
    from softflow.flow_run import FlowRunError, run_flow
    from traceability.store_flow import store_flow, store_flow_failure

    if not window.found:
        return False, None
    try:
        flow = run_flow(run_read, window.start_s, window.end_s, parameters["flow"]["max_frames"])
    except FlowRunError as error:
        store_flow_failure(session, raw_file, error.channel, error.problem, parameters)
        return False, str(error)
    except Exception as error:  # noqa: BLE001 - one run's camera must not stop the batch
        problem = f"internal error in the flow analysis ({type(error).__name__}: {error})"
        store_flow_failure(session, raw_file, "/camera/side", problem, parameters)
        return False, f"{run_read.source}: /camera/side: {problem}"
    if flow is None:
        return False, None
    store_flow(session, raw_file, window, flow.result, pack_flow(flow.result, flow.first_frame),
               parameters)
    return True, None


def run(args: argparse.Namespace) -> int:
    import ingest
    from ingest.inspect_report import report
    from run_results import process_run
    from softflow.flow_run import MAX_FRAMES
    from stable_phase import StablePhaseParams
    from traceability import open_database, store_ingested_run
    from traceability.hashing import content_sha256
    from traceability.store_flow import stored_flow_failure
    from traceability.store_results import (find_result, params_sha256, processed_file,
                                            store_ingest_failure, store_run_result)

    if not args.campaign.is_dir():
        print(f"swtlab process: {args.campaign}: no such folder", file=sys.stderr)
        return exit_codes.BAD_INPUT
    try:
        rig = _rig_compliance(args)
        paths = ingest.find_runs(args.campaign, channel_map=args.channel_map)
    except (OSError, ValueError, tomllib.TOMLDecodeError, ingest.IngestError) as error:
        print(f"swtlab process: {error}", file=sys.stderr)
        return exit_codes.BAD_INPUT
    if not paths:
        print(f"swtlab process: {args.campaign}: no runs found (MCAP files or folders with "
              "run.json; --channel-map for other files)", file=sys.stderr)
        return exit_codes.BAD_INPUT
    stable_params = StablePhaseParams()
    parameters = {"stable_phase": stable_params.to_dict(), "channel_map": args.channel_map,
                  "rig_compliance": rig.to_dict() if rig else None,
                  "flow": {"max_frames": MAX_FRAMES}}
    params_hash = params_sha256(parameters)
    session_factory = open_database(args.db)
    statuses: dict[str, list[str]] = {"ok": [], "flagged": [], "no_stable_phase": []}
    failed: list[str] = []
    flow_failed: list[str] = []
    flows = up_to_date = 0
    for path in progress(paths, desc="process", quiet=args.quiet):
        sha256, _ = content_sha256(path)
        with session_factory.begin() as session:
            if processed_file(session, path, sha256, params_hash):
                up_to_date += 1
                known = stored_flow_failure(session, path, sha256, params_hash)
                if known is not None:
                    flow_failed.append(f"{path}: {known.channel}: {known.problem}")
                continue
            try:
                run_read = ingest.read_run(path, channel_map=args.channel_map)
            except ingest.IngestError as error:
                store_ingest_failure(session, path, sha256, str(error), parameters)
                failed.append(str(error))
                continue
            raw_file, _ = store_ingested_run(session, run_read, report(run_read)["streams"],
                                             {**parameters, "derivation": run_read.derivation})
            if find_result(session, raw_file, params_hash) is None:
                result = process_run(run_read, stable_params, rig)
                stored = store_run_result(session, raw_file, result, parameters)
                measured, problem = _soil_flow(session, run_read, raw_file, stored.window,
                                               parameters)
                flows += measured
                flow_failed += [problem] if problem else []
                reasons = "; ".join(result.flags)
                statuses.setdefault(result.status, []).append(
                    f"{run_read.run_id}: {reasons}" if reasons else run_read.run_id)
            else:
                up_to_date += 1
    done = sum(len(v) for v in statuses.values())
    print(f"processed {done} of {len(paths)} runs ({up_to_date} already up to date): "
          f"{len(statuses['ok'])} ok, {len(statuses['flagged'])} flagged, "
          f"{len(statuses['no_stable_phase'])} without a stable phase, {len(failed)} failed")
    for status in ("flagged", "no_stable_phase"):
        for line in statuses[status]:
            print(f"  {status}: {line}")
    for line in failed:
        print(f"  failed: {line}")
    if flows or flow_failed:
        print(f"soil flow under the wheel (side camera): measured in {flows} runs"
              + (f", not measured in {len(flow_failed)}" if flow_failed else ""))
    for line in flow_failed:
        print(f"  soil flow not measured: {line}")
    print(f"database: {args.db}  (list the results: swtlab results --db {args.db})")
    return exit_codes.OK if done + up_to_date else exit_codes.BAD_INPUT
