"""Where the tasks of a run go: threads in this process, or a dask.distributed cluster.

Dense atlases, adaptive refinement and critical values all hand their tasks to
``Runner.run``, so each runs here or on a cluster alike and gives the same
cells.  Only a bounded window of tasks is in flight at a time: the scheduler
never holds millions of tasks, and finished results reach the calling process
(and leave it) one by one.
"""

from __future__ import annotations

import contextlib
import logging
import os
import sys
import uuid
from collections.abc import Callable, Iterator
from concurrent.futures import FIRST_COMPLETED, ThreadPoolExecutor, wait
from dataclasses import dataclass

from ..errors import StabmapError
from ..version import __version__

CONNECT_TIMEOUT = 20.0  # seconds to reach a scheduler
WORKER_TIMEOUT = 120.0  # seconds to wait for a scheduler's first worker
RETRIES = 2  # re-runs of a task that raised (a worker that dies is handled by the scheduler)


def check_threads(threads, option: str = "threads") -> int:
    if threads is None:
        return os.cpu_count() or 1
    if isinstance(threads, bool) or not float(threads).is_integer() or threads < 1:
        raise StabmapError(f"{option} must be a whole number >= 1, got {threads!r}")
    return int(threads)


def check_where(client=None, workers: int | None = None, threads: int | None = None) -> None:
    """Fail before any work on a contradictory choice of where to run."""
    if client is not None and workers is not None:
        raise StabmapError(
            "give a scheduler (--scheduler ADDRESS, client=) for an existing cluster or a number of local "
            "workers (--workers N, workers=), not both"
        )
    if (client is not None or workers is not None) and threads is not None:
        raise StabmapError(
            "threads (--threads) sets the threads of an in-process run; on a cluster each worker has its own "
            "(dask worker --nthreads)"
        )
    if workers is not None:
        check_threads(workers, "workers")
    if threads is not None:
        check_threads(threads, "threads")


@dataclass
class Runner:
    """Where one run's tasks go: ``client`` None (``threads`` threads here) or a dask.distributed Client."""

    client: object | None
    threads: int

    def run(self, task: Callable, args: list[tuple], todo: list[int], on_result: Callable[[int, object], None]) -> None:
        """Run ``task(*args[i])`` for every i in ``todo``, handing each result to ``on_result(i, result)`` as it finishes.

        At most ``2 * threads + 2`` tasks are in flight.  On any error or Ctrl-C the tasks not yet finished are
        cancelled and the exception propagates; results already handed over stay handed over.
        """
        window = 2 * self.threads + 2
        if self.client is None:
            executor, options = ThreadPoolExecutor(self.threads), lambda i: {}
        else:
            token = uuid.uuid4().hex[:8]
            executor = self.client.get_executor(retries=RETRIES, pure=False)
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
            if self.client is None:  # a thread cannot be stopped mid-task: running ones finish theirs
                executor.shutdown(cancel_futures=True)
            else:  # cluster tasks are cancelled on the scheduler
                executor.shutdown(wait=False)
            raise
        executor.shutdown()


@contextlib.contextmanager
def start(client=None, *, workers: int | None = None, threads: int | None = None, announce: bool = False) -> Iterator[Runner]:
    """The Runner of one run: ``client`` (a Client or a scheduler address), a local cluster of ``workers``
    processes, or ``threads`` threads here (default: all cores).  ``announce`` prints the cluster and its
    dashboard on stderr."""
    check_where(client, workers, threads)
    with contextlib.ExitStack() as stack:
        if workers is not None:
            client = stack.enter_context(local_cluster(workers))
        elif isinstance(client, str):
            client = stack.enter_context(connect(client))
        if client is None:
            yield Runner(None, check_threads(threads))
            return
        runner = Runner(client, cluster_threads(client))
        if announce:
            print(
                f"[stabmap] on the dask cluster at {client.scheduler.address}: {len(client.nthreads())} workers, "
                f"{runner.threads} threads; dashboard {client.dashboard_link}",
                file=sys.stderr,
            )
        yield runner


@contextlib.contextmanager
def connect(address: str) -> Iterator:
    """A ``dask.distributed.Client`` of the scheduler at ``address``, closed on exit."""
    from distributed import Client

    try:
        c = Client(address, timeout=CONNECT_TIMEOUT, set_as_default=False)
    except (OSError, TimeoutError, ValueError) as exc:
        raise StabmapError(
            f"cannot reach the dask scheduler at {address!r} ({type(exc).__name__}: {exc}); give its address as "
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
    try:
        cluster = LocalCluster(
            n_workers=workers, threads_per_worker=1, processes=True, dashboard_address=":0", silence_logs=logging.ERROR
        )
    except RuntimeError as exc:
        raise StabmapError(
            f"could not start a local cluster of {workers} worker processes ({exc}); from a Python script, run it "
            "under 'if __name__ == \"__main__\":' (the workers import the script), or start 'dask scheduler' and "
            "'dask worker' yourself and pass their address (client=, --scheduler)"
        ) from None
    with cluster, Client(cluster, set_as_default=False) as client:
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
    versions = set(client.run(worker_version).values())
    if versions != {__version__}:
        raise StabmapError(
            f"the cluster's workers run stabmap {', '.join(sorted(map(str, versions)))}, this process {__version__}; "
            "install the same stabmap on every worker"
        )
    return max(1, sum(client.nthreads().values()))


def worker_version() -> str:
    """The stabmap version a worker runs (called on every worker)."""
    from stabmap.version import __version__ as version

    return version
