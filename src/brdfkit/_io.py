"""Atomic file output: a file appears whole under its name or not at all.

Every file brdfkit writes (figures, MERL tables, renders, fit results) goes
through :func:`write_atomic`: the bytes go to a temporary file in the target
directory, which is renamed over the target with :func:`os.replace` (atomic on
POSIX), and removed again on any error or interruption. Errors name the path
and what is wrong with it. A process killed outright (SIGKILL, power loss) cannot
remove its temporary file; the name carries the writer's process id
(``.brdfkit-<pid>-XXXXXXXX<suffix>``), and the first write of a later process into the
same directory removes those whose writer is gone (:func:`remove_stale_temp_files`).
:func:`to_jsonable` makes any result JSON-ready in one way for every writer of JSON
(the CLI's ``--json``, the explorer's API): NumPy values to Python types, NaN and ±inf to null.
"""

from __future__ import annotations

import math
import os
import re
import tempfile
import time
from collections.abc import Callable, Mapping
from typing import BinaryIO

import numpy as np

from brdfkit._cache import memo
from brdfkit.errors import BrdfkitError

__all__ = ["write_atomic", "check_output_path", "to_jsonable", "remove_stale_temp_files",
           "TEMP_PREFIX"]

#: The start of every temporary file's name; then the writer's pid, '-', mkstemp's 8 random
#: characters (letters, digits, '_') and the target's suffix.
TEMP_PREFIX = ".brdfkit-"
_TEMP_NAME = re.compile(r"\.brdfkit-(?:(?P<pid>\d+)-)?[a-z0-9_]{8}(?:\.[A-Za-z0-9]+)?")
#: A temporary file without a pid (written before the pid was in the name) is stale when
#: it is older than this: no write of brdfkit takes an hour between creating and renaming.
UNTAGGED_STALE_SECONDS = 3600.0

#: The directories whose stale temporary files this process has removed (once each): a
#: bounded memo — a directory evicted after 256 others is only cleaned once more.
@memo(maxsize=256)
def _clean_once(directory: str) -> bool:
    remove_stale_temp_files(directory)
    return True



def check_output_path(path, *, option: str = "path", suffixes: tuple[str, ...] = ()) -> str:
    """*path* as a string whose directory exists and whose suffix is allowed.

    Call it before expensive work so that a typo fails at once. *option* is how
    the caller names the path in messages (the CLI passes ``"--out"`` or
    ``"--plot"``; the API says ``"path"``).

    Raises
    ------
    BrdfkitError
        Naming *option*, the path and the problem (suffix, a directory in the
        way, missing directory) and the fix.
    """
    p = os.fspath(path)
    if suffixes and not p.lower().endswith(tuple(s.lower() for s in suffixes)):
        raise BrdfkitError(f"{option} must end in {' or '.join(suffixes)}; got {p!r}")
    if os.path.isdir(p):
        raise BrdfkitError(f"{option} {p!r} is a directory; give a file name")
    directory = os.path.dirname(os.path.abspath(p))
    if not os.path.isdir(directory):
        raise BrdfkitError(f"{option} {p!r}: the directory {directory!r} does not exist; "
                           "create it first or choose another path")
    return p


def write_atomic(path, write: Callable[[BinaryIO], None], *, option: str = "path") -> str:
    """Call ``write(fh)`` on a temporary file next to *path*, then rename it to *path*.

    The temporary file is ``.brdfkit-<pid>-XXXXXXXX<suffix>`` in the target directory, so
    *path* is either the old file or the complete new one. It gets the mode a
    plain ``open()`` would give it (the umask applied to 0o666; ``mkstemp`` would
    leave 0o600). On any exception — including KeyboardInterrupt and SystemExit
    (the command line's SIGTERM handler) — the temporary file is removed and the
    exception re-raised; an OSError becomes a BrdfkitError naming *option*, the
    path and the reason (unwritable directory, read-only or pseudo file system
    such as ``/proc``).
    """
    p = check_output_path(path, option=option)
    directory = os.path.dirname(os.path.abspath(p))
    _clean_once(directory)
    try:
        fd, tmp = tempfile.mkstemp(prefix=f"{TEMP_PREFIX}{os.getpid()}-",
                                   suffix=os.path.splitext(p)[1], dir=directory)
    except OSError as exc:
        raise BrdfkitError(f"{option} {p!r}: cannot create a file in {directory!r} "
                           f"({exc.strerror or exc}); choose a writable directory") from None
    try:
        with os.fdopen(fd, "wb") as fh:
            write(fh)
        umask = os.umask(0)
        os.umask(umask)
        os.chmod(tmp, 0o666 & ~umask)
        os.replace(tmp, p)
    except BaseException as exc:
        if os.path.exists(tmp):
            os.unlink(tmp)
        if isinstance(exc, OSError):
            raise BrdfkitError(f"{option} {p!r}: cannot write the file "
                               f"({exc.strerror or exc})") from None
        raise
    return p


def _alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:  # another user's process: alive
        return True
    except OverflowError:  # not a pid at all
        return False
    return True


def remove_stale_temp_files(directory) -> list[str]:
    """Remove brdfkit's own temporary files in *directory* (not below it) that no process
    is writing any more: those whose writer's pid (in the name) is gone, and untagged ones
    older than :data:`UNTAGGED_STALE_SECONDS`. Files of other names are never touched;
    errors (a file removed meanwhile, no permission) are ignored. Returns the removed paths.
    """
    removed = []
    try:
        names = os.listdir(directory)
    except OSError:
        return removed
    now = time.time()
    for name in names:
        m = _TEMP_NAME.fullmatch(name)
        if m is None:
            continue
        path = os.path.join(directory, name)
        try:
            if m["pid"] is not None:
                stale = int(m["pid"]) != os.getpid() and not _alive(int(m["pid"]))
            else:
                stale = now - os.lstat(path).st_mtime > UNTAGGED_STALE_SECONDS
            if stale and os.path.isfile(path) and not os.path.islink(path):
                os.unlink(path)
                removed.append(path)
        except OSError:
            continue
    return removed


def to_jsonable(obj):
    """Recursively convert NumPy values to JSON types; NaN and ±inf become None."""
    if isinstance(obj, Mapping):
        return {str(k): to_jsonable(v) for k, v in obj.items()}
    if isinstance(obj, np.ndarray):
        return to_jsonable(obj.tolist())
    if isinstance(obj, list | tuple):
        return [to_jsonable(v) for v in obj]
    if isinstance(obj, np.bool_ | bool):
        return bool(obj)
    if isinstance(obj, np.integer):
        return int(obj)
    if isinstance(obj, np.floating | float):
        x = float(obj)
        return x if math.isfinite(x) else None
    return obj
