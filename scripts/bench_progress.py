"""What a user of `stabmap atlas` sees and waits for: the first progress line, how good its first estimate of the
time to go is, how fast Ctrl-C acts and what it keeps, and a worker killed mid-run on a cluster started the
default way (nannies).  Every run is the command line in a subprocess, its standard error read as it comes.

    python scripts/bench_progress.py                          # about 6 minutes on 2 cores
    python scripts/bench_progress.py --baseline /work/main    # the same runs of the code at that path as well
    python scripts/bench_progress.py --quick                  # seconds; run once by the test suite

Columns: "first line" is the first progress line; "first points" the first that counts finished points; "ETA
at 10 %" the time to go the line showed once 10 % of the points were done, against the time the run then took
until it wrote the file ("actual", which includes writing it).  Ctrl-C: SIGINT sent ``--interrupt-at`` seconds
after the first points line; "acted" is the time from the signal to the process's exit; "kept" the points saved
in the checkpoint against those the last line before the signal counted.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import platform
import re
import shutil
import signal
import subprocess
import sys
import tempfile
import threading
import time
from pathlib import Path

HERE = Path(__file__).resolve().parents[1]
NEW = re.compile(r"\[atlas\] ([\d,]+)/([\d,]+) points.*?(?:about ([\d.]+) (s|min|h) to go)?\s*\|")
OLD = re.compile(r"\[atlas\] ([\d,]+)/([\d,]+) chunks of ~([\d,]+) points.*?about ([\d.]+) s to go")
UNIT = {"s": 1, "min": 60, "h": 3600}


def resample_scene(example: str, sizes: dict[str, int], path: Path, code: Path) -> Path:
    """The bundled ``example`` with its grid resampled to ``sizes``, written as TOML (by the code at ``code``)."""
    script = (
        "import sys, stabmap; from stabmap.scene.grid import resample; "
        f"open(sys.argv[1], 'w').write(resample(stabmap.example({example!r}), **{sizes!r}).to_toml())"
    )
    subprocess.run([sys.executable, "-c", script, str(path)], check=True, env=_env(code), cwd=path.parent)
    return path


def _default_sigint() -> None:
    """In the child: Ctrl-C acts as in a terminal even when this script runs in the background (where a shell
    starts it with SIGINT ignored, which a child inherits)."""
    signal.signal(signal.SIGINT, signal.SIG_DFL)


def _env(code: Path) -> dict:
    return dict(os.environ, PYTHONPATH=str(code))


class Watched:
    """A command run with its standard error read as it comes: (seconds since start, text) of every line."""

    def __init__(self, cmd: list[str], code: Path, cwd: Path):
        self.t0 = time.perf_counter()
        self.proc = subprocess.Popen(cmd, stderr=subprocess.PIPE, stdout=subprocess.DEVNULL, env=_env(code), cwd=cwd,
                                     preexec_fn=_default_sigint)
        self.lines: list[tuple[float, str]] = []
        self.reader = threading.Thread(target=self._read, daemon=True)
        self.reader.start()

    def _read(self) -> None:
        buf = b""
        while chunk := os.read(self.proc.stderr.fileno(), 4096):
            buf += chunk
            *whole, buf = re.split(rb"[\r\n]", buf)
            now = time.perf_counter() - self.t0
            self.lines += [(now, w.decode(errors="replace").strip()) for w in whole if w.strip()]

    def wait(self, timeout: float = 3600) -> float:
        self.proc.wait(timeout)
        self.reader.join(5)
        return time.perf_counter() - self.t0

    def progress(self) -> list[tuple[float, int, int, float | None]]:
        """(time, points done, points, seconds to go or None) of every progress line (old or new format)."""
        rows = []
        for t, text in self.lines:
            if m := NEW.search(text):
                eta = float(m[3]) * UNIT[m[4]] if m[3] else None
                rows.append((t, int(m[1].replace(",", "")), int(m[2].replace(",", "")), eta))
            elif m := OLD.search(text):
                per, done, total = int(m[3].replace(",", "")), int(m[1].replace(",", "")), int(m[2].replace(",", ""))
                rows.append((t, done * per, total * per, float(m[4])))
        return rows


def first_lines(scene: Path, code: Path, tmp: Path, extra: list[str]) -> dict:
    """The first progress line, the first points, the ETA at 10 % against the actual time to go, the run's time."""
    out = tmp / "a.nc"
    w = Watched([sys.executable, "-m", "stabmap", "atlas", str(scene), "-o", str(out), *extra], code, tmp)
    total_time = w.wait()
    assert w.proc.returncode == 0, w.lines[-5:]
    wrote = next((t for t, text in w.lines if text.startswith("wrote ")), total_time)
    rows = w.progress()
    any_line = next((t for t, text in w.lines if text.startswith("[atlas]")), math.nan)
    first_points = next((t for t, d, n, _ in rows if d > 0), math.nan)
    at10 = next(((t, eta) for t, d, n, eta in rows if d >= 0.1 * n and eta is not None), (math.nan, math.nan))
    out.unlink(missing_ok=True)
    return {"first line s": any_line, "first points s": first_points, "ETA at 10 % s": at10[1],
            "actual s": wrote - at10[0], "run s": wrote}


def interrupt(scene: Path, code: Path, tmp: Path, extra: list[str], after: float) -> dict:
    """SIGINT ``after`` seconds after the first line that counts points: how long until exit, what is kept."""
    out = tmp / "b.nc"
    w = Watched([sys.executable, "-m", "stabmap", "atlas", str(scene), "-o", str(out), *extra], code, tmp)
    deadline = time.perf_counter() + 600
    while not any(d > 0 for _, d, _, _ in w.progress()):
        if w.proc.poll() is not None or time.perf_counter() > deadline:
            break
        time.sleep(0.05)
    time.sleep(after)
    shown = max((d for _, d, _, _ in w.progress()), default=0)
    t_signal = time.perf_counter()
    w.proc.send_signal(signal.SIGINT)
    w.proc.wait(600)
    acted = time.perf_counter() - t_signal
    kept = _saved_points(out, code)
    shutil.rmtree(str(out) + ".partial", ignore_errors=True)
    return {"signal at s": t_signal - w.t0, "acted s": acted, "status": w.proc.returncode, "shown": shown, "kept": kept}


def _saved_points(out: Path, code: Path) -> int:
    """Points in the finished chunks of ``out``'s checkpoint (or -1 if there is none), read by the code at ``code``."""
    partial = Path(str(out) + ".partial")
    if not partial.exists():
        return -1
    script = (
        "import sys, math; from stabmap.store.checkpoint import Checkpoint; from stabmap.run.chunks import chunk_locations; "
        "c = Checkpoint.open(__import__('pathlib').Path(sys.argv[1])); locs = chunk_locations(c.shape, c.chunks); "
        "print(sum(math.prod(b - a for a, b in locs[i]) for i in c.done()))"
    )
    return int(subprocess.run([sys.executable, "-c", script, str(partial)], capture_output=True, text=True, env=_env(code), check=True).stdout)


def killed_worker(scene: Path, code: Path, tmp: Path, kill_at: float, which: str) -> dict:
    """The issue's reproduction: 'dask scheduler', two default 'dask worker' (with nannies), SIGKILL at ``kill_at``
    s of one worker's 'dask worker' process (``which="nanny"``) or of the process under it that runs the tasks."""
    import psutil

    env = _env(code)
    sched_file = tmp / "scheduler.json"
    sched_file.unlink(missing_ok=True)
    procs = [subprocess.Popen([sys.executable, "-m", "dask", "scheduler", "--host", "127.0.0.1", "--port", "0",
                               "--scheduler-file", str(sched_file)], env=env, cwd=tmp, stdout=subprocess.DEVNULL,
                              stderr=subprocess.DEVNULL)]
    try:
        while not sched_file.exists():
            time.sleep(0.1)
        time.sleep(0.3)
        address = json.loads(sched_file.read_text())["address"]
        for i in range(2):
            procs.append(subprocess.Popen([sys.executable, "-m", "dask", "worker", address, "--nthreads", "1"], env=env,
                                          cwd=tmp, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL))
        time.sleep(8)  # the workers start (the user starts them before the run)
        out = tmp / "c.nc"
        w = Watched([sys.executable, "-m", "stabmap", "atlas", str(scene), "-o", str(out), "--scheduler", address], code, tmp)
        time.sleep(kill_at)
        victim = procs[1].pid if which == "nanny" else psutil.Process(procs[1].pid).children()[-1].pid
        os.kill(victim, signal.SIGKILL)
        total = w.wait()
        rows = w.progress()
        first_points = next((t for t, d, n, _ in rows if d > 0), math.nan)
        last = w.lines[-1][1] if w.lines else ""
        out.unlink(missing_ok=True)
        return {"killed": which, "at s": kill_at, "status": w.proc.returncode, "run s": total,
                "first points s": first_points, "last line": last[:110]}
    finally:
        for p in reversed(procs):
            p.terminate()
        for p in procs:
            try:
                p.wait(20)
            except subprocess.TimeoutExpired:
                p.kill()


def _table(rows: list[dict]) -> str:
    keys = list(rows[0])
    fmt = lambda v: f"{v:.1f}" if isinstance(v, float) else f"{v:,}" if isinstance(v, int) else str(v)
    return "\n".join(["| " + " | ".join(keys) + " |", "|" + "---|" * len(keys)]
                     + ["| " + " | ".join(fmt(r[k]) for k in keys) + " |" for r in rows])


def main(argv: list[str] | None = None) -> dict:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--quick", action="store_true", help="one small scene, no cluster (seconds)")
    ap.add_argument("--baseline", type=Path, help="also run the stabmap checkout at this path")
    ap.add_argument("--interrupt-at", type=float, default=5.0, help="seconds after the first points line to send SIGINT")
    args = ap.parse_args(argv)
    codes = [("this", HERE)] + ([("baseline", args.baseline.resolve())] if args.baseline else [])
    if args.quick:
        cases = [("paper-n3-fixed", {"omega": 60, "m_2": 40})]
    else:
        cases = [("top-cylinder-cavity", {}), ("paper-n1-fixed-1mode", {}), ("paper-n3-fixed", {"omega": 1500, "m_2": 1200})]
    print(f"# machine: {os.cpu_count()} cores, {platform.machine()}, python {platform.python_version()}; --threads 2")
    result = {"first": [], "interrupt": [], "cluster": []}
    with tempfile.TemporaryDirectory() as d:
        tmp = Path(d)
        for example, sizes in cases:
            for label, code in codes:
                scene = resample_scene(example, sizes, tmp / f"{example}.toml", code) if sizes else None
                scene = scene or resample_scene(example, {}, tmp / f"{example}.toml", code)
                name = example + (f" {'x'.join(map(str, sizes.values()))}" if sizes else "")
                result["first"].append({"scene": name, "code": label, **first_lines(scene, code, tmp, ["--threads", "2"])})
                if not args.quick:
                    result["interrupt"].append({"scene": name, "code": label,
                                                **interrupt(scene, code, tmp, ["--threads", "2"], args.interrupt_at)})
        if not args.quick:
            big = resample_scene("paper-n3-fixed", {"omega": 1500, "m_2": 1200}, tmp / "big.toml", HERE)
            for which in ("nanny", "worker"):
                result["cluster"].append({"scene": "paper-n3-fixed 1500x1200", **killed_worker(big, HERE, tmp, 5.0, which)})
    for key, rows in result.items():
        if rows:
            print(f"\n## {key}\n{_table(rows)}")
    return result


if __name__ == "__main__":
    main()
