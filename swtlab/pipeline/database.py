"""The database adapter: a :class:`Campaign` in (``store``), a :class:`Campaign` out
(``load``). The only writer of processed runs: :func:`swtlab.process_into` stores through
:func:`store_one` too."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Any

from swtlab.pipeline.campaign import Campaign, Failure, ProcessedRun

if TYPE_CHECKING:
    from sqlalchemy.orm import Session, sessionmaker


def _content(done: ProcessedRun) -> tuple[str, int] | None:
    """The (sha256, size) of the raw file that ``done`` hashed, or None (hash it again)."""
    return (done.sha256, done.size_bytes) if done.sha256 and done.size_bytes is not None else None


def store_processed(session: Session, done: ProcessedRun, parameters: dict[str, Any], *,
                    allow_run_id_reuse: bool = False) -> bool:
    """Store one processed run in ``session`` (one transaction per run, the caller's): the
    raw file, its result, its soil flow or the failures. An unchanged file already stored
    with these parameters writes nothing; returns whether a new result was stored. A file
    the database refuses (another file's run_id, a name too long) is a failure of stage
    ``store``, recorded with its reason."""
    from softflow.flow_run import SIDE_TOPIC
    from traceability import store_ingested_run
    from traceability.store import RunIdClaimed
    from traceability.store_failures import store_failure
    from traceability.store_flow import store_flow, store_flow_failure
    from traceability.store_results import find_result, params_sha256, store_run_result
    from traceability.text import TextRefused

    def failed(stage: str, run_id: str | None) -> None:
        for f in done.failures:
            if f.stage == stage:
                store_failure(session, done.path, done.sha256, f.stage, f.error_type, f.reason,
                              parameters, run_id)

    if done.run is None or done.streams is None:  # read together: both or neither
        failed("ingest", None)
        return False
    try:
        with session.begin_nested():
            raw_file, _ = store_ingested_run(session, done.run, done.streams,
                                             {**parameters, "derivation": done.run.derivation},
                                             allow_run_id_reuse=allow_run_id_reuse,
                                             content=_content(done))
    except (RunIdClaimed, TextRefused) as error:
        failure = Failure.of(done.path, "store", error)
        if failure not in done.failures:
            done.failures.append(failure)
        failed("store", done.run.run_id)
        return False
    if done.result is None:
        failed("results", done.run.run_id)
        return False
    if find_result(session, raw_file, params_sha256(parameters)):
        return False
    stored = store_run_result(session, raw_file, done.result, parameters)
    if done.flow is not None and done.flow_npz is not None:  # measured and packed together
        store_flow(session, raw_file, stored.window, done.flow.result, done.flow_npz, parameters)
    for f in done.failures:
        if f.stage == "soil_flow":
            store_flow_failure(session, raw_file, SIDE_TOPIC, f.reason, parameters)
    return True


def store_one(session_factory: sessionmaker[Session], done: ProcessedRun,
              parameters: dict[str, Any], *,
              allow_run_id_reuse: bool = False) -> bool:
    """:func:`store_processed` in a transaction of its own (retried on a lock). A run the
    database refuses (a value it cannot hold, a constraint) is rolled back and recorded as a
    failure of stage ``store`` in ``done.failures`` and in the database; the batch goes on.
    A database that is locked or unreachable raises (no run's fault). Returns whether a new
    result was stored."""
    from sqlalchemy.exc import InterfaceError, OperationalError

    from traceability.database import in_transaction
    from traceability.store_failures import store_failure

    try:
        return in_transaction(session_factory, lambda session: store_processed(
            session, done, parameters, allow_run_id_reuse=allow_run_id_reuse))
    except (OperationalError, InterfaceError):
        raise  # the database itself (locked, gone): not this run's fault
    except Exception as error:  # one run the database refuses, not the batch
        failure = Failure.of(done.path, "store", getattr(error, "orig", None) or error)
        done.failures.append(failure)
    run_id = None if done.run is None else done.run.run_id
    in_transaction(session_factory, lambda session: store_failure(
        session, done.path, done.sha256, "store", failure.error_type, failure.reason,
        parameters, run_id))
    return False


def store(campaign: Campaign, db_url: str, *, allow_run_id_reuse: bool = False) -> int:
    """Store every run of ``campaign`` (processed by :func:`swtlab.process_campaign`) in the
    database at ``db_url`` (created or upgraded), one transaction per run; returns the number
    of new results. Storing again changes nothing; a run the database refuses (another
    file's run_id unless ``allow_run_id_reuse``, a value it cannot hold) is a failure of
    stage ``store`` (in ``campaign.failures`` and the database) and the others are stored."""
    from traceability import open_database

    if not any(r.run is not None or r.failures for r in campaign.runs):
        raise ValueError("campaign holds no processed raw files (loaded from a database?)")
    session_factory = open_database(db_url)
    stored = 0
    for done in campaign.runs:
        known = len(done.failures)
        stored += store_one(session_factory, done, campaign.parameters,
                            allow_run_id_reuse=allow_run_id_reuse)
        campaign.failures += done.failures[known:]
    return stored


def load(db_url: str, campaign: str | None = None) -> Campaign:
    """The newest results of every run in the database at ``db_url`` (of the campaign named
    ``campaign``, else of all) as a :class:`Campaign`; its ``runs`` carry path and sha256 of
    each raw file (no ``ingest.Run``), its ``failures`` the files whose newest outcome is a
    failure (file, stage, reason, exception type)."""
    from traceability import open_database
    from traceability.queries import latest_results
    from traceability.store_failures import current_failures

    with open_database(db_url, read_only=True)() as session:
        table = latest_results(session)
        failures = [Failure(row.path, row.stage, row.error, row.failure_type, None)
                    for row in current_failures(session)]
    if campaign is not None:
        if len(table) == 0 or campaign not in set(table["campaign"]):
            known = sorted(set(table["campaign"])) if len(table) else []
            raise ValueError(f"{db_url}: no campaign {campaign!r}; stored: {known}")
        table = table[table["campaign"] == campaign].reset_index(drop=True)
    runs = [ProcessedRun(path=Path(p), sha256=s)
            for p, s in zip(table.get("raw_file_path", []), table.get("raw_file_sha256", []))]
    return Campaign(runs=runs, results=table, failures=failures, source=db_url)
