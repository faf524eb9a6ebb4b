"""`brdfkit fit … --out … --scheduler ADDRESS` against a real Dask cluster (issue 19): a
`dask scheduler` and a `dask worker` started as separate processes on 127.0.0.1 (never
another address), the command line run as a process of its own.

- a batch runs on the cluster and resumes (before: ``ValueError: No clients found``,
  nothing written);
- a worker SIGKILLed mid-task: the nanny restarts it, the scheduler runs the task again,
  every row is written once;
- the scheduler SIGKILLed mid-batch: one error line, the rows fitted so far kept, a re-run
  fits only the rest;
- an address that answers but is not Dask (a real HTTP server): one line within the
  stated connect timeout (before: hung for 150 s and more); a malformed address: one line
  at once, no ``Client.__del__`` noise (before: a traceback after 20 s).

Every process is started in its own process group and killed with it in a finalizer;
every wait is bounded.
"""

from __future__ import annotations

import contextlib
import http.server
import json
import os
import shutil
import signal
import subprocess
import sys
import threading
import time
from pathlib import Path

import pytest

import brdfkit
from brdfkit.fitting.batch import CONNECT_TIMEOUT_S, STATUS_OK, read_checked

distributed = pytest.importorskip("distributed")

#: The brdfkit under test (the worktree's, or the one PYTHONPATH names) for subprocesses.
SRC = str(Path(brdfkit.__file__).resolve().parents[1])
DASK = shutil.which("dask", path=os.path.dirname(sys.executable)) or shutil.which("dask")
pytestmark = pytest.mark.skipif(DASK is None, reason="the dask command is not installed")
#: Bounds of the waits (seconds): a process starting (imports of dask and brdfkit on a
#: loaded 2-core machine take a few seconds), a whole command-line batch.
START_S = 120.0
#: Where the scheduler's and worker's HTTP servers listen: Dask starts one (health,
#: metrics) even with --no-dashboard, on 0.0.0.0:8787 unless told otherwise.
LOOPBACK_ANY_PORT = "127.0.0.1:0"
BATCH_S = 240.0
ENV = {**os.environ, "PYTHONPATH": os.pathsep.join([SRC, os.environ.get("PYTHONPATH", "")])}
MATERIALS = ("merl:nickel@abc", "merl:violet-rubber@abc", "merl:gold-paint@abc")


def _until(what: str, check, timeout: float, every: float = 0.05):
    t0 = time.monotonic()
    while time.monotonic() - t0 < timeout:
        got = check()
        if got:
            return got
        time.sleep(every)
    raise AssertionError(f"waited {timeout} s for {what}")


def _kill_group(proc: subprocess.Popen) -> None:
    with contextlib.suppress(ProcessLookupError):
        os.killpg(proc.pid, signal.SIGKILL)
    with contextlib.suppress(subprocess.TimeoutExpired):
        proc.wait(timeout=10)


class Cluster:
    """A `dask scheduler` and one `dask worker` (with its nanny), on loopback."""

    def __init__(self, directory: Path, *, workers: int = 1, scheduler_env=None):
        self.dir = directory
        self.procs: list[subprocess.Popen] = []
        sched_file = directory / "scheduler.json"
        self.scheduler = self._start("scheduler", env={**ENV, **(scheduler_env or {})}, cmd=[
            DASK, "scheduler", "--host", "127.0.0.1", "--port", "0", "--no-dashboard",
            "--dashboard-address", LOOPBACK_ANY_PORT, "--scheduler-file", str(sched_file)])

        def address():
            with contextlib.suppress(OSError, ValueError):
                return json.loads(sched_file.read_text())["address"]
            return None

        try:
            self.address = _until("the scheduler's address", address, START_S)
            self.client = distributed.Client(self.address, set_as_default=False,
                                             timeout=START_S)
            if workers:
                self.worker = self._start("worker", cmd=[
                    DASK, "worker", self.address, "--nworkers", "1", "--nthreads", "1",
                    "--host", "127.0.0.1", "--no-dashboard", "--dashboard-address",
                    LOOPBACK_ANY_PORT, "--death-timeout", "60"])
                self.client.wait_for_workers(1, timeout=START_S)
        except BaseException as exc:
            self.stop()
            logs = {p.name: p.read_text(errors="replace")[-1500:]
                    for p in directory.glob("*.log")}
            raise AssertionError(f"the cluster did not start ({exc!r}); logs: {logs}") from exc

    def _start(self, name, cmd, env=ENV) -> subprocess.Popen:
        log = open(self.dir / f"{name}.log", "wb")  # noqa: SIM115 - closed with the process
        proc = subprocess.Popen(cmd, stdout=log, stderr=subprocess.STDOUT, env=env,
                                start_new_session=True)
        log.close()
        self.procs.append(proc)
        return proc

    def worker_pid(self):
        with contextlib.suppress(OSError, distributed.comm.CommClosedError, TimeoutError):
            pids = list(self.client.run(os.getpid).values())
            return pids[0] if len(pids) == 1 else None
        return None

    def stop(self) -> None:
        client = getattr(self, "client", None)
        try:
            with contextlib.suppress(Exception):  # noqa: BLE001 - a possibly dead cluster
                if client is not None:
                    client.close(timeout=5)
        finally:  # the processes go whatever the client did (a CancelledError escapes above)
            for proc in reversed(self.procs):
                _kill_group(proc)


@pytest.fixture(scope="module")
def cluster(tmp_path_factory):
    c = Cluster(tmp_path_factory.mktemp("dask"))
    try:
        yield c
    finally:
        c.stop()


def _cli(*args, **kw) -> subprocess.Popen:
    return subprocess.Popen([sys.executable, "-m", "brdfkit", *args], env=ENV,
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                            start_new_session=True, **kw)


def _finish(proc: subprocess.Popen, timeout: float = BATCH_S):
    try:
        out, err = proc.communicate(timeout=timeout)
    finally:
        _kill_group(proc)
    return proc.returncode, out, err


def _rows(path):
    rows, invalid = read_checked(path)
    assert not invalid, invalid
    keys = [(r["model"], r["target"]) for r in rows]
    assert len(keys) == len(set(keys)), "a row is written twice"
    return {k: r for k, r in zip(keys, rows, strict=True)}


def _brdfkit_tasks(client) -> int:
    """Tasks of brdfkit batches the scheduler has seen (its per-prefix counters)."""
    def count(dask_scheduler):
        return sum(sum(tp.state_counts.values()) for name, tp in
                   dask_scheduler.task_prefixes.items() if name.startswith("brdfkit"))
    return client.run_on_scheduler(count)


def test_batch_runs_on_a_real_scheduler_and_worker_and_resumes(cluster, tmp_path):
    out = tmp_path / "fits.csv"
    before = _brdfkit_tasks(cluster.client)
    args = ["fit", "lambert", *(a for m in MATERIALS[:2] for a in ("--to", m)), "--out",
            str(out), "--scheduler", cluster.address]
    code, stdout, stderr = _finish(_cli(*args))
    assert code == 0, stderr
    rows = _rows(out)
    assert set(rows) == {("lambert", m) for m in MATERIALS[:2]}
    assert all(r["status"] == STATUS_OK for r in rows.values())
    assert _brdfkit_tasks(cluster.client) - before >= 2  # they ran on the cluster
    code, stdout, stderr = _finish(_cli(*args))
    assert code == 0 and "0 fitted now, 2 already there" in stdout, (stdout, stderr)


def test_worker_killed_mid_task(cluster, tmp_path):
    """The worker process is SIGKILLed while it runs a fit (the first fit in a fresh process
    takes seconds: brdfkit is imported, Numba's kernels loaded; hence the restart first);
    its nanny starts a new one and the scheduler gives it the task again. Every row once,
    every row ok, exit 0."""
    out = tmp_path / "fits.csv"
    cluster.client.restart(timeout=START_S)  # a fresh worker process, no brdfkit loaded
    old = _until("the worker's pid", cluster.worker_pid, START_S)
    proc = _cli("fit", "ward", *(a for m in MATERIALS for a in ("--to", m)), "--out", str(out),
                "--scheduler", cluster.address)
    try:
        busy = _until("a task on the worker",
                      lambda: [k for ks in cluster.client.processing().values() for k in ks],
                      START_S)
        time.sleep(0.5)  # inside the task: its first fit takes seconds (above)
        assert not out.exists(), "the fit finished before the kill; the test needs a slower one"
        os.kill(old, signal.SIGKILL)
        new = _until("a new worker", lambda: (p := cluster.worker_pid()) not in (None, old)
                     and p, START_S, every=0.5)
    finally:
        code, stdout, stderr = _finish(proc)
    assert busy and new != old
    assert code == 0, stderr
    rows = _rows(out)
    assert set(rows) == {("ward", m) for m in MATERIALS}
    assert all(r["status"] == STATUS_OK for r in rows.values()), rows


def test_a_task_whose_worker_always_dies_is_an_error_row_and_exit_1(tmp_path):
    """With Dask's allowed-failures at 0, the first worker death while a task runs makes
    it a KilledWorker: its row says so (status error), the batch exits 1 naming it, and
    a re-run retries it."""
    out = tmp_path / "fits.csv"
    c = Cluster(tmp_path, scheduler_env={"DASK_DISTRIBUTED__SCHEDULER__ALLOWED_FAILURES": "0"})
    try:
        old = _until("the worker's pid", c.worker_pid, START_S)
        proc = _cli("fit", "ward", "--to", MATERIALS[0], "--out", str(out), "--scheduler",
                    c.address)
        try:
            _until("the task on the worker",
                   lambda: [k for ks in c.client.processing().values() for k in ks], START_S)
            time.sleep(0.5)  # inside the task: a fresh worker's first fit takes seconds
            assert not out.exists(), "the fit finished before the kill"
            os.kill(old, signal.SIGKILL)
            code, stdout, stderr = _finish(proc, timeout=START_S)
        finally:
            _kill_group(proc)
    finally:
        c.stop()
    assert code == 1, (stdout, stderr)
    lines = stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith(
        f"brdfkit: error: 1 of 1 fits failed ({MATERIALS[0]} (ward): dask: "), stderr
    assert "died" in lines[0]  # Dask's KilledWorker: "... workers died while running it"
    [row] = _rows(out).values()
    assert row["status"] == "error" and row["message"].startswith("dask: ")


def test_scheduler_going_away_mid_batch(tmp_path):
    """The scheduler is SIGKILLed once a few rows are on disk: the batch ends with one
    error line (status 2), the rows stay, and a re-run (here on local processes) fits only
    the others."""
    out = tmp_path / "fits.csv"
    c = Cluster(tmp_path)
    try:
        proc = _cli("fit", "lambert", "--to", "merl:all@abc", "--out", str(out),
                    "--scheduler", c.address)
        try:
            _until("3 rows", lambda: out.exists() and len(read_checked(out)[0]) >= 3,
                   BATCH_S, every=0.02)
            _kill_group(c.scheduler)
            t0 = time.monotonic()
            code, stdout, stderr = _finish(proc, timeout=60)
            seconds = time.monotonic() - t0
        finally:
            _kill_group(proc)
    finally:
        c.stop()
    kept = _rows(out)
    assert code == 2, (stdout, stderr)
    lines = stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("brdfkit: error: the Dask scheduler"), stderr
    assert f"{len(kept)} of 100 rows are in" in lines[0]
    assert 3 <= len(kept) < 100 and seconds < CONNECT_TIMEOUT_S + 20
    code, stdout, stderr = _finish(_cli("fit", "lambert", "--to", "merl:all@abc", "--out",
                                        str(out)))
    assert code == 0, stderr
    assert f"{100 - len(kept)} fitted now, {len(kept)} already there" in stdout
    assert len(_rows(out)) == 100


def test_a_scheduler_without_workers_is_said_and_ctrl_c_stops(tmp_path):
    """The jobs wait for a worker (one may join later), and the user is told so in one
    line; Ctrl-C (SIGINT to the process group, as a terminal sends it) ends the wait."""
    c = Cluster(tmp_path, workers=0)
    out = tmp_path / "fits.csv"
    try:
        proc = _cli("fit", "lambert", "--to", MATERIALS[0], "--out", str(out),
                    "--scheduler", c.address)
        guard = threading.Timer(START_S, _kill_group, [proc])  # bounds the readline
        guard.start()
        try:
            note = proc.stderr.readline()
            os.killpg(proc.pid, signal.SIGINT)
            code, stdout, stderr = _finish(proc, timeout=30)
        finally:
            guard.cancel()
            _kill_group(proc)
    finally:
        c.stop()
    assert note.startswith(f"brdfkit: note: the Dask scheduler {c.address} has no worker yet"), \
        note
    # the one line and status of every interrupted command (130 = 128 + SIGINT)
    assert code == 130 and stderr.strip().splitlines() == [
        f"brdfkit: interrupted: 0 of 1 rows are in {out}; re-run the same command to "
        "resume"], stderr


def test_a_worker_address_is_not_a_scheduler(cluster, tmp_path):
    """Given the worker's address by mistake (it speaks Dask, but is no scheduler)."""
    worker = next(iter(cluster.client.scheduler_info()["workers"]))
    code, stdout, stderr = _finish(_cli("fit", "lambert", "--to", MATERIALS[0], "--out",
                                        str(tmp_path / "fits.csv"), "--scheduler", worker),
                                   timeout=60)
    assert code == 2 and stderr.strip().splitlines() == [
        f"brdfkit: error: --scheduler {worker}: answers as a Dask Worker, not a scheduler; "
        "give the scheduler's address"], stderr


@contextlib.contextmanager
def _http_server():
    """A real HTTP server on a free loopback port: it accepts a TCP connection and
    never answers Dask's handshake as Dask would."""
    server = http.server.ThreadingHTTPServer(("127.0.0.1", 0),
                                             http.server.SimpleHTTPRequestHandler)
    thread = threading.Thread(target=server.serve_forever, daemon=True)
    thread.start()
    try:
        yield f"tcp://127.0.0.1:{server.server_address[1]}"
    finally:
        server.shutdown()
        server.server_close()


def test_an_address_that_is_not_dask_fails_within_the_timeout(tmp_path):
    out = tmp_path / "fits.csv"
    with _http_server() as address:
        t0 = time.monotonic()
        code, stdout, stderr = _finish(_cli("fit", "lambert", "--to", MATERIALS[0], "--out",
                                            str(out), "--scheduler", address),
                                       timeout=CONNECT_TIMEOUT_S + 60)
        seconds = time.monotonic() - t0
    assert code == 2
    assert stderr.strip().splitlines() == [stderr.strip()], stderr
    assert stderr.startswith(f"brdfkit: error: --scheduler {address}: cannot connect")
    assert f"within {CONNECT_TIMEOUT_S:g} s" in stderr
    # the connect timeout, plus the command's start (~2 s, more on a loaded machine)
    assert CONNECT_TIMEOUT_S <= seconds < CONNECT_TIMEOUT_S + 15, seconds
    assert not out.exists()


@pytest.mark.parametrize("address", ["tcp://127.0.0.1:notaport", "foo://bar",
                                     "tcp://127.0.0.1:99999"])
def test_a_malformed_address_is_one_line_at_once(tmp_path, address):
    t0 = time.monotonic()
    code, stdout, stderr = _finish(_cli("fit", "lambert", "--to", MATERIALS[0], "--out",
                                        str(tmp_path / "fits.csv"), "--scheduler", address),
                                   timeout=60)
    seconds = time.monotonic() - t0
    assert code == 2
    lines = stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith(
        f"brdfkit: error: --scheduler {address!r} is not a Dask scheduler address; expected "
        "[tcp://]HOST:PORT"), stderr
    assert "__del__" not in stderr and "Traceback" not in stderr
    assert seconds < CONNECT_TIMEOUT_S, seconds  # no connect attempt at all
