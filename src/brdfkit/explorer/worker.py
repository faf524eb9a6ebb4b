"""
The explorer's compute, off the web server: one worker process and fit processes
================================================================================

Why a process. Numba's kernels hold the GIL, so a model computed in a thread of the web
server stops every other request (issue 19: a pumped model with ``times: 8`` held the
server for over 12 minutes, ``/api/catalog`` waited, Ctrl-C went unanswered), and a
thread cannot be stopped. So the views, verdicts and exports run in **one worker
process** (:class:`Worker`; one, because the machine has 2 cores and the web server needs
the other, and because its model cache then serves every request), one job at a time,
and each request has a **time budget** (``--budget``, :data:`BUDGET_S`): a job that is
still running at its deadline has its worker killed (SIGKILL) and a new one started, and
the request answers at once with what was done and an error for the rest, which the
page shows. A request that cannot start before its deadline (the worker busy with
others) answers "busy"; at most :data:`MAX_WAITING` wait.

A fit (minutes) runs in a **process of its own** (:class:`Fits`), at most :data:`MAX_FITS`
at once, killed after :data:`FIT_BUDGET_S`; its progress comes back through a pipe.

The worker and fit processes run in sessions of their own (Ctrl-C at the terminal reaches
the server, which stops them), and exit when the server process is gone.
"""

from __future__ import annotations

import asyncio
import itertools
import os
import socket
import subprocess
import sys
import threading
import time
from multiprocessing.connection import Connection

from brdfkit.errors import BrdfkitError
from brdfkit.explorer.guard import RequestError

__all__ = ["Worker", "Fits", "OverBudget", "BUDGET_S", "MAX_WAITING", "FIT_BUDGET_S",
           "MAX_FITS", "SHUTDOWN_GRACE_S"]

#: Seconds one request may compute by default (``brdfkit explore --budget``): a slider move
#: takes 0.03-0.1 s, a new pumped model 2-13 s (times 1-3, measured), a new MERL material's
#: verdict ~6 s, the worker's cold start ~2-5 s; a pumped model with times 8 takes over 12 min.
BUDGET_S = 30.0
#: Requests waiting for the worker at once; more are answered "busy" (the page sends one
#: views and one verdict request at a time; several pages or a script may send more).
MAX_WAITING = 8
#: Fits running at once: each takes a core for seconds to minutes (the machine has two).
MAX_FITS = 1
#: Seconds a fit may run: a MERL material fit takes ~5-60 s.
FIT_BUDGET_S = 600.0
#: Fit records kept for ``GET /api/fit/{id}`` (the oldest finished are forgotten).
MAX_FIT_RECORDS = 64
#: Seconds the server waits for running requests on Ctrl-C/SIGTERM before cancelling them.
SHUTDOWN_GRACE_S = 1.0
#: Seconds between looks at a busy worker by a waiting request (cheap: a lock test).
_SLOT_POLL_S = 0.01
#: Progress messages a fit sends per second at most (the page polls every 0.5 s).
_PROGRESS_HZ = 10.0


class OverBudget(BrdfkitError):
    """A request that ran out of its time budget: *parts* holds what was done; *started*:
    whether its job ran (else the worker was busy with others all along); *warm*: the
    worker had finished warming up when the job started (so the job itself was slow)."""

    def __init__(self, message: str, parts: dict, *, started: bool, warm: bool = False):
        super().__init__(message)
        self.parts, self.started, self.warm = parts, started, warm


def _start_child(kind: str):
    """Start a child process (``python -c`` running :func:`_child` *kind*) in a session of
    its own — Ctrl-C at the terminal reaches the server only, which stops its children —
    and return ``(process, connection)``. A plain interpreter rather than
    multiprocessing's spawn: the server's ``__main__`` (a user's script) is not re-run."""
    ours, theirs = socket.socketpair()
    code = "import sys; from brdfkit.explorer.worker import _child; _child(*sys.argv[1:])"
    try:
        proc = subprocess.Popen([sys.executable, "-c", code, kind, str(theirs.fileno()),
                                 str(os.getpid())], pass_fds=(theirs.fileno(),),
                                stdin=subprocess.DEVNULL, start_new_session=True)
    finally:
        theirs.close()
    return proc, Connection(ours.detach())


def _child(kind: str, fd: str, ppid: str) -> None:
    """A child's entry: exit when the server process is gone, then run the worker or a
    fit over the connection on *fd*."""
    conn = Connection(int(fd))

    def watch():
        while os.getppid() == int(ppid):
            time.sleep(0.5)
        os._exit(0)
    threading.Thread(target=watch, daemon=True, name="brdfkit parent watch").start()
    (_worker_main if kind == "worker" else _fit_main)(conn)


def _internal(exc: BaseException) -> str:
    first = next((ln.strip() for ln in str(exc).splitlines() if ln.strip()), "")
    return f"internal error: {type(exc).__name__}: {first}"[:500]


# --------------------------------------------------------------------------- the worker
def _worker_main(conn) -> None:
    """The worker process: jobs ``(id, kind, payload)`` in, messages out — ``("part", id,
    index, value)``, ``("done", id, value)``, ``("error", id, message)`` and, whenever a
    file's compiled model is ready, ``("mark", path)``."""
    from brdfkit.explorer.compute import Session

    lock = threading.Lock()

    def send(msg) -> None:
        with lock:
            conn.send(msg)

    session = Session(mark=lambda path: send(("mark", path)))
    try:  # the first message: the page's first request, computed while the page loads
        first = conn.recv()
    except (EOFError, OSError):
        os._exit(0)
    _warm_up(session, first[1] if first and first[0] == "warm" else None)
    send(("ready",))
    while True:
        try:
            job_id, kind, payload = conn.recv()
        except (EOFError, OSError):
            os._exit(0)
        try:
            send(("done", job_id, _run(session, kind, payload,
                                       lambda i, v, j=job_id: send(("part", j, i, v)))))
        except BrdfkitError as exc:
            send(("error", job_id, str(exc), getattr(exc, "status", 400)))
        except (Exception, RecursionError) as exc:  # noqa: BLE001 - reported, never a traceback
            send(("error", job_id, _internal(exc), 500))


def _warm_up(session, payload: dict | None) -> None:
    """Compute the page's first request (*payload*, a "views" job:
    :func:`~brdfkit.explorer.compute.start_payload`) before the first job: the imports, the
    views' kernels from Numba's disk cache, the sphere's loop compiled for that model, and
    the model's albedo curve and θ_h × θ_d image kept in the session's cache, so that the
    page's first ``/api/views`` finds them ready. An error is the first job's to show."""
    if payload is None:
        return
    try:
        _run(session, "views", payload, lambda i, v: None)
    except (Exception, RecursionError):  # noqa: BLE001 - the page's request reports it
        pass


def _run(session, kind: str, payload: dict, part):
    session.allow(payload.get("given", ()))
    session.set_digests(payload.get("digests", {}))
    if kind in ("views", "verdicts"):
        one = session.model_views if kind == "views" else session.model_verdict
        for i, entry in enumerate(payload["entries"]):
            part(i, one(entry, payload["state"]))
        if kind == "views":
            session.files.start_compiles()  # the drafts drawn: compile them now
        return None
    if kind == "export":
        return session.export_binary(payload["entry"])
    if kind == "names":  # build (and cache) the models: their names, or the first error
        return [session.get_built(e)[0].name for e in payload["entries"]]
    if kind == "join":  # the compiling threads (the tests wait for them)
        for t in list(session.files.threads):
            t.join(timeout=payload.get("timeout", 300.0))
        return None
    raise BrdfkitError(f"unknown job {kind!r}")


class _Job:
    def __init__(self, loop, conn):
        self.loop, self.conn = loop, conn
        self.future = loop.create_future()
        # its error is read (or the request went away): no "exception never retrieved"
        self.future.add_done_callback(lambda f: f.cancelled() or f.exception())
        self.parts: dict[int, object] = {}

    def settle(self, ok: bool, value) -> None:
        def apply():
            if not self.future.done():
                if ok:
                    self.future.set_result(value)
                else:
                    self.future.set_exception(value)
        self.loop.call_soon_threadsafe(apply)


class Worker:
    """The web server's handle on its worker process (module docstring). *on_mark(path)*:
    a file's compiled model is ready; *warm*: the "views" job a new process computes before
    any other (the page's first request, :func:`~brdfkit.explorer.compute.start_payload`;
    None: nothing). Started by :meth:`start` or on first use; :meth:`stop` ends it."""

    def __init__(self, *, on_mark=None, warm: dict | None = None):
        self.on_mark = on_mark
        self.warm = warm  # the "views" job a new process computes first (_warm_up)
        self._lock = threading.Lock()  # the process handle
        self._slot = threading.Lock()  # one job at a time
        self._waiting = 0
        self._urgent = 0  # waiting jobs that are not low priority
        self._proc = None
        self._conn = None
        self._jobs: dict[int, _Job] = {}
        self._ids = itertools.count(1)
        self._stopped = False
        self._ready = None  # the connection of the worker that has warmed up
        self.restarts = 0

    @property
    def pid(self) -> int | None:
        return None if self._proc is None else self._proc.pid

    def start(self) -> None:
        """Start the process now if it is not running (it warms up while idle)."""
        with self._lock:
            if self._stopped or (self._proc is not None and self._proc.poll() is None):
                return
            self._proc, parent = _start_child("worker")
            self._conn = parent
            try:
                parent.send(("warm", self.warm))
            except OSError:  # the process died at once: the first job reports it
                pass
            threading.Thread(target=self._read, args=(parent,), daemon=True,
                             name="brdfkit worker reader").start()

    def _read(self, conn) -> None:
        while True:
            try:
                msg = conn.recv()
            except (EOFError, OSError):
                break
            if msg[0] == "mark":
                if self.on_mark is not None:
                    self.on_mark(msg[1])
                continue
            if msg[0] == "ready":
                self._ready = conn
                continue
            job = self._jobs.get(msg[1])
            if job is None:
                continue
            if msg[0] == "part":
                job.parts[msg[2]] = msg[3]
            elif msg[0] == "done":
                job.settle(True, msg[2])
            else:
                job.settle(False, RequestError(msg[2], msg[3]))
        for job in list(self._jobs.values()):  # the process ended under a job
            if job.conn is conn:
                job.settle(False, RequestError("the explorer's worker process stopped", 503))

    def _kill(self) -> None:
        with self._lock:
            proc, conn = self._proc, self._conn
            self._proc = self._conn = None
        if proc is not None:
            proc.kill()
            proc.wait(timeout=5)
        if conn is not None:
            conn.close()

    def restart(self) -> None:
        """Kill the process (a job over its budget) and start a fresh one."""
        self._kill()
        self.restarts += 1
        self.start()

    def stop(self) -> None:
        self._stopped = True
        self._kill()

    async def run(self, kind: str, payload: dict, *, deadline: float, what: str,
                  low: bool = False):
        """Run one job before *deadline* (``time.monotonic()``); its result. Raises
        :class:`OverBudget` (with the parts done) when the deadline passes, a BrdfkitError
        with the job's error otherwise. *what* names the request in the messages; a *low*
        priority job (a verdict) lets every waiting other job (the views of a slider move)
        go first."""
        if self._waiting >= MAX_WAITING:
            raise OverBudget(f"{what}: the explorer is busy ({MAX_WAITING} requests waiting, "
                             "MAX_WAITING); try again in a moment", {}, started=False)
        self._waiting += 1
        self._urgent += 0 if low else 1
        try:
            while (low and self._urgent) or not self._slot.acquire(blocking=False):
                if time.monotonic() >= deadline:
                    raise OverBudget(f"{what}: not started within the time budget: the "
                                     "explorer was busy with other requests", {},
                                     started=False)
                await asyncio.sleep(_SLOT_POLL_S)
        except asyncio.CancelledError:  # the server is stopping: a message, no traceback
            raise RequestError("the explorer is stopping", 503) from None
        finally:
            self._waiting -= 1
            self._urgent -= 0 if low else 1
        job_id = next(self._ids)
        job = None
        finished = False
        try:
            self.start()
            with self._lock:
                conn = self._conn
            if conn is None:
                raise BrdfkitError("the explorer is shutting down")
            job = self._jobs[job_id] = _Job(asyncio.get_running_loop(), conn)
            warm = self._ready is conn
            try:
                conn.send((job_id, kind, payload))
            except OSError:  # the process died between jobs (killed from outside, OOM)
                raise RequestError("the explorer's worker process stopped; it is being "
                                   "restarted: try again", 503) from None
            remaining = deadline - time.monotonic()
            try:
                result = await asyncio.wait_for(asyncio.shield(job.future), max(remaining, 0))
            except TimeoutError:
                raise OverBudget(f"{what}: over the time budget", dict(job.parts),
                                 started=True, warm=warm) from None
            except asyncio.CancelledError:
                # the server is stopping (Ctrl-C): the request ends with a message, not a
                # cancelled task that the server would log with a traceback
                raise RequestError("the explorer is stopping", 503) from None
            finished = True
            return result, dict(job.parts)
        finally:
            self._jobs.pop(job_id, None)
            if job is not None and not finished and not job.future.done():
                # over budget or cancelled (shutdown): the process is still computing it
                self.restart()
            self._slot.release()


# --------------------------------------------------------------------------- fits
def _fit_main(conn) -> None:
    from brdfkit.explorer.compute import Session
    from brdfkit.fitting import fit

    last = [0.0]

    def progress(stage, evaluations, value):
        now = time.monotonic()
        if now - last[0] >= 1.0 / _PROGRESS_HZ:
            last[0] = now
            conn.send(("progress", {"stage": stage, "evaluations": int(evaluations),
                                    "loss": float(value)}))

    try:
        model, target, loss, given = conn.recv()
        session = Session()
        session.allow(given)
        m, t = session.get_built(model)[0], session.get_built(target)[0]
        r = fit(m, t, loss=loss, progress=progress)
        d = r.to_dict()
        conn.send(("done", {"state": "done", "params": d["params"], "metrics": d["metrics"],
                            "message": r.message, "success": r.success}))
    except BrdfkitError as exc:
        conn.send(("done", {"state": "error", "error": str(exc)}))
    except (Exception, RecursionError) as exc:  # noqa: BLE001 - reported in the page
        conn.send(("done", {"state": "error", "error": _internal(exc)}))


class Fits:
    """Fits in processes of their own (module docstring): :meth:`start` → an id,
    :meth:`status` → the record ``{"state", "stage", "evaluations", "loss", ...}``."""

    def __init__(self, *, budget_s: float = FIT_BUDGET_S):
        self.budget_s = budget_s
        self._jobs: dict[int, dict] = {}
        self._procs: dict[int, object] = {}
        self._ids = itertools.count(1)
        self._lock = threading.Lock()

    def running(self) -> int:
        with self._lock:
            return sum(1 for j in self._jobs.values() if j["state"] == "running")

    def start(self, *, model: dict, target: dict, loss: str, given, names) -> int:
        with self._lock:
            if sum(1 for j in self._jobs.values() if j["state"] == "running") >= MAX_FITS:
                raise BrdfkitError(f"fit: {MAX_FITS} fit is running already (MAX_FITS: each "
                                   "takes a core); wait for it to finish")
            job_id = next(self._ids)
            self._jobs[job_id] = {"state": "running", "stage": "starting", "evaluations": 0,
                                  "t0": time.perf_counter(), "model": names[0],
                                  "target": names[1]}
            while len(self._jobs) > MAX_FIT_RECORDS:
                old = next((k for k, j in self._jobs.items() if j["state"] != "running"), None)
                if old is None:
                    break
                self._jobs.pop(old)
        proc, parent = _start_child("fit")
        parent.send((model, target, loss, list(given)))
        self._procs[job_id] = proc
        threading.Thread(target=self._follow, args=(job_id, proc, parent), daemon=True,
                         name=f"brdfkit fit {job_id} reader").start()
        return job_id

    def _follow(self, job_id: int, proc, conn) -> None:
        job = self._jobs[job_id]
        deadline = time.monotonic() + self.budget_s
        try:
            while True:
                remaining = deadline - time.monotonic()
                if remaining <= 0:
                    job.update(state="error", error=f"fit: over its time budget of "
                               f"{self.budget_s:g} s (FIT_BUDGET_S); stopped")
                    break
                if not conn.poll(min(remaining, 0.5)):
                    continue
                try:
                    kind, value = conn.recv()
                except (EOFError, OSError):
                    if job["state"] == "running":
                        job.update(state="error", error="fit: its process stopped")
                    break
                job.update(value)
                if kind == "done":
                    break
        finally:
            job["seconds"] = round(time.perf_counter() - job["t0"], 2)
            if proc.poll() is None:
                proc.kill()
            proc.wait(timeout=5)
            conn.close()
            self._procs.pop(job_id, None)

    def status(self, job_id: int) -> dict | None:
        job = self._jobs.get(job_id)
        if job is None:
            return None
        out = {k: v for k, v in job.items() if k != "t0"}
        out.setdefault("seconds", round(time.perf_counter() - job["t0"], 2))
        return out

    def stop(self) -> None:
        for proc in list(self._procs.values()):
            proc.kill()
