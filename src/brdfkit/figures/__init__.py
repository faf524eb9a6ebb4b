"""
Figures of the papers, reproduced by computation
================================================

A registry of named figures. Each figure function takes no required
arguments and returns a Matplotlib :class:`~matplotlib.figure.Figure`
(Agg backend) with labelled axes, a legend and a caption naming the paper
figure; :func:`save_figure` writes PNG or SVG atomically.

Public objects
--------------
- :data:`FIGURES` — name → figure function.
- :func:`register_figure` — decorator adding a function under a name.
- :func:`make_figure`, :func:`save_figure`, :func:`figure_names`.

Figure modules: :mod:`~brdfkit.figures.lewis` (``lewis-fig5``,
``lewis-fig7``, ``lewis-fig8``, ``lewis-fig9``), :mod:`~brdfkit.figures.neumann`
(``neumann-fig1``).
"""

from __future__ import annotations

import os
import tempfile
from collections.abc import Callable

import matplotlib

matplotlib.use("Agg")  # noqa: E402  (headless: no display on servers and CI)

from brdfkit.errors import BrdfkitError  # noqa: E402

__all__ = ["FIGURES", "register_figure", "make_figure", "save_figure", "figure_names",
           "save_atomic"]

FIGURES: dict[str, Callable] = {}


def register_figure(name: str) -> Callable[[Callable], Callable]:
    """Decorator: register a figure function under *name* (e.g. ``"lewis-fig5"``)."""
    def deco(func: Callable) -> Callable:
        if name in FIGURES:
            raise RuntimeError(f"figure {name!r} registered twice")
        FIGURES[name] = func
        return func
    return deco


def figure_names() -> list[str]:
    """Registered figure names, sorted."""
    return sorted(FIGURES)


def make_figure(name: str):
    """Build the figure *name* (a Matplotlib Figure)."""
    key = str(name).strip().lower()
    if key not in FIGURES:
        raise BrdfkitError(f"unknown figure {name!r}; valid names: " + ", ".join(figure_names()))
    return FIGURES[key]()


def save_atomic(fig, path: str, *, dpi: int = 150) -> str:
    """Save *fig* to *path* (format from the suffix: .png or .svg) via a temp file + os.replace."""
    path = os.fspath(path)
    ext = os.path.splitext(path)[1].lower().lstrip(".")
    if ext not in ("png", "svg"):
        raise BrdfkitError(f"--out must end in .png or .svg; got {path!r}")
    directory = os.path.dirname(os.path.abspath(path))
    if not os.path.isdir(directory):
        raise BrdfkitError(f"output directory does not exist: {directory}")
    fd, tmp = tempfile.mkstemp(prefix=".brdfkit-", suffix="." + ext, dir=directory)
    try:
        with os.fdopen(fd, "wb") as fh:
            fig.savefig(fh, format=ext, dpi=dpi, bbox_inches="tight")
        # mkstemp creates the file with mode 0600; give it the mode a plain open() would
        umask = os.umask(0)
        os.umask(umask)
        os.chmod(tmp, 0o666 & ~umask)
        os.replace(tmp, path)
    except BaseException:
        if os.path.exists(tmp):
            os.unlink(tmp)
        raise
    return path


def save_figure(name: str, path: str, *, dpi: int = 150) -> str:
    """Build figure *name* and write it to *path* (.png or .svg)."""
    import matplotlib.pyplot as plt

    fig = make_figure(name)
    try:
        return save_atomic(fig, path, dpi=dpi)
    finally:
        plt.close(fig)


# Importing the figure modules registers their figures.
from brdfkit.figures import lewis, neumann  # noqa: E402,F401,I001
from brdfkit.figures import pumping as _pumping_figures  # noqa: E402,F401  (neumann-fig3 ... fig7)
