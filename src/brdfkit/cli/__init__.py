"""
The ``brdfkit`` command line
============================

A thin layer over the library (click). Angles are in DEGREES on the command
line (radians in the API); every command that prints data has ``--json``.
Bad input — from brdfkit or from click's own parsing (missing option, bad
choice, unknown command, value out of range) — prints one line
``brdfkit: error: <message>`` on stderr and exits with status 2. Long
commands (``table2``, ``figure``) show progress on stderr when it is a
terminal, never in ``--json`` output.

Layout: the group is built here, in one place, from plain click commands;
the command modules import :mod:`brdfkit.cli._common` and never this module.

- :mod:`brdfkit.cli.model_commands` — ``models``, ``eval``.
- :mod:`brdfkit.cli.analysis` — ``albedo``, ``check``, ``table2``, ``figure``.
- :mod:`brdfkit.cli.energy_commands` — ``verdicts`` (the energy table of issue 22).
- :mod:`brdfkit.cli.data_commands` — ``materials``, ``export``.
- :mod:`brdfkit.cli.explore_commands` — ``explore`` (the browser app).
- :mod:`brdfkit.cli.render_commands` — ``render sphere``.
- :mod:`brdfkit.cli.fit_commands` — ``fit``.
- :mod:`brdfkit.cli.reproduce_commands` — ``reproduce`` (the papers' report).
- :mod:`brdfkit.cli._group` — the group class (one-line errors, SIGTERM).
- :mod:`brdfkit.cli._common` — model options, directions, JSON.
- :mod:`brdfkit.cli._progress` — progress on stderr.

To add a command: write it with ``@click.command(...)`` in a module under
``brdfkit/cli/`` and add one line to ``_COMMANDS`` below (commands are
imported when looked up, so each command pays only for its own imports).

Public objects
--------------
- :data:`main` — the click group.
- :func:`run` — the ``brdfkit`` console script and ``python -m brdfkit``: ``main``
  with a fast exit.
"""

from __future__ import annotations

import atexit
import os
import sys

import click

import brdfkit
from brdfkit.cli._group import BrdfkitGroup

__all__ = ["main", "run"]


#: command name -> where it is defined; imported only when the command is looked up
_COMMANDS = {
    "models": "brdfkit.cli.model_commands:models_cmd",
    "eval": "brdfkit.cli.model_commands:eval_cmd",
    "albedo": "brdfkit.cli.analysis:albedo_cmd",
    "check": "brdfkit.cli.analysis:check_cmd",
    "table2": "brdfkit.cli.analysis:table2_cmd",
    "verdicts": "brdfkit.cli.energy_commands:verdicts_cmd",
    "figure": "brdfkit.cli.analysis:figure_cmd",
    "materials": "brdfkit.cli.data_commands:materials_cmd",
    "export": "brdfkit.cli.data_commands:export_cmd",
    "explore": "brdfkit.cli.explore_commands:explore_cmd",
    "render": "brdfkit.cli.render_commands:render_group",
    "fit": "brdfkit.cli.fit_commands:fit_cmd",
    "reproduce": "brdfkit.cli.reproduce_commands:reproduce_cmd",
}


@click.group("brdfkit", cls=BrdfkitGroup, lazy=_COMMANDS,
             context_settings={"help_option_names": ["-h", "--help"]})
@click.version_option(brdfkit.__version__, prog_name="brdfkit")
def main() -> None:
    """brdfkit: physically plausible reflectance models (BRDFs).

    Angles are in degrees on the command line. Run 'brdfkit COMMAND --help'
    for a command's options.
    """


def run() -> None:
    """The ``brdfkit`` console script: :data:`main`, then a fast exit.

    When the command has finished (its output written and flushed, its ``finally``
    blocks run), the atexit handlers run and the process ends with ``os._exit``,
    skipping the interpreter's teardown of every module: with Numba and LLVM loaded that
    teardown took 0.2-0.6 s (measured), a quarter of a one-line ``brdfkit fit``. Nothing
    is lost: no output is pending, and atexit cleanups (e.g. multiprocessing's) still
    run. An exception other than SystemExit propagates as usual (a bug: its traceback).
    """
    try:
        main(prog_name="brdfkit")
        code = 0
    except SystemExit as exc:
        code = exc.code
    if code is None:
        code = 0
    elif not isinstance(code, int):  # sys.exit("message"): printed, status 1
        print(code, file=sys.stderr)
        code = 1
    atexit._run_exitfuncs()
    for stream in (sys.stdout, sys.stderr):
        try:
            stream.flush()
        except (OSError, ValueError):  # a closed pipe (e.g. '| head'): nothing to flush to
            pass
    os._exit(code)
