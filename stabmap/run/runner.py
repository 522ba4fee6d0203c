"""Where the tasks of a run go: threads in this process, or a dask.distributed cluster.

Dense atlases, adaptive refinement and critical values all hand their work to
``Runner.run``, so each runs here or on a cluster alike and gives the same
cells.  The runner sizes every task from the measured run times of the tasks
before it (``Pace``), keeps a bounded window of tasks in flight (the scheduler
never holds millions of tasks, and finished results reach the calling process
and leave it one by one), and follows the cluster as workers leave and join.

Faults, on a cluster: a worker that dies or restarts costs only its running
tasks, which the scheduler reruns elsewhere (every task is a pure function of
its arguments); a task that raised is retried RETRIES times; a lost scheduler
ends the run with ``SchedulerLost``.  The runner makes no call that goes to
every worker (no ``Client.run``): the stabmap version is checked by each task
(``stabmap.run.tasks.run_task``), so a worker that dies or joins at any moment
of the run, start-up included, is never asked anything.
"""

from __future__ import annotations

import contextlib
import itertools
import logging
import os
import sys
import time
import uuid
from collections.abc import Callable, Iterator
from concurrent.futures import FIRST_COMPLETED, CancelledError, ThreadPoolExecutor, wait
from typing import Protocol

from ..errors import StabmapError, given, param
from ..version import __version__
from .chunks import TASK_SECONDS
from .tasks import run_task

CONNECT_TIMEOUT = 20.0  # seconds to reach a scheduler
WORKER_TIMEOUT = 120.0  # seconds to wait for a scheduler's first worker
RETRIES = 2  # re-runs of a task that raised (a worker that dies is handled by the scheduler)
GRACE_SECONDS = 1.0  # after Ctrl-C, running tasks that finish within this are still kept
TICK_SECONDS = 0.5  # the progress callback's period while no task finishes
SLOTS_SECONDS = 2.0  # how often the runner looks at the cluster's workers
FIRST_TASK_POINTS = 16  # the size of tasks before any task has been timed


class SchedulerLost(StabmapError):
    """The dask scheduler went away mid-run; the CLI exits with status 3 (``--resume`` finishes a file run)."""

    exit_status = 3


def check_threads(threads, name: str = "threads") -> int:
    """A count of threads (or of worker processes: ``name`` the parameter that gave it); None: one per core."""
    if threads is None:
        return os.cpu_count() or 1
    if isinstance(threads, bool) or not float(threads).is_integer() or threads < 1:
        raise StabmapError(f"{given(name, threads)}: must be a whole number >= 1")
    return int(threads)


def check_where(client=None, workers: int | None = None, threads: int | None = None) -> None:
    """Fail before any work on a contradictory choice of where to run."""
    if client is not None and workers is not None:
        raise StabmapError(
            f"give a scheduler ({param('client')}) for an existing cluster or a number of local "
            f"workers ({param('workers')}), not both"
        )
    if (client is not None or workers is not None) and threads is not None:
        raise StabmapError(
            f"{param('threads')} sets the threads of an in-process run; on a cluster each worker has its own "
            "(dask worker --nthreads)"
        )
    if workers is not None:
        check_threads(workers, "workers")
    if threads is not None:
        check_threads(threads, "threads")


class Pace:
    """The seconds a point costs, measured on finished tasks (recent tasks weigh more), and the next task's size.

    Tasks are sized to last about TASK_SECONDS; before the first task is timed they hold FIRST_TASK_POINTS
    points (or what ``seconds_per_point``, a probe's measurement, gives).  Each finished task moves the estimate
    by a fifth of the way to its own cost per point, whatever its size, so the pace follows a scene whose points
    grow dearer within a few tasks.  Towards the end of a batch the tasks shrink, down to an eighth of full size,
    so that every thread finishes at about the same time.
    """

    WEIGHT = 0.2  # weight of the last finished task in the estimate

    def __init__(self, seconds_per_point: float | None = None):
        self.seconds_per_point = seconds_per_point or None

    def record(self, points: int, seconds: float) -> None:
        if points <= 0 or seconds <= 0:
            return
        cost = seconds / points
        old = self.seconds_per_point
        self.seconds_per_point = cost if old is None else old + self.WEIGHT * (cost - old)

    def task_points(self, remaining: int, slots: int) -> int:
        """Points of the next task, of ``remaining`` points still to hand out to ``slots`` threads."""
        cost = self.seconds_per_point
        if cost is None:
            return FIRST_TASK_POINTS
        full = TASK_SECONDS / cost
        return max(1, int(min(full, max(full / 8, remaining / (2 * max(1, slots))))))


class Work(Protocol):
    """What ``Runner.run`` hands out: ``remaining`` points, taken a task at a time."""

    remaining: int

    def take(self, points: int) -> tuple[tuple, object, int]:
        """A task of about ``points`` points (at least one unit): (its arguments after the scene, a handle given back
        with its result, its points)."""


class Runner:
    """Where one run's tasks go: ``client`` None (``threads`` threads here) or a dask.distributed Client."""

    def __init__(self, client, threads: int):
        self.client, self.threads = client, threads
        self.pace = Pace()
        # the seconds of every task handed over, by stage (stabmap.systems.stages), and the most threads seen:
        # what the run's work cost (stabmap.run.costs)
        self.seconds: dict[str, float] = {}
        self.most_threads = threads
        self.workers = 0 if client is not None else 1
        self._looked = -float("inf")
        self._counter = itertools.count()
        self._token = uuid.uuid4().hex[:8]
        if client is not None:
            self.slots()

    @property
    def address(self) -> str:
        return getattr(getattr(self.client, "scheduler", None), "address", "?")

    def slots(self) -> int:
        """Threads to keep busy: this process's, or those of the cluster's workers now (looked up every few seconds,
        so workers that join or leave during the run count)."""
        if self.client is None:
            return self.threads
        now = time.monotonic()
        if now - self._looked >= SLOTS_SECONDS:
            self._looked = now
            try:
                nthreads = self.client.nthreads()
            except Exception as exc:
                self._check_scheduler(exc)
                nthreads = None
            if nthreads is not None:
                self.workers, self.threads = len(nthreads), sum(nthreads.values())
                self.most_threads = max(self.most_threads, self.threads)
        return max(1, self.threads)

    def run(self, task: Callable, scene, work: Work, on_result: Callable[[object, object], None],
            on_tick: Callable[[], None] | None = None) -> None:
        """Run ``task(scene, *args)`` over all of ``work``, handing each result to ``on_result(handle, result)``.

        At most ``2 * slots + 2`` tasks are in flight.  ``on_tick()`` is called at least every TICK_SECONDS.  On
        Ctrl-C, tasks that finish within GRACE_SECONDS are still handed over and the rest are cancelled; on any
        other error the tasks not yet finished are cancelled; either way the exception propagates and results
        already handed over stay handed over.
        """
        pending: dict = {}
        if self.client is None:
            executor = ThreadPoolExecutor(self.threads)

            def submit(args):
                return executor.submit(run_task, __version__, task, scene, *args)
        else:
            executor = self.client.get_executor(retries=RETRIES, pure=False)
            name = getattr(task, "__name__", "task").replace("_", "-")

            def submit(args):
                key = f"stabmap-{name}-{next(self._counter)}-{self._token}"
                return executor.submit(run_task, __version__, task, scene, *args, key=key)

        def hand_over(futures) -> None:
            for f in futures:
                handle, points = pending.pop(f)
                result, seconds, by_stage = self._result(f)
                self.pace.record(points, seconds)
                for k, v in by_stage.items():
                    self.seconds[k] = self.seconds.get(k, 0.0) + v
                on_result(handle, result)

        try:
            while True:
                while work.remaining and len(pending) < 2 * self.slots() + 2:
                    args, handle, points = work.take(self.pace.task_points(work.remaining, self.slots()))
                    pending[submit(args)] = (handle, points)
                if not pending:
                    break
                hand_over(wait(set(pending), timeout=TICK_SECONDS, return_when=FIRST_COMPLETED).done)
                if on_tick is not None:
                    on_tick()
        except BaseException as exc:
            lost = isinstance(exc, SchedulerLost)
            if not lost and self.client is None:
                for f in pending:
                    f.cancel()  # those not started
            if isinstance(exc, KeyboardInterrupt) and pending:
                self._grace(pending, hand_over)
            if self.client is None:  # a thread cannot be stopped mid-task: a running one finishes in the background
                executor.shutdown(wait=False, cancel_futures=True)
            elif not lost:  # cluster tasks are cancelled on the scheduler
                with contextlib.suppress(Exception):
                    executor.shutdown(wait=False)
            raise
        executor.shutdown(wait=False)

    def _grace(self, pending: dict, hand_over) -> None:
        """After Ctrl-C: keep the tasks that finish within GRACE_SECONDS (a second Ctrl-C stops at once)."""
        done = wait(set(pending), timeout=GRACE_SECONDS).done
        with contextlib.suppress(Exception):
            hand_over([f for f in done if not f.cancelled() and f.exception() is None])

    def _result(self, f):
        try:
            return f.result()
        except StabmapError:
            raise
        except Exception as exc:
            self._check_scheduler(exc)
            raise

    def _check_scheduler(self, exc: BaseException | None = None) -> None:
        """Raise SchedulerLost if the client has lost its scheduler (its futures are then cancelled)."""
        if self.client is not None and getattr(self.client, "status", "running") != "running":
            raise SchedulerLost(f"lost the dask scheduler at {self.address} mid-run") from None
        if isinstance(exc, CancelledError) and self.client is not None:
            raise StabmapError(
                f"the dask scheduler at {self.address} cancelled this run's tasks (was the cluster restarted?)"
            ) from None


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
        wait_for_workers(client)
        runner = Runner(client, 1)
        if announce:
            print(
                f"[stabmap] on the dask cluster at {runner.address}: {runner.workers} workers, {runner.threads} threads "
                f"now (workers may join or leave during the run); dashboard {client.dashboard_link}",
                file=sys.stderr,
            )
        yield runner


@contextlib.contextmanager
def quiet_dask_logs(enabled: bool = True) -> Iterator[None]:
    """Silence the client-side logs of dask.distributed (and tornado) in this process while inside: the command
    line reports a lost worker or scheduler in its own words.  The scheduler's and workers' own logs are untouched."""
    if not enabled:
        yield
        return
    import distributed  # noqa: F401 - sets up its loggers' handlers

    handlers = [h for name in ("distributed", "tornado") for h in logging.getLogger(name).handlers]
    levels = [h.level for h in handlers]
    for h in handlers:
        h.setLevel(logging.CRITICAL + 1)
    try:
        yield
    finally:
        for h, level in zip(handlers, levels, strict=True):
            h.setLevel(level)


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
            f"'dask worker' yourself and pass their address ({param('client')})"
        ) from None
    with cluster, Client(cluster, set_as_default=False) as client:
        yield client


def wait_for_workers(client) -> None:
    """Wait for the cluster's first worker (the scheduler alone is asked: no call goes to the workers)."""
    try:
        client.wait_for_workers(1, timeout=WORKER_TIMEOUT)
    except TimeoutError:
        raise StabmapError(
            f"the dask scheduler at {client.scheduler.address} has no workers after {WORKER_TIMEOUT:.0f} s; "
            f"start some with 'dask worker {client.scheduler.address}'"
        ) from None
    except Exception as exc:
        raise SchedulerLost(f"lost the dask scheduler at {client.scheduler.address} ({type(exc).__name__})") from None
