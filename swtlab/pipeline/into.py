"""Raw files -> database: ``process_into`` (what ``swtlab process`` does, docs/results.md).

The workers compute the runs outside any transaction; this process is the one writer, storing
each run as it comes back (one transaction per run: a batch killed midway loses nothing
stored, and the next call finishes it without duplicates).
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable, Iterable
from dataclasses import dataclass, field
from functools import partial
from pathlib import Path
from typing import TYPE_CHECKING

from swtlab.pipeline.campaign import Failure, ProcessedRun

if TYPE_CHECKING:
    from distributed import Client
    from sqlalchemy.orm import Session


@dataclass
class StoredBatch:
    """What :func:`process_into` did: ``found`` run files; ``stored``, the runs whose new
    result was stored in this call; ``up_to_date``, runs already stored with these parameters
    (not read again, or read again only to re-pool their drift); ``failures`` of every stage
    but the soil flow; ``flow_failures`` (``file: channel: problem``); ``missing``, stored
    files gone from the folder (``path (run RUN_ID)``, marked missing); the ``db_url``."""

    found: int
    db_url: str
    stored: list[ProcessedRun] = field(default_factory=list)
    up_to_date: int = 0
    failures: list[Failure] = field(default_factory=list)
    flow_failures: list[str] = field(default_factory=list)
    missing: list[str] = field(default_factory=list)

    @property
    def flows(self) -> int:
        """Stored runs with a soil flow measured."""
        return sum(r.flow is not None for r in self.stored)


def _known(session: Session, path: Path, sha256: str | None,
           params_hash: str) -> tuple[str, list[str]] | None:
    """``(campaign, flow failure lines)`` of a file stored with this content and these
    parameters as its run's current version, else None (to be processed)."""
    from traceability.models import RawFile
    from traceability.store_flow import stored_flow_failure
    from traceability.store_results import processed_file

    if sha256 is None:
        return None
    raw_file = session.query(RawFile).filter_by(path=str(path.resolve()), sha256=sha256).first()
    if raw_file is None or not processed_file(session, path, sha256, params_hash):
        return None
    failure = stored_flow_failure(session, path, sha256, params_hash)
    return (raw_file.run.campaign.name,
            [] if failure is None else [f"{path}: {failure.channel}: {failure.problem}"])


def process_into(db_url: str, folder: str | Path, channel_map: str | None = None,
                 jobs: int = 1, *, rig_compliance_file: str | Path | None = None,
                 allow_run_id_reuse: bool = False, client: Client | None = None,
                 progress: Callable[..., Iterable[ProcessedRun]] | None = None
                 ) -> StoredBatch:
    """Process every run under ``folder`` into the database at ``db_url`` (created or
    upgraded) and mark stored files gone from ``folder`` missing.

    A file already stored with the same content and parameters is not processed again; a
    changed file is its run's new version; a file claiming another file's stored run_id is a
    failure of stage ``store`` unless ``allow_run_id_reuse``. The drift diffusion of the
    load cells is pooled as :func:`swtlab.process_campaign` pools it, over every run under
    ``folder`` with a result, per campaign (``run_results.uncertainty_budget.pool_drift``):
    when a campaign gains or changes runs, its runs already stored are read again and their
    budgets replaced, so the rows are those of ``process_campaign`` then ``store``.
    ``jobs``, ``client``, ``channel_map``, ``rig_compliance_file``: as for
    :func:`swtlab.process_campaign`; ``progress``: wraps the computed runs as they come,
    called with ``total=`` the number to compute (e.g. ``tqdm``). A database that cannot be
    opened raises; a run that fails is in ``.failures`` (and recorded) and the batch goes on.
    """
    from run_results.uncertainty_budget import pool_drift
    from swtlab.pipeline.database import store_one
    from swtlab.pipeline.process import (ProcessSettings, budget_params, find_runs,
                                         process_files, rig_compliance)
    from traceability import open_database
    from traceability.database import in_transaction
    from traceability.hashing import content_sha256
    from traceability.store import mark_missing
    from traceability.store_results import params_sha256, replace_uncertainty

    if jobs < 1:
        raise ValueError(f"jobs {jobs} must be >= 1")
    folder = Path(folder)
    paths = find_runs(folder, channel_map)
    settings = ProcessSettings(channel_map=channel_map,
                               rig=rig_compliance(folder, rig_compliance_file),
                               budget=budget_params(folder))
    parameters = settings.parameters()
    params_hash = params_sha256(parameters)
    session_factory = open_database(db_url)
    batch = StoredBatch(found=len(paths), db_url=db_url)
    todo: list[tuple] = []       # (path, (sha256, size) or None): not yet processed
    current: list[tuple] = []    # (path, (sha256, size), campaign): stored and up to date
    for path in paths:
        try:
            content = content_sha256(path)
        except OSError:
            content = None  # unreadable: process_file records why
        known = in_transaction(session_factory, partial(
            _known, path=path, sha256=content and content[0], params_hash=params_hash))
        if known is None:
            todo.append((path, content))
        else:
            current.append((path, content, known[0]))
            batch.up_to_date += 1
            batch.flow_failures += known[1]
    computed = process_files([p for p, _ in todo], settings, jobs, client=client,
                             contents=[c for _, c in todo], keep_samples=False)
    pooled: list[ProcessedRun] = []   # every run with a result: the drift is pooled over them
    for processed in (progress(computed, total=len(todo)) if progress else computed):
        stored = store_one(session_factory, processed, parameters,
                           allow_run_id_reuse=allow_run_id_reuse)
        batch.failures += [f for f in processed.failures if f.stage != "soil_flow"]
        if processed.result is None:
            continue
        pooled.append(processed)
        if any(f.stage == "store" for f in processed.failures):
            continue
        if not stored:
            batch.up_to_date += 1
            continue
        batch.stored.append(processed)
        batch.flow_failures += [f"{processed.run.source}: /camera/side: {f.reason}"
                                for f in processed.failures if f.stage == "soil_flow"]
    batch.missing = in_transaction(session_factory, lambda session: [
        f"{row.path} (run {row.run.run_id})" for row in mark_missing(session, folder)])
    changed = {r.result.campaign for r in pooled}
    again = [(p, c) for p, c, campaign in current if campaign in changed]
    if again:  # their campaign's pool changed: their budgets are made again (no soil flow)
        pooled += [r for r in process_files([p for p, _ in again],
                                             dataclasses.replace(settings, max_frames=0), jobs,
                                             client=client, contents=[c for _, c in again],
                                             keep_samples=False) if r.result is not None]
    if pooled:
        def store_pooled(session: Session) -> None:
            for done, result in zip(pooled, pool_drift([r.result for r in pooled])):
                replace_uncertainty(session, done.path, done.sha256, params_hash,
                                    result.uncertainty)

        in_transaction(session_factory, store_pooled)
    return batch
