"""Writing figures to disk: output-path checks and the atomic writer.

This module knows nothing about which figures exist (that is
:mod:`brdfkit.figures._registry`); the CLI's ``--plot`` uses it for plots
that are not registered figures.

Public objects (re-exported by :mod:`brdfkit.figures`)
------------------------------------------------------
- :func:`check_output_path` — validate a ``.png``/``.svg`` path before any work.
- :func:`save_atomic` — write a Matplotlib figure via temp file + ``os.replace``.
"""

from __future__ import annotations

import os
import tempfile

import matplotlib

# Headless: no display on servers and CI. Importing brdfkit.figures runs this before any
# figure is built (the figure modules import pyplot inside their functions, never at import).
matplotlib.use("Agg")

from brdfkit.errors import BrdfkitError  # noqa: E402

__all__ = ["FORMATS", "check_output_path", "save_atomic"]

#: Output formats, chosen by the file's suffix.
FORMATS = ("png", "svg")


def check_output_path(path, *, option: str = "path") -> tuple[str, str]:
    """Check that a figure can be written to *path*; return ``(path, format)``.

    Call it before expensive work so that a typo fails at once. *option* is
    how the caller names the path in messages (the CLI passes ``"--out"`` or
    ``"--plot"``; the API says ``"path"``).

    Raises
    ------
    BrdfkitError
        The suffix is not ``.png``/``.svg``, *path* is a directory, or its
        directory does not exist.
    """
    path = os.fspath(path)
    ext = os.path.splitext(path)[1].lower().lstrip(".")
    if ext not in FORMATS:
        raise BrdfkitError(f"{option} must end in .png or .svg (the format is taken from the "
                           f"suffix); got {path!r}")
    if os.path.isdir(path):
        raise BrdfkitError(f"{option} {path!r} is a directory; give a file name ending in "
                           f".{ext}")
    directory = os.path.dirname(os.path.abspath(path))
    if not os.path.isdir(directory):
        raise BrdfkitError(f"{option} {path!r}: the directory {directory!r} does not exist; "
                           "create it first or choose another path")
    return path, ext


def save_atomic(fig, path, *, dpi: int = 150, option: str = "path") -> str:
    """Save *fig* to *path* (format from the suffix: .png or .svg) via a temp file + os.replace.

    The figure is written to ``.brdfkit-XXXX.<ext>`` in the target directory
    and renamed over *path*, so *path* is either the old file or the complete
    new one. Any exception — including :class:`SystemExit` raised by the
    command line's SIGTERM handler and :class:`KeyboardInterrupt` — removes the
    temp file before it propagates.

    Parameters
    ----------
    fig : matplotlib.figure.Figure
    path : str or os.PathLike
    dpi : int, keyword-only
        Resolution of PNG output.
    option : str, keyword-only
        How the caller names *path* in error messages (e.g. ``"--plot"``).

    Raises
    ------
    BrdfkitError
        Bad suffix, missing directory (see :func:`check_output_path`), or the
        operating system refused the write (unwritable directory, read-only or
        pseudo file system such as ``/proc``): the message names *option*, the
        path and the reason.
    """
    path, ext = check_output_path(path, option=option)
    directory = os.path.dirname(os.path.abspath(path))
    try:
        fd, tmp = tempfile.mkstemp(prefix=".brdfkit-", suffix="." + ext, dir=directory)
    except OSError as exc:
        raise BrdfkitError(f"{option} {path!r}: cannot create a file in {directory!r} "
                           f"({exc.strerror or exc}); choose a writable directory") from None
    try:
        with os.fdopen(fd, "wb") as fh:
            fig.savefig(fh, format=ext, dpi=dpi, bbox_inches="tight")
        # mkstemp creates the file with mode 0600; give it the mode a plain open() would
        umask = os.umask(0)
        os.umask(umask)
        os.chmod(tmp, 0o666 & ~umask)
        os.replace(tmp, path)
    except BaseException as exc:
        if os.path.exists(tmp):
            os.unlink(tmp)
        if isinstance(exc, OSError):
            raise BrdfkitError(f"{option} {path!r}: cannot write the file "
                               f"({exc.strerror or exc})") from None
        raise
    return path
