"""Where the tasks of a run go: local threads, or a dask.distributed cluster.

The tasks are the same function either way (for an atlas ``chunks.atlas_chunk``),
so the results are identical cell for cell.  Only a bounded window of tasks is in
flight at a time: the scheduler never holds millions of tasks, and finished
blocks reach the writing process (and leave it) one by one.
"""

from __future__ import annotations

import contextlib
import logging
import os
import uuid
from collections.abc import Callable, Iterator
from concurrent.futures import FIRST_COMPLETED, ThreadPoolExecutor, wait

from . import __version__
from .errors import StabmapError

CONNECT_TIMEOUT = 20.0  # seconds to reach a scheduler
WORKER_TIMEOUT = 120.0  # seconds to wait for a scheduler's first worker
RETRIES = 2  # re-runs of a task that raised (a worker that dies is handled by the scheduler)


def check_threads(threads, option: str = "threads") -> int:
    if threads is None:
        return os.cpu_count() or 1
    if isinstance(threads, bool) or not float(threads).is_integer() or threads < 1:
        raise StabmapError(f"{option} must be a whole number >= 1, got {threads!r}")
    return int(threads)


@contextlib.contextmanager
def connect(client=None) -> Iterator:
    """A ``dask.distributed.Client`` for ``client``: a Client (used as is) or a scheduler address (opened and closed here)."""
    if client is None or not isinstance(client, str):
        yield client
        return
    from distributed import Client

    try:
        c = Client(client, timeout=CONNECT_TIMEOUT, set_as_default=False)
    except (OSError, TimeoutError, ValueError) as exc:
        raise StabmapError(
            f"cannot reach the dask scheduler at {client!r} ({type(exc).__name__}: {exc}); give its address as "
            "tcp://HOST:8786 and check that 'dask scheduler' runs there"
        ) from None
    try:
        yield c
    finally:
        c.close()


@contextlib.contextmanager
def local_cluster(workers: int) -> Iterator:
    """A Client of a fresh local cluster of ``workers`` processes (one thread each), closed on exit."""
    from distributed import Client, LocalCluster

    workers = check_threads(workers, "workers")
    with LocalCluster(
        n_workers=workers, threads_per_worker=1, processes=True, dashboard_address=":0", silence_logs=logging.ERROR
    ) as cluster, Client(cluster, set_as_default=False) as client:
        yield client


def cluster_threads(client) -> int:
    """Threads of the cluster's workers, after waiting for at least one worker to join."""
    try:
        client.wait_for_workers(1, timeout=WORKER_TIMEOUT)
    except TimeoutError:
        raise StabmapError(
            f"the dask scheduler at {client.scheduler.address} has no workers after {WORKER_TIMEOUT:.0f} s; "
            f"start some with 'dask worker {client.scheduler.address}'"
        ) from None
    versions = set(client.run(_stabmap_version).values())
    if versions != {__version__}:
        raise StabmapError(
            f"the cluster's workers run stabmap {', '.join(sorted(map(str, versions)))}, this process {__version__}; "
            "install the same stabmap on every worker"
        )
    return max(1, sum(client.nthreads().values()))


def _stabmap_version() -> str:
    import stabmap

    return stabmap.__version__


def run_tasks(
    task: Callable,
    args: list[tuple],
    todo: list[int],
    on_result: Callable[[int, object], None],
    *,
    client=None,
    threads: int = 1,
) -> None:
    """Run ``task(*args[i])`` for every i in ``todo``, handing each result to ``on_result(i, result)`` as it finishes.

    On local threads (``client`` None) or on a dask.distributed cluster.  At most
    ``2 * threads + 2`` tasks are in flight.  On any error or Ctrl-C the tasks not
    yet finished are cancelled and the exception propagates; results already
    handed over stay handed over.
    """
    window = 2 * threads + 2
    if client is None:
        executor, options = ThreadPoolExecutor(threads), lambda i: {}
    else:
        token = uuid.uuid4().hex[:8]
        executor = client.get_executor(retries=RETRIES, pure=False)
        name = getattr(task, "__name__", "task").replace("_", "-")

        def options(i):
            return {"key": f"stabmap-{name}-{i}-{token}"}

    pending: dict = {}
    queue = iter(todo)
    try:
        while True:
            for i in queue:
                pending[executor.submit(task, *args[i], **options(i))] = i
                if len(pending) >= window:
                    break
            if not pending:
                break
            for f in wait(set(pending), return_when=FIRST_COMPLETED).done:
                on_result(pending.pop(f), f.result())
    except BaseException:
        for f in pending:
            f.cancel()
        if client is None:  # a thread cannot be stopped mid-task: running ones finish theirs
            executor.shutdown(cancel_futures=True)
        else:  # cluster tasks are cancelled on the scheduler
            executor.shutdown(wait=False)
        raise
    executor.shutdown()
