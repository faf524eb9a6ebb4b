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

import matplotlib

# Headless: no display on servers and CI. Importing brdfkit.figures runs this before any
# figure is built (the figure modules import pyplot inside their functions, never at import).
matplotlib.use("Agg")

from brdfkit import _io  # noqa: E402
from brdfkit.errors import BrdfkitError  # noqa: E402

__all__ = ["FORMATS", "check_output_path", "save_atomic"]

#: Output formats, chosen by the file's suffix.
FORMATS = ("png", "svg")


def check_output_path(path, *, option: str = "path") -> tuple[str, str]:
    """Check that a figure can be written to *path*; return ``(path, format)``.

    :func:`brdfkit._io.check_output_path` with the figure formats: the suffix
    must be ``.png`` or ``.svg`` (the format is taken from it).

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
    return _io.check_output_path(path, option=option), ext


def save_atomic(fig, path, *, dpi: int = 150, option: str = "path") -> str:
    """Save *fig* to *path* (format from the suffix: .png or .svg), atomically.

    Written through :func:`brdfkit._io.write_atomic`: *path* is either the old
    file or the complete new one, and any exception — including
    :class:`SystemExit` raised by the command line's SIGTERM handler — removes
    the temporary ``.brdfkit-<pid>-XXXXXXXX.<ext>`` file before it propagates.

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
        operating system refused the write: the message names *option*, the
        path and the reason.
    """
    path, ext = check_output_path(path, option=option)
    return _io.write_atomic(
        path, lambda fh: fig.savefig(fh, format=ext, dpi=dpi, bbox_inches="tight"),
        option=option)
