"""Atomic file output: a file appears whole under its name or not at all.

Every file brdfkit writes (figures, MERL tables, renders, fit results) goes
through :func:`write_atomic`: the bytes go to a temporary file in the target
directory, which is renamed over the target with :func:`os.replace` (atomic on
POSIX), and removed again on any error or interruption. Errors name the path
and what is wrong with it. :func:`to_jsonable` makes any result JSON-ready in
one way for every writer of JSON (the CLI's ``--json``, the explorer's API):
NumPy values to Python types, NaN and ±inf to null.
"""

from __future__ import annotations

import math
import os
import tempfile
from collections.abc import Callable, Mapping
from typing import BinaryIO

import numpy as np

from brdfkit.errors import BrdfkitError

__all__ = ["write_atomic", "check_output_path", "to_jsonable"]


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

    The temporary file is ``.brdfkit-XXXX<suffix>`` in the target directory, so
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
    try:
        fd, tmp = tempfile.mkstemp(prefix=".brdfkit-", suffix=os.path.splitext(p)[1],
                                   dir=directory)
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
