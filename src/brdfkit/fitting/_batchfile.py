"""
A batch's output file: read and checked, written atomically, locked while a batch writes
=========================================================================================

The file of :func:`brdfkit.fitting.batch.run_batch` (CSV, or Parquet by the suffix).

- **Checked on reading.** A file that is not a batch file (binary, not UTF-8, a Parquet
  file named ``.csv``, no key columns) is refused in one line naming it. Each row is
  checked (every field present, no NUL byte, the key filled, a known status, the JSON
  columns JSON); an invalid row is left out — its job runs again and the rewritten file
  no longer has it — and reported (:func:`read_checked`).
- **Written atomically** (:func:`brdfkit._io.write_atomic`): key columns and status
  first.
- **One writer.** :func:`writer_lock` takes an advisory lock (``fcntl.flock``) on a lock
  file next to the output, ``.NAME.lock``, holding the writer's process id; a second
  batch on the same output is refused in one line naming the file and that process.
  The kernel releases the lock when its holder dies (even by SIGKILL), so a killed batch
  never blocks the next.

Public objects (re-exported by :mod:`brdfkit.fitting.batch`)
------------------------------------------------------------
- :data:`KEY_COLUMNS`, :data:`STATUSES`, :data:`SUFFIXES`, :data:`JSON_COLUMNS`.
- :func:`read_rows`, :func:`read_checked`, :func:`write_rows`, :func:`writer_lock`.
"""

from __future__ import annotations

import contextlib
import csv
import io
import json
import os
from collections.abc import Iterable, Iterator

from brdfkit._io import write_atomic
from brdfkit.errors import BrdfkitError

__all__ = ["KEY_COLUMNS", "STATUS_OK", "STATUS_ERROR", "STATUS_NOT_CONVERGED", "STATUSES",
           "SUFFIXES", "JSON_COLUMNS", "read_rows", "read_checked", "write_rows",
           "writer_lock", "key_of", "is_parquet"]

#: Columns that identify a job's row (its key), first in every output file.
KEY_COLUMNS = ("model", "target", "loss", "procedure")
STATUS_OK = "ok"
STATUS_ERROR = "error"
#: A fit that ran but did not converge (its FitResult.success is False): kept, not retried.
STATUS_NOT_CONVERGED = "not-converged"
#: Every status a row may have.
STATUSES = (STATUS_OK, STATUS_ERROR, STATUS_NOT_CONVERGED)
#: Suffixes of batch output files: CSV (always) and Parquet (with pyarrow).
SUFFIXES = (".csv", ".parquet")
#: Columns holding JSON (written by fit_row): a row whose value there does not parse is
#: invalid (a row cut mid-way).
JSON_COLUMNS = ("params", "at_bounds")
#: The first bytes of every Parquet file (its magic number, Apache Parquet format spec).
_PARQUET_MAGIC = b"PAR1"
#: Invalid rows named in a report (the rest are counted).
_SHOWN_INVALID = 3


def key_of(row: dict) -> tuple:
    return tuple(str(row.get(c, "")) for c in KEY_COLUMNS)


def is_parquet(path) -> bool:
    return os.fspath(path).lower().endswith(".parquet")


def pyarrow_modules(path):
    try:
        import pyarrow
        import pyarrow.parquet
    except ImportError:
        raise BrdfkitError(f"--out {os.fspath(path)!r}: Parquet output needs pyarrow: pip "
                           "install 'brdfkit[batch]' (or pip install pyarrow), or write "
                           ".csv") from None
    return pyarrow, pyarrow.parquet


def _foreign(p: str, why: str) -> BrdfkitError:
    return BrdfkitError(f"{p}: not a brdfkit batch file ({why}); choose another --out to "
                        "start afresh")


def _check_columns(p, names) -> None:
    missing = [c for c in (*KEY_COLUMNS, "status") if c not in (names or ())]
    if missing:
        raise _foreign(p, f"expected columns {', '.join((*KEY_COLUMNS, 'status'))}; missing "
                          f"{', '.join(missing)}")


def _row_problem(row: dict) -> str | None:
    """Why *row* (a dict of the file's columns) is not a valid row, or None."""
    if None in row:
        return "its number of fields differs from the header's (a row cut or run together)"
    for k, v in row.items():
        if isinstance(v, str) and "\x00" in v:
            return f"a NUL byte in {k}"
    empty = [c for c in KEY_COLUMNS if not str(row.get(c) or "").strip()]
    if empty:
        return f"no {', '.join(empty)}"
    if row.get("status") not in STATUSES:
        return f"status {str(row.get('status'))[:20]!r} is none of {', '.join(STATUSES)}"
    for c in JSON_COLUMNS:
        v = row.get(c)
        if v not in (None, ""):
            try:
                json.loads(v)
            except (TypeError, ValueError):
                return f"{c} is not JSON ({str(v)[:30]!r}...)"
    return None


def _read_csv(p: str) -> tuple[list[dict], list[tuple[int, str]]]:
    with open(p, "rb") as fh:
        data = fh.read()
    if data.startswith(_PARQUET_MAGIC):
        raise _foreign(p, "it is a Parquet file; name it .parquet")
    try:
        text = data.decode("utf-8-sig")  # a byte-order mark (a spreadsheet's save) is skipped
    except UnicodeDecodeError as exc:
        raise _foreign(p, f"not UTF-8 text: byte 0x{data[exc.start]:02x} at offset "
                          f"{exc.start}") from None
    reader = csv.reader(io.StringIO(text, newline=""))
    try:
        header = next(reader, None)
        _check_columns(p, header)
        rows, bad = [], []
        for fields in reader:
            if not fields:
                continue
            row = dict(zip(header, fields, strict=False))
            if len(fields) != len(header):
                row[None] = fields  # marks a field count that differs from the header's
            why = _row_problem(row)
            if why is None:
                rows.append(row)
            else:
                bad.append((reader.line_num, why))
    except csv.Error as exc:
        raise _foreign(p, f"line {reader.line_num}: {exc}") from None
    return rows, bad


def _read_parquet(p: str) -> tuple[list[dict], list[tuple[int, str]]]:
    _, pq = pyarrow_modules(p)
    try:
        table = pq.read_table(p)
    except (OSError, ValueError) as exc:  # pyarrow's ArrowInvalid is a ValueError
        raise BrdfkitError(f"{p}: not a Parquet file ({exc}); choose another --out to "
                           "start afresh") from None
    _check_columns(p, table.column_names)
    rows, bad = [], []
    for i, row in enumerate(table.to_pylist()):
        why = _row_problem(row)
        if why is None:
            rows.append(row)
        else:
            bad.append((i + 1, why))
    return rows, bad


def read_checked(path) -> tuple[list[dict], list[str]]:
    """The valid rows of a batch file ([] if it does not exist) and a description of each
    invalid one (``"line 3: params is not JSON ('{\\"rho_d\\": [0.1'...)"``; Parquet:
    ``"row 3: ..."``): see the module docstring.

    Raises :class:`~brdfkit.errors.BrdfkitError` naming the file when it exists but is not
    a batch file."""
    p = os.fspath(path)
    if not os.path.exists(p):
        return [], []
    rows, bad = (_read_parquet if is_parquet(p) else _read_csv)(p)
    where = "row" if is_parquet(p) else "line"
    return rows, [f"{where} {n}: {why}" for n, why in bad]


def read_rows(path) -> list[dict]:
    """The valid rows of a batch output file, [] if it does not exist: from CSV as dicts of
    strings, from Parquet with the stored types (None where a row has no value). Invalid
    rows are left out (:func:`read_checked` says which)."""
    return read_checked(path)[0]


def describe_invalid(path, problems: list[str]) -> str:
    """One line: how many rows of *path* were invalid and the first reasons."""
    shown = "; ".join(problems[:_SHOWN_INVALID])
    more = f"; and {len(problems) - _SHOWN_INVALID} more" if len(problems) > _SHOWN_INVALID \
        else ""
    return (f"{os.fspath(path)}: {len(problems)} invalid row(s) left out and their jobs run "
            f"again ({shown}{more})")


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
    pa, pq = pyarrow_modules(path)
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
    if is_parquet(path):
        return _write_parquet(path, rows, columns)

    def write(fh):
        text = io.StringIO()
        w = csv.DictWriter(text, fieldnames=columns, restval="", lineterminator="\n")
        w.writeheader()
        for r in rows:
            w.writerow({k: ("" if v is None else v) for k, v in r.items()})
        fh.write(text.getvalue().encode("utf-8"))

    return write_atomic(path, write, option="--out")


# --------------------------------------------------------------------------- one writer
def lock_path(path) -> str:
    """The lock file of output *path*: ``.NAME.lock`` in its directory."""
    p = os.path.abspath(os.fspath(path))
    return os.path.join(os.path.dirname(p), f".{os.path.basename(p)}.lock")


def _holder(fd: int) -> str:
    """The process id written in a lock file, as 'process N', or '' if unreadable."""
    try:
        text = os.pread(fd, 32, 0).decode("ascii", "replace").strip()
    except OSError:
        return ""
    return f" (process {text})" if text.isdigit() else ""


@contextlib.contextmanager
def writer_lock(path) -> Iterator[None]:
    """Hold the lock of output *path* for the block (module docstring); refuse at once,
    in one line naming the file and the holder's process id, when another batch holds it.

    Without ``fcntl`` (not a POSIX system) the block runs unlocked."""
    try:
        import fcntl
    except ImportError:
        yield
        return
    lock = lock_path(path)
    while True:
        try:
            fd = os.open(lock, os.O_RDWR | os.O_CREAT, 0o666)
        except OSError as exc:
            raise BrdfkitError(f"--out {os.fspath(path)!r}: cannot create its lock file "
                               f"{lock!r} ({exc.strerror or exc}); choose a writable "
                               "directory") from None
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            holder = _holder(fd)
            os.close(fd)
            raise BrdfkitError(f"--out {os.fspath(path)!r} is being written by another batch"
                               f"{holder}; wait for it to finish (its lock: {lock}) or choose "
                               "another --out") from None
        # the holder before us may have removed the file between our open and our lock:
        # then we hold a lock on a name nobody else sees; open the file anew
        try:
            same = os.path.samestat(os.fstat(fd), os.stat(lock))
        except FileNotFoundError:
            same = False
        if same:
            break
        os.close(fd)
    try:
        os.ftruncate(fd, 0)
        os.pwrite(fd, f"{os.getpid()}\n".encode("ascii"), 0)
        yield
    finally:
        with contextlib.suppress(FileNotFoundError):
            os.unlink(lock)  # before unlocking: a waiter re-checks the name (above)
        os.close(fd)
