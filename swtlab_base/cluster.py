"""Work on a dask.distributed cluster (docs/scale-out.md): :func:`connect` to a scheduler,
:func:`map_in_order` to run one function over many inputs on its workers, results back in
the order of the inputs. ``swtlab process`` (runs), ``swtlab flow`` (frame pairs) and
``swtlab gap-bench`` (campaigns) all use these.

Each task runs numba, OpenCV and BLAS/OpenMP on its share of its host's cores: the cores
the worker may run on split evenly over the task threads (``nthreads``) of all workers on
that host, at least one (:func:`worker_threads`), applied by the ``limit`` the caller
passes (it knows which libraries its tasks load: ``swtlab.pipeline.process.limit_threads``
for runs, ``softflow.threads.limit`` for frame pairs); left alone, every worker would start
a thread per core.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable, Iterator
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from distributed import Client

#: how long :func:`connect` waits for its scheduler
CONNECT_TIMEOUT_S = 20


def connect(address: str) -> Client:
    """A ``dask.distributed.Client`` of the scheduler at ``address``; a one-line
    ``ValueError`` when dask is not installed or the scheduler cannot be reached."""
    try:
        from distributed import Client
    except ImportError:
        raise ValueError("--dask needs dask.distributed (pip install 'dask[distributed]')"
                         ) from None
    try:
        return Client(address, timeout=f"{CONNECT_TIMEOUT_S}s")
    except (OSError, TimeoutError, ValueError) as error:
        raise ValueError(f"--dask {address}: cannot reach the scheduler ({error})") from None


def task_slots(client: Client) -> dict[str, int]:
    """Task threads (``nthreads``) of the client's workers, summed per host."""
    slots: dict[str, int] = {}
    for worker in client.scheduler_info()["workers"].values():
        slots[worker["host"]] = slots.get(worker["host"], 0) + worker["nthreads"]
    return slots


def worker_threads(slots: dict[str, int]) -> int:
    """In a dask worker: the threads each of its tasks may run, ``available_cores() //``
    the task threads on its host (``slots``, :func:`task_slots`; a worker that joined
    since: its own), at least one."""
    from distributed import get_worker

    from swtlab_base.cores import available_cores

    worker = get_worker()
    return max(1, available_cores() // max(1, slots.get(worker.ip, worker.state.nthreads)))


def _capped(fn: Callable[..., Any], limit: Callable[[int], None], slots: dict[str, int],
            *args: Any) -> Any:
    limit(worker_threads(slots))
    return fn(*args)


def map_in_order(client: Client, fn: Callable[..., Any], *iterables: Iterable[Any],
                 limit: Callable[[int], None]) -> Iterator[Any]:
    """``fn(*args)`` for each ``args`` of ``zip(*iterables)``, on the workers of ``client``
    (each task first calls ``limit(threads)`` with its share of its host's cores), yielded
    in input order as they are done; an error raised by ``fn`` is raised here. Arguments
    may be the client's futures (``client.scatter``: data sent once, used by several
    tasks)."""
    work = list(zip(*iterables))
    if not work:
        return
    slots = task_slots(client)
    n = len(work)
    futures = client.map(_capped, [fn] * n, [limit] * n, [slots] * n, *zip(*work), pure=False)
    for future in futures:
        yield future.result()
        future.release()
