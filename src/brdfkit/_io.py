"""Atomic file output: a file appears whole under its name or not at all.

Every file brdfkit writes (figures, MERL tables, renders, fit results) goes
through :func:`write_atomic`: the bytes go to a temporary file in the target
directory, which is renamed over the target with :func:`os.replace` (atomic on
POSIX), and removed again on any error or interruption. Errors name the path
and what is wrong with it.
"""

from __future__ import annotations

import os
import tempfile
from collections.abc import Callable
from typing import BinaryIO

from brdfkit.errors import BrdfkitError

__all__ = ["write_atomic", "check_output_path"]


def check_output_path(path, *, option: str = "path", suffixes: tuple[str, ...] = ()) -> str:
    """*path* as a string, its directory existing and writable and its suffix allowed.

    Raises
    ------
    BrdfkitError
        Naming *option*, the path and the problem (suffix, missing directory,
        not writable, a directory in the way).
    """
    p = os.fspath(path)
    if suffixes and not p.lower().endswith(tuple(s.lower() for s in suffixes)):
        raise BrdfkitError(f"{option} must end in {' or '.join(suffixes)}; got {p!r}")
    directory = os.path.dirname(os.path.abspath(p))
    if not os.path.isdir(directory):
        raise BrdfkitError(f"{option}: output directory does not exist: {directory}")
    if not os.access(directory, os.W_OK):
        raise BrdfkitError(f"{option}: output directory is not writable: {directory}")
    if os.path.isdir(p):
        raise BrdfkitError(f"{option}: {p!r} is a directory, not a file name")
    return p


def write_atomic(path, write: Callable[[BinaryIO], None], *, option: str = "path") -> str:
    """Call ``write(fh)`` on a temporary file next to *path*, then rename it to *path*.

    The file gets the mode a plain ``open()`` would give it (the umask applied to
    0o666; ``mkstemp`` would leave 0o600). On any exception — including
    KeyboardInterrupt and SystemExit (SIGTERM in the CLI) — the temporary file is
    removed and the exception re-raised; an OSError becomes a BrdfkitError naming
    the path.
    """
    p = check_output_path(path, option=option)
    directory = os.path.dirname(os.path.abspath(p))
    base = os.path.basename(p)
    try:
        fd, tmp = tempfile.mkstemp(prefix=f".{base}.", suffix=".brdfkit-tmp", dir=directory)
    except OSError as exc:
        raise BrdfkitError(f"{option}: cannot create a file in {directory}: "
                           f"{exc.strerror or exc}") from None
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
            raise BrdfkitError(f"{option}: cannot write {p!r}: {exc.strerror or exc}") from None
        raise
    return p
