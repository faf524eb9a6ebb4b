"""
Batches of fits: resumable, written row by row, local processes or a Dask cluster
=================================================================================

:func:`run_batch` runs many independent jobs (a fit of one model to one
material, say) and writes each finished row to a CSV or Parquet file (by the
suffix: ``.csv``, ``.parquet``; Parquet needs pyarrow, the ``batch`` extra)
**as it completes**, atomically (the whole file is rewritten to a temporary file and renamed, so a
reader or a crash never sees half a row). Hence:

- **Resume.** Re-running with the same output skips every job whose key is
  already in the file with status ``ok`` (failed rows are retried and replaced).
- **Ctrl-C loses nothing finished.** On an interrupt the pending jobs are
  cancelled and :class:`BatchInterrupted` says how many rows are on disk.
- **Exactly once.** Rows are keyed (:attr:`Job.key`); a retried job — a Dask
  worker killed mid-task is rescheduled by the scheduler — replaces, never
  duplicates, its row.

Where the jobs run
------------------
=================  =========================================================
``workers=1``      in this process, one after the other
``workers=N``      N local processes (``concurrent.futures``, *spawn* start:
                   Numba's threading layers are not fork-safe)
``scheduler=ADDR`` a Dask distributed cluster (``tcp://host:8786``, or a
                   :class:`distributed.Client`/``LocalCluster`` object);
                   ``retries`` re-runs a job whose worker died
=================  =========================================================

A job function takes a :class:`Job` and returns a flat ``dict`` row (str,
int, float, bool or None values); it must be importable by the workers
(a module-level function, e.g. :func:`brdfkit.fitting.batch.fit_row`). An
exception inside it becomes a row with status ``error`` and the message, so
one bad material does not stop a database run.

Public objects
--------------
- :class:`Job`, :func:`run_batch`, :class:`BatchReport`, :class:`BatchInterrupted`,
  :func:`read_rows`, :func:`write_rows`.
- :func:`fit_row` — the job function of ``brdfkit fit … --out``: one fit, one row.
- :func:`job_spec` — the :class:`~brdfkit.spec.ModelSpec` of a job's model.
- :func:`expand_targets` — ``merl:all``, ``rgl:all``, ``nielsen:all`` → material specs.
"""

from __future__ import annotations

import concurrent.futures as cf
import csv
import io
import multiprocessing
import os
import time
import traceback
from collections.abc import Callable, Iterable
from dataclasses import dataclass, field

from brdfkit._io import check_output_path, write_atomic
from brdfkit.errors import BrdfkitError

__all__ = ["Job", "run_batch", "BatchReport", "BatchInterrupted", "read_rows", "write_rows",
           "SUFFIXES",
           "fit_row", "job_spec", "expand_targets", "KEY_COLUMNS", "STATUS_OK", "STATUS_ERROR",
           "STATUS_NOT_CONVERGED"]

#: Columns that identify a job's row (its key), first in every output file.
KEY_COLUMNS = ("model", "target", "loss", "procedure")
STATUS_OK = "ok"
STATUS_ERROR = "error"
#: A fit that ran but did not converge (its FitResult.success is False): kept, not retried.
STATUS_NOT_CONVERGED = "not-converged"


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
    (finished now, ok or error), ``failed`` (status error), ``seconds``, the output path."""

    total: int
    skipped: int
    done: int
    failed: int
    seconds: float
    out: str

    @property
    def success(self) -> bool:
        return self.failed == 0 and self.skipped + self.done == self.total


class BatchInterrupted(BrdfkitError):
    """The batch was interrupted (Ctrl-C); every finished row is in the output file."""


# --------------------------------------------------------------------------- the file
def _key_of(row: dict) -> tuple:
    return tuple(str(row.get(c, "")) for c in KEY_COLUMNS)


#: Suffixes of batch output files: CSV (always) and Parquet (with pyarrow).
SUFFIXES = (".csv", ".parquet")


def _is_parquet(path) -> bool:
    return os.fspath(path).lower().endswith(".parquet")


def _pyarrow(path):
    try:
        import pyarrow
        import pyarrow.parquet
    except ImportError:
        raise BrdfkitError(f"--out {os.fspath(path)!r}: Parquet output needs pyarrow: pip "
                           "install 'brdfkit[batch]' (or pip install pyarrow), or write "
                           ".csv") from None
    return pyarrow, pyarrow.parquet


def _check_columns(p, names) -> None:
    missing = [c for c in (*KEY_COLUMNS, "status") if c not in (names or ())]
    if missing:
        raise BrdfkitError(f"{p}: not a brdfkit batch file: expected columns "
                           f"{', '.join((*KEY_COLUMNS, 'status'))}; missing "
                           f"{', '.join(missing)} (choose another --out to start afresh)")


def read_rows(path) -> list[dict]:
    """Rows of a batch output file, [] if it does not exist: from CSV as dicts of strings,
    from Parquet with the stored types (None where a row has no value).

    Raises :class:`~brdfkit.errors.BrdfkitError` naming the file when it exists
    but is not a batch file (no key columns, or not readable as Parquet)."""
    p = os.fspath(path)
    if not os.path.exists(p):
        return []
    if _is_parquet(p):
        _, pq = _pyarrow(p)
        try:
            table = pq.read_table(p)
        except (OSError, ValueError) as exc:  # pyarrow's ArrowInvalid is a ValueError
            raise BrdfkitError(f"{p}: not a Parquet file ({exc}); choose another --out to "
                               "start afresh") from None
        _check_columns(p, table.column_names)
        return table.to_pylist()
    with open(p, newline="", encoding="utf-8") as fh:
        reader = csv.DictReader(fh)
        _check_columns(p, reader.fieldnames)
        return list(reader)


def _column_type(pa, values):
    """One Arrow type for a column: bool, int64 or float64 (ints and floats mixed) when
    every value present is of that kind, else string (values written with str())."""
    present = [v for v in values if v is not None]
    if present and all(isinstance(v, bool) for v in present):
        return pa.bool_()
    if present and all(isinstance(v, int) and not isinstance(v, bool) for v in present):
        return pa.int64()
    if present and all(isinstance(v, int | float) and not isinstance(v, bool)
                       for v in present):
        return pa.float64()
    return pa.string()


def _write_parquet(path, rows, columns) -> str:
    pa, pq = _pyarrow(path)
    arrays = []
    for c in columns:
        vals = [r.get(c) for r in rows]
        kind = _column_type(pa, vals)
        if kind == pa.string():
            vals = [None if v is None else str(v) for v in vals]
        elif kind == pa.float64():
            vals = [None if v is None else float(v) for v in vals]
        arrays.append(pa.array(vals, type=kind))
    table = pa.Table.from_arrays(arrays, names=list(columns))
    return write_atomic(path, lambda fh: pq.write_table(table, fh), option="--out")


def write_rows(path, rows: Iterable[dict]) -> str:
    """Write *rows* atomically as CSV or, for a ``.parquet`` path, Parquet (one typed
    column per field: bool, int64, float64 or string): key columns and status first, then
    the others in order of first appearance."""
    rows = list(rows)
    columns = [*KEY_COLUMNS, "status"]
    for r in rows:
        columns.extend(c for c in r if c not in columns)
    if _is_parquet(path):
        return _write_parquet(path, rows, columns)

    def write(fh):
        text = io.StringIO()
        w = csv.DictWriter(text, fieldnames=columns, restval="", lineterminator="\n")
        w.writeheader()
        for r in rows:
            w.writerow({k: ("" if v is None else v) for k, v in r.items()})
        fh.write(text.getvalue().encode("utf-8"))

    return write_atomic(path, write, option="--out")


# --------------------------------------------------------------------------- running
def _safe(run_job: Callable[[Job], dict], job: Job) -> dict:
    """Run one job; an exception becomes an error row (the batch goes on)."""
    t0 = time.perf_counter()
    try:
        row = dict(run_job(job))
        row.setdefault("status", STATUS_OK)
    except Exception as exc:  # noqa: BLE001 - any failure of one job is recorded, not raised
        last = traceback.extract_tb(exc.__traceback__)[-1:]
        where = f" ({last[0].filename.rsplit(os.sep, 1)[-1]}:{last[0].lineno})" if last else ""
        row = {"status": STATUS_ERROR, "message": f"{type(exc).__name__}: {exc}{where}"}
    row.update(dict(zip(KEY_COLUMNS, job.key, strict=True)))
    row.setdefault("job_seconds", round(time.perf_counter() - t0, 3))
    return row


def _check_workers(workers) -> int:
    ok = isinstance(workers, int) and not isinstance(workers, bool) and 1 <= workers <= 256
    if not ok:
        raise BrdfkitError(f"--workers must be an integer from 1 to 256; got {workers!r}")
    return workers


def run_batch(jobs: Iterable[Job], *, out, run_job: Callable[[Job], dict], workers: int = 1,
              scheduler=None, retries: int = 2,
              progress: Callable[[int, int, str], None] | None = None) -> BatchReport:
    """Run *jobs* with *run_job*, writing each finished row to *out* (module docstring).

    Parameters
    ----------
    jobs : iterable of Job
        Duplicates (same key) run once.
    out : path
        CSV or Parquet output (by suffix); existing ok rows are kept and their jobs
        skipped.
    run_job : callable
        ``run_job(job) -> dict`` (module level, importable by the workers).
    workers : int, keyword-only
        Local processes, 1 to 256 (1: in this process). Ignored with *scheduler*.
    scheduler : str or distributed.Client or LocalCluster, keyword-only, optional
        Run on this Dask cluster instead.
    retries : int, keyword-only
        Dask retries of a job whose worker died (0 to 10).
    progress : callable, keyword-only, optional
        ``progress(done, total, label)`` after each finished job and once at the start.

    Returns
    -------
    BatchReport

    Raises
    ------
    BatchInterrupted
        On KeyboardInterrupt, after cancelling the pending jobs; finished rows are on disk.
    BrdfkitError
        Bad *out*, *workers* or *retries*; an unreachable scheduler.
    """
    path = check_output_path(out, option="--out", suffixes=SUFFIXES)
    if _is_parquet(path):
        _pyarrow(path)  # fail before any fit when pyarrow is missing
    workers = _check_workers(workers)
    if not (isinstance(retries, int) and 0 <= retries <= 10):
        raise BrdfkitError(f"retries must be an integer from 0 to 10; got {retries!r}")
    unique = list({j.key: j for j in jobs}.values())
    rows = {_key_of(r): r for r in read_rows(path)}
    finished = {k for k, r in rows.items()
                if r.get("status") in (STATUS_OK, STATUS_NOT_CONVERGED)}
    todo = [j for j in unique if j.key not in finished]
    total, skipped = len(unique), len(unique) - len(todo)
    t0 = time.perf_counter()
    state = {"done": 0, "failed": 0}

    def record(row: dict) -> None:
        rows[_key_of(row)] = row
        write_rows(path, rows.values())
        state["done"] += 1
        state["failed"] += row.get("status") != STATUS_OK
        if progress is not None:
            progress(skipped + state["done"], total, f"{row['model']} -> {row['target']}")

    if progress is not None:
        progress(skipped, total, "")
    try:
        if scheduler is not None:
            _run_dask(todo, run_job, scheduler, retries, record)
        elif workers == 1 or len(todo) <= 1:
            for job in todo:
                record(_safe(run_job, job))
        else:
            _run_processes(todo, run_job, workers, record)
    except KeyboardInterrupt:
        raise BatchInterrupted(
            f"interrupted: {skipped + state['done']} of {total} rows are in {path}; re-run the "
            "same command to resume") from None
    return BatchReport(total=total, skipped=skipped, done=state["done"],
                       failed=state["failed"], seconds=time.perf_counter() - t0, out=path)


def _run_processes(todo, run_job, workers, record) -> None:
    ctx = multiprocessing.get_context("spawn")
    pool = cf.ProcessPoolExecutor(max_workers=min(workers, len(todo)), mp_context=ctx)
    try:
        futures = {pool.submit(_safe, run_job, j): j for j in todo}
        for fut in cf.as_completed(futures):
            try:
                record(fut.result())
            except cf.process.BrokenProcessPool as exc:  # a worker process died
                j = futures[fut]
                record({**dict(zip(KEY_COLUMNS, j.key, strict=True)), "status": STATUS_ERROR,
                        "message": f"worker process died: {exc}"})
    finally:
        pool.shutdown(wait=True, cancel_futures=True)


def _client(scheduler):
    try:
        import distributed
    except ImportError:
        raise BrdfkitError("--scheduler needs Dask distributed: pip install 'brdfkit[batch]' "
                           "(or pip install distributed)") from None
    if isinstance(scheduler, distributed.Client):
        return scheduler, False
    try:
        return distributed.Client(scheduler, timeout="10s", set_as_default=False), True
    except (OSError, TimeoutError) as exc:
        raise BrdfkitError(f"--scheduler {scheduler!r}: cannot connect to a Dask scheduler "
                           f"({exc}); start one with 'dask scheduler' or check the "
                           "address") from None


def _run_dask(todo, run_job, scheduler, retries, record) -> None:
    from distributed import as_completed

    client, own = _client(scheduler)
    try:
        job_of = {client.submit(_safe, run_job, j, pure=False, retries=retries,
                                key=f"brdfkit-fit-{'|'.join(j.key)}-{os.getpid()}-{k}"): j
                  for k, j in enumerate(todo)}
        futures = list(job_of)
        try:
            for fut, row in as_completed(futures, with_results=True, raise_errors=False):
                if fut.status == "error":  # e.g. KilledWorker after the allowed retries
                    j = job_of[fut]
                    row = {**dict(zip(KEY_COLUMNS, j.key, strict=True)),
                           "status": STATUS_ERROR, "message": f"dask: {fut.exception()}"}
                record(row)
        except BaseException:
            client.cancel(futures)
            raise
    finally:
        if own:
            client.close()


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
