"""Progress on stderr for long commands (``table2``, ``figure``, ``check``, ``render`` …).

Shown only when stderr is a terminal and the command's output is not JSON:
a pipe, a log file or a ``--json`` consumer sees nothing extra. The display
is a single counter line rewritten in place (``\\r``) and erased when the
work ends, so the terminal is left with the command's own output only.

Public objects
--------------
- :func:`stderr_is_interactive` — the test deciding whether to show progress.
- :func:`counter` — context manager yielding a ``progress(done, total, what)``
  callback (or None when progress is off).
- :func:`status` — context manager printing one "building …" line.
- :func:`working` — :func:`status` shown when a person watches and the output is not JSON.
"""

from __future__ import annotations

import contextlib
import sys
import time
from collections.abc import Callable, Iterator

import click

__all__ = ["stderr_is_interactive", "counter", "status", "working"]


def stderr_is_interactive() -> bool:
    """True when stderr is a terminal (a person is watching)."""
    try:
        return bool(sys.stderr.isatty())
    except (AttributeError, ValueError):  # closed or exotic streams: treat as not interactive
        return False


@contextlib.contextmanager
def counter(label: str, *, enabled: bool) -> Iterator[Callable[[int, int, str], None] | None]:
    """Yield ``progress(done, total, what)`` writing ``label: done/total what`` on stderr.

    Yields None when not *enabled* (pass it straight to a ``progress=``
    keyword). The line is erased on exit, also on errors.
    """
    if not enabled:
        yield None
        return
    width = 0

    def progress(done: int, total: int, what: str) -> None:
        nonlocal width
        text = f"{label}: {done}/{total} {what}".rstrip()
        click.echo("\r" + text.ljust(width), nl=False, err=True)
        width = max(width, len(text))

    try:
        yield progress
    finally:
        if width:
            click.echo("\r" + " " * width + "\r", nl=False, err=True)


@contextlib.contextmanager
def status(text: str, *, enabled: bool) -> Iterator[None]:
    """Print ``text …`` on stderr before the block and ``done (N s)`` after it, if *enabled*."""
    if not enabled:
        yield
        return
    click.echo(f"{text} ...", nl=False, err=True)
    t0 = time.perf_counter()
    ok = False
    try:
        yield
        ok = True
    finally:
        end = f" done ({time.perf_counter() - t0:.1f} s)" if ok else " failed"
        click.echo(end, err=True)


def working(text: str, *, as_json: bool = False):
    """:func:`status` of *text*, shown when stderr is a terminal and the output is not JSON.

    For a command whose work has no count (one albedo curve, one render, one table)
    and may take seconds (a material, a pumped or compensated model).
    """
    return status(text, enabled=not as_json and stderr_is_interactive())
