"""The database adapter: a :class:`Campaign` in (``store``), a :class:`Campaign` out
(``load``). The only writer of processed runs: the CLI stores through
:func:`store_processed` too."""

from __future__ import annotations

from pathlib import Path

from swtlab.pipeline.campaign import Campaign, Failure, ProcessedRun


def store_processed(session, done: ProcessedRun, parameters: dict, *,
                    allow_run_id_reuse: bool = False) -> bool:
    """Store one processed run in ``session`` (one transaction per run, the caller's): the
    raw file, its result, its soil flow or the failures. An unchanged file already stored
    with these parameters writes nothing; returns whether a new result was stored. A file
    the database refuses (another file's run_id, a name too long) is a failure of stage
    ``store``, recorded with its reason."""
    from softflow.flow_run import SIDE_TOPIC
    from traceability import store_ingested_run
    from traceability.store import RunIdClaimed
    from traceability.text import TextRefused
    from traceability.store_flow import store_flow, store_flow_failure
    from traceability.store_results import (find_result, params_sha256, store_ingest_failure,
                                            store_run_result)

    ingest_failures = [f for f in done.failures if f.stage == "ingest"]
    if done.run is None:
        for f in ingest_failures:
            store_ingest_failure(session, done.path, done.sha256, f.reason, parameters)
        return False
    try:
        with session.begin_nested():
            raw_file, _ = store_ingested_run(session, done.run, done.streams,
                                             {**parameters, "derivation": done.run.derivation},
                                             allow_run_id_reuse=allow_run_id_reuse)
    except (RunIdClaimed, TextRefused) as error:
        failure = Failure(str(done.path), "store", str(error))
        if failure not in done.failures:
            done.failures.append(failure)
        store_ingest_failure(session, done.path, done.sha256, str(error), parameters)
        return False
    if done.result is None or find_result(session, raw_file, params_sha256(parameters)):
        return False
    stored = store_run_result(session, raw_file, done.result, parameters)
    if done.flow is not None:
        store_flow(session, raw_file, stored.window, done.flow.result, done.flow_npz, parameters)
    for f in done.failures:
        if f.stage == "soil_flow":
            store_flow_failure(session, raw_file, SIDE_TOPIC, f.reason, parameters)
    return True


def store(campaign: Campaign, db_url: str, *, allow_run_id_reuse: bool = False) -> int:
    """Store every run of ``campaign`` (processed by :func:`swtlab.process_campaign`) in the
    database at ``db_url`` (created or upgraded), one transaction per run; returns the number
    of new results. Storing again changes nothing. A file claiming the run_id of a run stored
    from another file is refused (a ``store`` failure, added to ``campaign.failures``) unless
    ``allow_run_id_reuse``."""
    from traceability import open_database
    from traceability.database import in_transaction

    if not any(r.run is not None or r.failures for r in campaign.runs):
        raise ValueError("campaign holds no processed raw files (loaded from a database?)")
    session_factory = open_database(db_url)
    stored = 0
    for done in campaign.runs:
        known = len(done.failures)
        stored += in_transaction(session_factory, lambda session, done=done: store_processed(
            session, done, campaign.parameters, allow_run_id_reuse=allow_run_id_reuse))
        campaign.failures.extend(done.failures[known:])  # refused by the database
    return stored


def load(db_url: str, campaign: str | None = None) -> Campaign:
    """The newest results of every run in the database at ``db_url`` (of the campaign named
    ``campaign``, else of all) as a :class:`Campaign`; its ``runs`` carry path and sha256 of
    each raw file (no ``ingest.Run``), its ``failures`` the files that could not be read."""
    from sqlalchemy import select

    from traceability import open_database
    from traceability.models import IngestFailure
    from traceability.queries import latest_results

    with open_database(db_url, read_only=True)() as session:
        table = latest_results(session)
        failures = [Failure(row.path, "ingest", row.error)
                    for row in session.scalars(select(IngestFailure)).all()]
    if campaign is not None:
        if len(table) == 0 or campaign not in set(table["campaign"]):
            known = sorted(set(table["campaign"])) if len(table) else []
            raise ValueError(f"{db_url}: no campaign {campaign!r}; stored: {known}")
        table = table[table["campaign"] == campaign].reset_index(drop=True)
    runs = [ProcessedRun(path=Path(p), sha256=s)
            for p, s in zip(table.get("raw_file_path", []), table.get("raw_file_sha256", []))]
    return Campaign(runs=runs, results=table, failures=failures, source=db_url)
