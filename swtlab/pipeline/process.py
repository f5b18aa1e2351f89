"""Raw files -> per-run results: ``process_file`` (one run, the function every worker runs),
``process_files`` (many, in order: serially, on a process pool or on a dask.distributed
cluster) and ``process_campaign`` (a folder). No database: whoever stores the runs is the
one writer (docs/scale-out.md; ``swtlab.pipeline.into.process_into`` stores them)."""

from __future__ import annotations

import dataclasses
import os
import signal
import sys
import tomllib
from collections.abc import Callable, Iterable, Iterator
from concurrent.futures import ProcessPoolExecutor
from contextlib import contextmanager
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING

from swtlab.pipeline.campaign import Campaign, Failure, FailureKind, ProcessedRun

if TYPE_CHECKING:
    from distributed import Client

    from run_results import RigCompliance
    from run_results.uncertainty_budget import BudgetParams
    from stable_phase import StablePhaseParams

#: prctl(2) option: the signal a process gets when its parent dies (linux/prctl.h)
PR_SET_PDEATHSIG = 1
#: the campaign's settings file (``[rig_compliance]``, ``[uncertainty]``, docs/run-results.md)
CAMPAIGN_SETTINGS = "swtlab.toml"


def _stable_default() -> StablePhaseParams:
    from stable_phase import StablePhaseParams

    return StablePhaseParams()


def _max_frames_default() -> int:
    from softflow.flow_run import MAX_FRAMES

    return MAX_FRAMES


def _budget_default() -> BudgetParams:
    from run_results.uncertainty_budget import BudgetParams

    return BudgetParams()


@dataclass(frozen=True)
class ProcessSettings:
    """How runs are processed: channel map, rig compliance (``run_results.RigCompliance`` or
    None), stable-phase parameters, side-camera frames per flow (0: no soil flow), what the
    uncertainty budget is told (``run_results.uncertainty_budget.BudgetParams``)."""

    channel_map: str | None = None
    rig: RigCompliance | None = None
    stable: StablePhaseParams = field(default_factory=_stable_default)
    max_frames: int = field(default_factory=_max_frames_default)
    budget: BudgetParams = field(default_factory=_budget_default)

    def parameters(self) -> dict:
        """The parameters recorded with (and hashed into) every stored result."""
        return {"stable_phase": self.stable.to_dict(), "channel_map": self.channel_map,
                "rig_compliance": self.rig.to_dict() if self.rig else None,
                "flow": {"max_frames": self.max_frames},
                "uncertainty": self.budget.to_dict()}


def rig_compliance(folder: Path, path: str | Path | None = None) -> RigCompliance | None:
    """The ``[rig_compliance]`` of ``path``, else of ``folder/swtlab.toml``; None when neither
    file exists or the campaign's file has no such table (it may hold ``[uncertainty]``
    alone). A named file that is missing, or without the table, is an error."""
    from run_results import RigCompliance

    source = Path(path) if path else Path(folder) / CAMPAIGN_SETTINGS
    if not source.is_file():
        if path:
            raise FileNotFoundError(f"{source}: no such file")
        return None
    table = tomllib.loads(source.read_text()).get("rig_compliance")
    if table is None and not path:
        return None
    if table is None:
        raise ValueError(f"{source}: no [rig_compliance] table")
    return RigCompliance.from_dict(table)


def budget_params(folder: Path) -> BudgetParams:
    """The ``[uncertainty]`` of ``folder/swtlab.toml`` (``clock_rate_bound_ppm``: the loggers'
    stated clock tolerance; ``zero_age_s``, ``zero_age_min_s``: the longest and shortest time
    from zeroing the load cells to a run's start) as ``BudgetParams``; nothing stated without
    the file or table."""
    from run_results.uncertainty_budget import BudgetParams

    source = Path(folder) / CAMPAIGN_SETTINGS
    table = tomllib.loads(source.read_text()).get("uncertainty", {}) if source.is_file() else {}
    unknown = sorted(set(table) - {"clock_rate_bound_ppm", "zero_age_s", "zero_age_min_s"})
    if unknown:
        raise ValueError(f"{source}: [uncertainty] has unknown key(s) {unknown}")
    return BudgetParams(**{k: float(v) for k, v in table.items()})


def _soil_flow(done: ProcessedRun, settings: ProcessSettings) -> None:
    from softflow.flow_archive import pack_flow
    from softflow.flow_run import FlowRunError, run_flow

    window = done.result.window
    if not window.found or settings.max_frames <= 0:
        return
    try:
        flow = run_flow(done.run, window.start_s, window.end_s, settings.max_frames)
    except FlowRunError as error:
        done.failures.append(Failure(str(done.path), "soil_flow", error.problem,
                                     type(error).__name__, FailureKind.INPUT))
        return
    except Exception as error:  # one run's camera must not stop the batch
        done.failures.append(Failure.of(done.path, "soil_flow", error))
        return
    if flow is not None:
        done.flow, done.flow_npz = flow, pack_flow(flow.result, flow.first_frame)


def process_file(path: Path, settings: ProcessSettings,
                 content: tuple[str, int] | None = None) -> ProcessedRun:
    """Read one raw file, find its stable phase, compute its results and its soil flow. Never
    raises for a bad run: what failed is in ``failures`` (ingest: nothing else is done).
    ``content``: the file's (sha256, size in bytes) when the caller has hashed it already.
    Linear algebra runs on one thread (the arrays are small: several BLAS threads per run
    only contend, with each other and with the other runs' workers)."""
    import ingest
    from ingest.inspect_report import stream_report
    from run_results import process_run
    from softflow.track_run import run_image_slip
    from threadpoolctl import threadpool_limits
    from traceability.hashing import content_sha256

    path = Path(path)
    done = ProcessedRun(path=path, sha256="")
    with threadpool_limits(limits=1, user_api="blas"):  # the libraries imported above
        try:
            done.sha256, done.size_bytes = content or content_sha256(path)
            done.run = ingest.read_run(path, channel_map=settings.channel_map)
            done.streams = stream_report(done.run)
        except Exception as error:  # one bad file must not stop the batch
            done.run = None
            done.failures.append(Failure.of(path, "ingest", error))
            return done
        try:
            done.result = process_run(done.run, settings.stable, settings.rig,
                                      run_image_slip(done.run), settings.budget)
        except Exception as error:
            done.failures.append(Failure.of(path, "results", error))
            return done
        _soil_flow(done, settings)
    return done


@contextmanager
def worker_pool(workers: int) -> Iterator[ProcessPoolExecutor]:
    """``workers`` processes, each limited to its share of this process's cores
    (``swtlab_base.cores.threads_per_worker``). OpenCV's share is set here too while the pool
    runs, for the workers forked from this process to inherit (see
    ``softflow.threads.opencv_threads``)."""
    from softflow.threads import opencv_threads
    from swtlab_base.cores import threads_per_worker

    threads = threads_per_worker(workers)
    with opencv_threads(threads), ProcessPoolExecutor(
            workers, initializer=_start_worker, initargs=(threads, os.getpid())) as pool:
        yield pool


def limit_threads(threads: int) -> None:
    """Run this process's numba, OpenCV and BLAS/OpenMP on at most ``threads`` threads (each
    :func:`worker_pool` worker's initializer, and each dask task's,
    ``swtlab_base.cluster.map_in_order``: N workers each with every core's threads
    oversubscribe the machine; numba's count is the calling thread's). The libraries a run
    loads are imported first: threadpoolctl limits only those loaded."""
    import ingest  # noqa: F401 - loaded before the limits, see above
    import run_results.process  # noqa: F401
    from softflow.threads import limit

    limit(threads)


def _start_worker(threads: int, parent_pid: int) -> None:
    """A worker's start: its share of the threads (:func:`limit_threads`), and its
    end with the batch's process. A batch killed by SIGKILL runs no clean-up, and its forked
    workers, holding both ends of their task queue's pipe, would wait on it for ever; on
    Linux the kernel sends them SIGTERM when their parent dies (``prctl(PR_SET_PDEATHSIG)``,
    prctl(2)), and a worker whose parent died before the request ends at once."""
    limit_threads(threads)
    if sys.platform != "linux":
        return
    import ctypes

    ctypes.CDLL(None, use_errno=True).prctl(PR_SET_PDEATHSIG, signal.SIGTERM)
    if os.getppid() != parent_pid:
        os._exit(1)


def _process(path: Path, settings: ProcessSettings, content: tuple[str, int] | None,
             keep_samples: bool) -> ProcessedRun:
    done = process_file(path, settings, content)
    if not keep_samples and done.run is not None:   # what the writer needs, not the samples
        done.run = dataclasses.replace(done.run, streams={}, channels=done.run.channels.iloc[:0],
                                       frames={})
    return done


def process_files(paths: list[Path], settings: ProcessSettings, jobs: int = 1, *,
                  client: Client | None = None,
                  contents: list[tuple[str, int] | None] | None = None,
                  keep_samples: bool = True) -> Iterator[ProcessedRun]:
    """:func:`process_file` of each of ``paths``, yielded in their order as they are done:
    in this process (``jobs`` 1), on ``jobs`` worker processes (:func:`worker_pool`: each
    on its share of the cores), or on the workers of the ``dask.distributed`` ``client``
    (``swtlab_base.cluster.map_in_order``: each on its share of its host's cores).
    ``contents``: each file's (sha256, size) or None; ``keep_samples=False`` drops each
    run's sample tables (``streams``, ``channels``, ``frames``) before it comes back from a
    worker (results, metadata and problems stay)."""
    if jobs < 1:
        raise ValueError(f"jobs {jobs} must be >= 1")
    work = list(zip(paths, [settings] * len(paths), contents or [None] * len(paths),
                    [keep_samples] * len(paths)))
    if client is not None:
        from swtlab_base.cluster import map_in_order

        yield from map_in_order(client, _process, *zip(*work), limit=limit_threads)
    elif jobs > 1 and len(work) > 1:
        with worker_pool(min(jobs, len(work))) as pool:
            yield from pool.map(_process, *zip(*work))
    else:
        for w in work:
            yield _process(*w)


def campaign_of(runs: list[ProcessedRun], parameters: dict) -> Campaign:
    """The :class:`Campaign` of processed runs (results table of the runs with a result); the
    load cells' drift diffusion of the uncertainty budgets is pooled over these runs."""
    from run_results import results_table
    from run_results.uncertainty_budget import pool_drift

    done = [r for r in runs if r.result is not None]
    for r, pooled in zip(done, pool_drift([r.result for r in done])):
        r.result = pooled
    table = results_table([r.result for r in runs if r.result is not None])
    sources = {r.result.run_id: r for r in runs if r.result is not None}
    if len(table):
        table.insert(2, "raw_file_path", [str(sources[i].path.resolve()) for i in table["run_id"]])
        table.insert(3, "raw_file_sha256", [sources[i].sha256 for i in table["run_id"]])
    return Campaign(runs=runs, results=table,
                    failures=[f for r in runs for f in r.failures], parameters=parameters)


def find_runs(folder: str | Path, channel_map: str | None = None) -> list[Path]:
    """The run files under ``folder``; a one-line error when there is none."""
    import ingest

    folder = Path(folder)
    if not folder.is_dir():
        raise FileNotFoundError(f"{folder}: no such folder")
    paths = ingest.find_runs(folder, channel_map=channel_map)
    if not paths:
        raise ValueError(f"{folder}: no runs found (MCAP files or folders with run.json; "
                         "channel_map for other files)")
    return paths


def _name(path: Path) -> str:
    return path.stem if path.is_file() else path.name


def process_campaign(folder: str | Path, channel_map: str | None = None, jobs: int = 1, *,
                     rig_compliance_file: str | Path | None = None,
                     runs: list[str] | None = None, soil_flow: bool = True,
                     progress: Callable[[Iterator[ProcessedRun]], Iterable[ProcessedRun]]
                     | None = None, client: Client | None = None,
                     keep_samples: bool = True) -> Campaign:
    """Every run under ``folder`` -> :class:`Campaign`, without a database.

    ``channel_map``: TOML map (path or shipped name) for a lab's own files; ``jobs`` > 1 runs
    :func:`process_file` on that many worker processes; ``client``: a
    ``dask.distributed.Client`` whose workers run it instead (they must see ``folder`` at the
    same path; docs/scale-out.md); ``rig_compliance_file``: overrides
    ``folder/swtlab.toml``; ``runs``: only the files whose name (without suffix) is listed;
    ``soil_flow=False`` skips the side-camera analysis; ``progress``: wraps the processed
    runs as they come (e.g. ``tqdm``); ``keep_samples=False``: the runs come back without
    their sample tables (see :func:`process_files`). A run that fails is in ``.failures`` and
    the batch goes on. The load cells' drift diffusion of the uncertainty budgets is pooled
    over every run processed (under ``folder``, or those of ``runs``) with a result, per
    campaign (:func:`campaign_of`); :func:`swtlab.process_into` pools it the same way.
    """
    from softflow.flow_run import MAX_FRAMES

    if jobs < 1:
        raise ValueError(f"jobs {jobs} must be >= 1")
    paths = find_runs(folder, channel_map)
    if runs is not None:
        unknown = sorted(set(runs) - {_name(p) for p in paths})
        if unknown:
            raise ValueError(f"{folder}: no run file(s) {unknown}")
        paths = [p for p in paths if _name(p) in set(runs)]
    settings = ProcessSettings(channel_map=channel_map,
                               rig=rig_compliance(Path(folder), rig_compliance_file),
                               max_frames=MAX_FRAMES if soil_flow else 0,
                               budget=budget_params(Path(folder)))
    done = process_files(paths, settings, jobs, client=client, keep_samples=keep_samples)
    return campaign_of(list(progress(done) if progress else done), settings.parameters())
