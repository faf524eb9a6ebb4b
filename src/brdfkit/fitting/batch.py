"""
Batches of fits: resumable, written row by row, local processes or a Dask cluster
=================================================================================

:func:`run_batch` runs many independent jobs (a fit of one model to one
material, say) and writes each finished row to a CSV or Parquet file (by the
suffix: ``.csv``, ``.parquet``; Parquet needs pyarrow, the ``batch`` extra)
**as it completes**, atomically (the whole file is rewritten to a temporary file and renamed, so a
reader or a crash never sees half a row). Hence:

- **Resume.** Re-running with the same output skips every job whose key is
  already in the file with status ``ok`` or ``not-converged`` (failed rows are retried
  and replaced). Every row read is checked first; an invalid one (cut mid-way, junk) is
  left out and its job runs again; a file that is not a batch file is refused
  (:mod:`brdfkit.fitting._batchfile`).
- **One writer.** A batch holds a lock next to its output; a second batch on the same
  output is refused in one line naming the other process.
- **Ctrl-C loses nothing finished.** On an interrupt the pending jobs are
  cancelled and :class:`BatchInterrupted` says how many rows are on disk.
- **Exactly once.** Rows are keyed (:attr:`Job.key`); a retried job — a Dask
  worker killed mid-task is rescheduled by the scheduler — replaces, never
  duplicates, its row.
- **Failures are counted**, not raised: :class:`BatchReport` has ``failed`` and the
  ``failures`` (the command line exits with status 1 and the first reasons).

Where the jobs run
------------------
=================  =========================================================
``workers=1``      in this process, one after the other
``workers=N``      up to N local processes (``concurrent.futures``, *spawn* start:
                   Numba's threading layers are not fork-safe), at most one per
                   CPU (:func:`useful_workers`); they die with this process
``scheduler=ADDR`` a Dask distributed cluster (``tcp://host:8786``, or a
                   :class:`distributed.Client`/``LocalCluster`` object);
                   ``retries`` re-runs a job whose worker died
                   (:mod:`brdfkit.fitting._dask`: the address checked, the
                   scheduler heard within :data:`CONNECT_TIMEOUT_S`)
=================  =========================================================

A job function takes a :class:`Job` and returns a flat ``dict`` row (str,
int, float, bool or None values); it must be importable by the workers
(a module-level function, e.g. :func:`brdfkit.fitting.batch.fit_row`). An
exception inside it becomes a row with status ``error`` and the message, so
one bad material does not stop a database run.

Public objects
--------------
- :class:`Job`, :func:`run_batch`, :class:`BatchReport`, :class:`BatchInterrupted`,
  :func:`read_rows`, :func:`read_checked`, :func:`write_rows`, :func:`useful_workers`.
- :func:`fit_row` — the job function of ``brdfkit fit … --out``: one fit, one row.
- :func:`job_spec` — the :class:`~brdfkit.spec.ModelSpec` of a job's model.
- :func:`expand_targets` — ``merl:all``, ``rgl:all``, ``nielsen:all`` → material specs.
"""

from __future__ import annotations

import concurrent.futures as cf
import ctypes
import multiprocessing
import os
import signal
import sys
import threading
import time
import traceback
import warnings
from collections.abc import Callable, Iterable
from dataclasses import dataclass, field

from brdfkit._io import check_output_path
from brdfkit.errors import BrdfkitError
from brdfkit.fitting._batchfile import (
    KEY_COLUMNS,
    STATUS_ERROR,
    STATUS_NOT_CONVERGED,
    STATUS_OK,
    STATUSES,
    SUFFIXES,
    describe_invalid,
    is_parquet,
    key_of,
    pyarrow_modules,
    read_checked,
    read_rows,
    write_rows,
    writer_lock,
)
from brdfkit.fitting._dask import CONNECT_TIMEOUT_S

__all__ = ["Job", "run_batch", "BatchReport", "BatchInterrupted", "read_rows", "read_checked",
           "write_rows", "SUFFIXES", "useful_workers", "MAX_WORKERS", "CONNECT_TIMEOUT_S",
           "fit_row", "job_spec", "expand_targets", "KEY_COLUMNS", "STATUS_OK", "STATUS_ERROR",
           "STATUS_NOT_CONVERGED"]


@dataclass(frozen=True)
class Job:
    """One unit of a batch: fit *model* to *target* with *loss* and *procedure*.

    ``options`` holds further keyword arguments for the job function as sorted
    ``(name, value)`` pairs (hashable and picklable); they are not part of the key.
    """

    model: str
    target: str
    loss: str = "l1"
    procedure: str = "auto"
    options: tuple = field(default=())

    @property
    def key(self) -> tuple[str, str, str, str]:
        return (self.model, self.target, self.loss, self.procedure)


@dataclass
class BatchReport:
    """What a batch did: jobs ``total``, ``skipped`` (already in the file), ``done``
    (finished now: ok, not converged or error), ``failed`` (status error now),
    ``not_converged``, ``seconds``, the output path, ``failures`` (``"target (model):
    message"`` of each failed row, in order), ``invalid`` (rows of the file left out on
    reading, each with its line and reason), ``workers`` (local processes used)."""

    total: int
    skipped: int
    done: int
    failed: int
    seconds: float
    out: str
    not_converged: int = 0
    failures: list = field(default_factory=list)
    invalid: list = field(default_factory=list)
    workers: int = 1

    @property
    def success(self) -> bool:
        return self.failed == 0 and self.skipped + self.done == self.total


class BatchInterrupted(BrdfkitError):
    """The batch was interrupted (Ctrl-C); every finished row is in the output file."""


# --------------------------------------------------------------------------- running
def _safe(run_job: Callable[[Job], dict], job: Job) -> dict:
    """Run one job; an exception becomes an error row (the batch goes on)."""
    t0 = time.perf_counter()
    try:
        row = dict(run_job(job))
        row.setdefault("status", STATUS_OK)
        if row["status"] not in STATUSES:  # it would be an invalid row on resume
            raise BrdfkitError(f"the job function returned status {row['status']!r}; "
                               f"expected one of {', '.join(STATUSES)}")
    except Exception as exc:  # noqa: BLE001 - any failure of one job is recorded, not raised
        last = traceback.extract_tb(exc.__traceback__)[-1:]
        where = f" ({last[0].filename.rsplit(os.sep, 1)[-1]}:{last[0].lineno})" if last else ""
        row = {"status": STATUS_ERROR, "message": f"{type(exc).__name__}: {exc}{where}"}
    row.update(dict(zip(KEY_COLUMNS, job.key, strict=True)))
    row.setdefault("job_seconds", round(time.perf_counter() - t0, 3))
    return row


def _error_row(job: Job, message: str) -> dict:
    return {**dict(zip(KEY_COLUMNS, job.key, strict=True)), "status": STATUS_ERROR,
            "message": message}


#: Most local worker processes (a sanity bound on the argument; the CPUs cap it further).
MAX_WORKERS = 256


def _check_workers(workers) -> int:
    ok = isinstance(workers, int) and not isinstance(workers, bool) and \
        1 <= workers <= MAX_WORKERS
    if not ok:
        raise BrdfkitError(f"--workers must be an integer from 1 to {MAX_WORKERS}; got "
                           f"{workers!r}")
    return workers


def _cpus() -> int:
    """CPUs this process may run on (its affinity mask where the system has one)."""
    try:
        return len(os.sched_getaffinity(0))
    except AttributeError:  # not Linux
        return os.cpu_count() or 1


def useful_workers(workers: int, n_jobs: int) -> tuple[int, str]:
    """The processes worth starting for *n_jobs* jobs: at most one per CPU (a fit keeps
    a CPU busy; more processes only compete for it and each costs an interpreter, Numba
    and the data) and one per job. Returns the number and, when the CPUs capped
    *workers*, one line saying so ('' otherwise)."""
    cpus = _cpus()
    n = max(1, min(workers, cpus, n_jobs))
    if workers > cpus and n_jobs > cpus:
        return n, (f"--workers {workers} capped at {n}: this machine has {cpus} CPU(s) for "
                   "this process, and more processes than CPUs only compete for them")
    return n, ""


def _say(notice, message: str) -> None:
    if notice is not None:
        notice(message)
    else:
        warnings.warn(message, stacklevel=3)


def run_batch(jobs: Iterable[Job], *, out, run_job: Callable[[Job], dict], workers: int = 1,
              scheduler=None, retries: int = 2,
              progress: Callable[[int, int, str], None] | None = None,
              notice: Callable[[str], None] | None = None) -> BatchReport:
    """Run *jobs* with *run_job*, writing each finished row to *out* (module docstring).

    Parameters
    ----------
    jobs : iterable of Job
        Duplicates (same key) run once.
    out : path
        CSV or Parquet output (by suffix); existing ok rows are kept and their jobs
        skipped; invalid rows are left out and their jobs run again.
    run_job : callable
        ``run_job(job) -> dict`` (module level, importable by the workers).
    workers : int, keyword-only
        Local processes, 1 to 256 (1: in this process), capped at the CPUs and the jobs
        (:func:`useful_workers`). Ignored with *scheduler*.
    scheduler : str or distributed.Client or LocalCluster, keyword-only, optional
        Run on this Dask cluster instead (``tcp://HOST:PORT``).
    retries : int, keyword-only
        Dask retries of a job whose worker died (0 to 10).
    progress : callable, keyword-only, optional
        ``progress(done, total, label)`` after each finished job and once at the start.
    notice : callable, keyword-only, optional
        ``notice(line)`` for what the batch changed on its own: workers capped, invalid
        rows left out. Default: :func:`warnings.warn`.

    Returns
    -------
    BatchReport

    Raises
    ------
    BatchInterrupted
        On KeyboardInterrupt, after cancelling the pending jobs; finished rows are on disk.
    BrdfkitError
        Bad *out* (not a batch file, written by another batch now), *workers*, *retries*
        or *scheduler*; an unreachable scheduler; a scheduler that went away.
    """
    path = check_output_path(out, option="--out", suffixes=SUFFIXES)
    if is_parquet(path):
        pyarrow_modules(path)  # fail before any fit when pyarrow is missing
    workers = _check_workers(workers)
    if not (isinstance(retries, int) and 0 <= retries <= 10):
        raise BrdfkitError(f"retries must be an integer from 0 to 10; got {retries!r}")
    if isinstance(scheduler, str):
        from brdfkit.fitting._dask import check_address

        check_address(scheduler)  # a malformed address fails before anything else
    with writer_lock(path):
        return _run_locked(list(jobs), path, run_job=run_job, workers=workers,
                           scheduler=scheduler, retries=retries, progress=progress,
                           notice=notice)


def _run_locked(jobs, path, *, run_job, workers, scheduler, retries, progress, notice):
    unique = list({j.key: j for j in jobs}.values())
    valid, invalid = read_checked(path)
    if invalid:
        _say(notice, describe_invalid(path, invalid))
    rows = {key_of(r): r for r in valid}
    finished = {k for k, r in rows.items()
                if r.get("status") in (STATUS_OK, STATUS_NOT_CONVERGED)}
    todo = [j for j in unique if j.key not in finished]
    total, skipped = len(unique), len(unique) - len(todo)
    if invalid and not todo:
        write_rows(path, rows.values())  # nothing to run: still drop the invalid rows
    n_workers = 1
    if scheduler is None and workers > 1 and len(todo) > 1:
        n_workers, why = useful_workers(workers, len(todo))
        if why:
            _say(notice, why)
    t0 = time.perf_counter()
    state = {"done": 0, "failed": 0, "not_converged": 0}
    failures: list[str] = []

    def record(row: dict) -> None:
        rows[key_of(row)] = row
        write_rows(path, rows.values())
        state["done"] += 1
        if row.get("status") == STATUS_ERROR:
            state["failed"] += 1
            failures.append(f"{row['target']} ({row['model']}): {row.get('message', '')}")
        state["not_converged"] += row.get("status") == STATUS_NOT_CONVERGED
        if progress is not None:
            progress(skipped + state["done"], total, f"{row['model']} -> {row['target']}")

    def where() -> str:
        return f"{skipped + state['done']} of {total} rows are in {path}"

    if progress is not None:
        progress(skipped, total, "")
    try:
        if scheduler is not None:
            from brdfkit.fitting._dask import run_dask

            run_dask(todo, run_job=run_job, scheduler=scheduler, retries=retries,
                     record=record, safe=_safe, error_row=_error_row, where=where,
                     say=lambda line: _say(notice, line))
        elif n_workers == 1:
            for job in todo:
                record(_safe(run_job, job))
        else:
            _run_processes(todo, run_job, n_workers, record)
    except KeyboardInterrupt:
        raise BatchInterrupted(f"interrupted: {where()}; re-run the same command to "
                               "resume") from None
    return BatchReport(total=total, skipped=skipped, done=state["done"],
                       failed=state["failed"], seconds=time.perf_counter() - t0, out=path,
                       not_converged=state["not_converged"], failures=failures,
                       invalid=invalid, workers=n_workers)


#: prctl(2) option: the signal the kernel sends this process when its parent dies
#: (<linux/prctl.h>).
_PR_SET_PDEATHSIG = 1
#: Seconds between a worker's checks that its parent lives, where prctl is missing.
_PARENT_POLL_S = 1.0


def _die_with_parent(parent: int) -> None:
    """A worker process's initializer: end this process when the batch's process dies,
    even by SIGKILL, which runs no cleanup of its own (the workers, and with them the
    multiprocessing resource tracker, were left running under PID 1). Linux: the kernel
    does it (``prctl(PR_SET_PDEATHSIG, SIGKILL)``); elsewhere a daemon thread polls the
    parent's pid."""
    armed = False
    if sys.platform.startswith("linux"):
        try:
            libc = ctypes.CDLL(None, use_errno=True)
            armed = libc.prctl(_PR_SET_PDEATHSIG, int(signal.SIGKILL), 0, 0, 0) == 0
        except (OSError, AttributeError):
            armed = False
    if os.getppid() != parent:  # the parent died before we were armed
        os._exit(1)
    if not armed:
        def watch() -> None:
            while os.getppid() == parent:
                time.sleep(_PARENT_POLL_S)
            os._exit(1)

        threading.Thread(target=watch, name="brdfkit-parent-watch", daemon=True).start()


def _run_processes(todo, run_job, workers, record) -> None:
    ctx = multiprocessing.get_context("spawn")
    pool = cf.ProcessPoolExecutor(max_workers=workers, mp_context=ctx,
                                  initializer=_die_with_parent, initargs=(os.getpid(),))
    try:
        futures = {pool.submit(_safe, run_job, j): j for j in todo}
        for fut in cf.as_completed(futures):
            try:
                record(fut.result())
            except cf.process.BrokenProcessPool as exc:  # a worker process died
                record(_error_row(futures[fut], f"worker process died: {exc}"))
    finally:
        pool.shutdown(wait=True, cancel_futures=True)


# --------------------------------------------------------------------------- fits
def expand_targets(specs: Iterable[str]) -> list[str]:
    """Material specs with ``SOURCE:all`` expanded to every built-in material of SOURCE
    (``merl:all@abc`` to their ABC fits); other specs unchanged, duplicates dropped."""
    from brdfkit.data import material_names

    out: list[str] = []
    for spec in specs:
        source, sep, rest = str(spec).partition(":")
        name, at, rep = rest.partition("@")
        if sep and name.strip().lower() == "all":
            names = [s for s in material_names() if s.startswith(source.lower() + ":")]
            if not names:
                raise BrdfkitError(f"--to {spec}: no built-in source {source!r}; valid: "
                                   "merl:all, rgl:all, nielsen:all")
            out.extend(f"{s}@{rep}" if at else s for s in names)
        else:
            out.append(str(spec))
    return list(dict.fromkeys(out))


def job_spec(job: Job):
    """The :class:`~brdfkit.spec.ModelSpec` a job fits (or a derived job rebuilds):
    ``job.model`` with the options ``params`` (a JSON object of values), ``pump`` (g)
    and ``times`` — the spec's flat dict form."""
    import json

    from brdfkit.spec import ModelSpec

    opts = dict(job.options)
    d = {"model": job.model, "params": json.loads(opts["params"]) if opts.get("params") else {}}
    if opts.get("pump"):
        d.update(pump=opts["pump"], times=int(opts.get("times", 1)))
    return ModelSpec.from_dict(d)


def fit_row(job: Job) -> dict:
    """Fit ``job.model`` to ``job.target`` (:func:`brdfkit.fitting.fit`) and flatten the
    result into one row: status (ok / not-converged), the loss value, the parameters (JSON,
    ready for ``-p``), every metric (``metric_<name>``), the worst albedo relative error,
    the evaluations and the seconds. ``job.options`` may hold ``pump``, ``times``,
    ``seed``, ``theta_max_deg``, ``params`` (a JSON object of starting values, e.g.
    ``{"eta": 1.5}`` to fit an optional index η that is None by default) and ``fixed``
    (a JSON list of parameter names held at those values, e.g. ``["alpha"]``)."""
    import json
    import math

    import numpy as np

    from brdfkit.fitting.procedure import fit
    from brdfkit.spec import ModelSpec

    opts = dict(job.options)
    m = job_spec(job).build()
    fixed = {k: m.values[k] for k in json.loads(opts.get("fixed") or "[]")}
    target = ModelSpec(job.target).build()
    theta_max = opts.get("theta_max_deg")
    t0 = time.perf_counter()
    r = fit(m, target, loss=job.loss, procedure=job.procedure, seed=int(opts.get("seed", 0)),
            fixed=fixed or None,
            theta_max=None if theta_max is None else math.radians(float(theta_max)))
    d = r.to_dict()
    row = {"status": STATUS_OK if r.success else STATUS_NOT_CONVERGED, "fit_status": r.status,
           "value": r.value, "params": json.dumps(d["params"], sort_keys=True)}
    row.update({f"metric_{k}": v for k, v in sorted(r.metrics.items())})
    rel = np.asarray(r.albedo_rel_error, dtype=np.float64)
    row["albedo_max_rel_error"] = float(np.nanmax(np.abs(rel))) if rel.size else None
    conv = r.convergence
    row["evaluations"] = conv.get("evaluations")
    row["at_bounds"] = json.dumps(conv.get("at_bounds", []))
    row["seconds"] = round(time.perf_counter() - t0, 3)
    row["message"] = r.message
    return row
