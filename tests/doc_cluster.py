"""The dask cluster a document's cluster blocks run on (tests/test_docs.py, ``<!-- doc-test: cluster -->``)."""

from __future__ import annotations

import contextlib
import os
import re
import signal
import socket
import subprocess
import time
from pathlib import Path

PLACEHOLDER = "HOST:8786"  # the docs' address of a running scheduler, as in tcp://HOST:8786
STARTS_CLUSTER = re.compile(r"^\s*dask (scheduler|worker)\b")


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


class Cluster:
    """One document's dask cluster on loopback: the ``dask scheduler`` and ``dask worker`` lines that started it,
    each a background process group, stopped together by ``stop``."""

    def __init__(self, cwd: Path, env: dict):
        self.cwd, self.env = cwd, env
        self.port = _free_port()
        self.address = f"tcp://127.0.0.1:{self.port}"
        self.procs: list[tuple[str, subprocess.Popen, Path]] = []  # (command as run, process, its log)

    def substitute(self, text: str) -> str:
        return text.replace(PLACEHOLDER, f"127.0.0.1:{self.port}")

    def command(self, line: str) -> tuple[str, str]:
        """The start line as it runs here, and which it starts ("scheduler" or "worker")."""
        kind = STARTS_CLUSTER.match(line).group(1)
        code = re.sub(r"\s+#.*$", "", self.substitute(line)).strip()
        assert kind == "worker" or not re.search(r"\s--(host|port)\b", code), f"the harness sets the scheduler's address: {line!r}"
        # What a cluster on loopback in a test needs, added where the line does not set it: the docs' own lines
        # would listen on every interface at the fixed port 8786, with dashboards, and a worker would take every core.
        if kind == "scheduler":
            options = {"--host": "127.0.0.1", "--port": str(self.port), "--no-dashboard": ""}
        else:
            options = {"--nthreads": "1", "--no-dashboard": ""}
        extra = [f"{flag} {value}".strip() for flag, value in options.items() if not re.search(rf"\s{flag}\b", code)]
        return " ".join([code, *extra]), kind

    @property
    def workers(self) -> int:
        return sum(1 for command, _, _ in self.procs if STARTS_CLUSTER.match(command).group(1) == "worker")

    def start(self, line: str) -> None:
        command, kind = self.command(line)
        assert (kind == "scheduler") == (not self.procs), f"a cluster starts with one scheduler, then workers: {line!r}"
        log = self.cwd / f".cluster-{len(self.procs)}-{kind}.log"
        with log.open("w") as out:
            # Its own session and process group, so that stop() reaches the processes it starts in turn (a
            # worker's nanny starts the worker process) and nothing outlives the document.
            proc = subprocess.Popen(["bash", "-c", command], cwd=self.cwd, env=self.env, stdout=out,
                                    stderr=subprocess.STDOUT, stdin=subprocess.DEVNULL, start_new_session=True)
        self.procs.append((command, proc, log))
        if kind == "scheduler":
            self._wait(lambda client: True, "the scheduler to accept clients")

    def wait_for_workers(self) -> None:
        n = self.workers
        self._wait(lambda client: len(client.nthreads()) >= n, f"{n} worker(s) to join")

    def _wait(self, ready, what: str, timeout: float = 120) -> None:
        from distributed import Client

        deadline = time.monotonic() + timeout
        while True:
            self._check_alive(what)
            try:
                with Client(self.address, timeout=3, set_as_default=False) as client:
                    while not ready(client):
                        self._check_alive(what)
                        assert time.monotonic() < deadline, f"timed out waiting for {what}\n{self.logs()}"
                        time.sleep(0.2)
                    return
            except OSError:  # not listening yet (distributed's connection timeouts are OSErrors)
                assert time.monotonic() < deadline, f"timed out waiting for {what}\n{self.logs()}"
                time.sleep(0.2)

    def _check_alive(self, what: str) -> None:
        dead = [(c, p.returncode) for c, p, _ in self.procs if p.poll() is not None]
        assert not dead, f"while waiting for {what}, {dead} exited\n{self.logs()}"

    def logs(self) -> str:
        return "\n".join(f"--- {command}\n{log.read_text()[-3000:]}" for command, _, log in self.procs)

    def stop(self) -> None:
        """SIGTERM to every process group (workers first), SIGKILL to what is left after 15 s."""
        for _, proc, _ in reversed(self.procs):
            with contextlib.suppress(ProcessLookupError):
                os.killpg(proc.pid, signal.SIGTERM)
        deadline = time.monotonic() + 15
        for _, proc, _ in reversed(self.procs):
            try:
                proc.wait(max(0.1, deadline - time.monotonic()))
            except subprocess.TimeoutExpired:
                with contextlib.suppress(ProcessLookupError):
                    os.killpg(proc.pid, signal.SIGKILL)
                proc.wait()
        for _, proc, _ in self.procs:
            # A group outlives its leader while a member lives (a worker process its nanny left behind), and Linux
            # gives no new process the pid of a group still in use, so this reaches only what is left of ours.
            with contextlib.suppress(ProcessLookupError):
                os.killpg(proc.pid, signal.SIGKILL)


def split_cluster_lines(body: str) -> tuple[list[str], str]:
    """A bash block's lines that start a cluster, and the rest of the block."""
    lines = body.splitlines()
    starts = [i for i, line in enumerate(lines) if STARTS_CLUSTER.match(line)]
    commands = [i for i, line in enumerate(lines) if line.strip() and not line.lstrip().startswith("#")]
    assert starts == commands[: len(starts)], f"the lines that start a cluster come first in their block:\n{body}"
    return [lines[i] for i in starts], "\n".join(line for i, line in enumerate(lines) if i not in starts) + "\n"


def cluster_for(block, cluster: Cluster | None, cwd: Path, env: dict) -> tuple[Cluster, str]:
    """The document's running cluster, started by the block's own start lines or else by the harness, and the
    block's code that runs on it (the start lines taken out, the address put in)."""
    starts, body = split_cluster_lines(block.body) if block.lang == "bash" else ([], block.body)
    schedulers = [line for line in starts if STARTS_CLUSTER.match(line).group(1) == "scheduler"]
    assert len(schedulers) <= 1 and not (schedulers and cluster), f"{block.where()}: one scheduler per document"
    new = cluster is None
    if new:
        cluster = Cluster(cwd, env)
    try:
        if new:
            cluster.start(schedulers[0] if schedulers else "dask scheduler")
        for line in starts:
            if line not in schedulers:
                cluster.start(line)
        if not cluster.workers:
            for _ in range(2):
                cluster.start(f"dask worker tcp://{PLACEHOLDER}")
        cluster.wait_for_workers()
    except BaseException:
        if new:  # the caller never got it, so cannot stop it
            cluster.stop()
        raise
    return cluster, cluster.substitute(body)
