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
- :mod:`brdfkit.cli.data_commands` — ``materials``, ``export``.
- :mod:`brdfkit.cli.explore_commands` — ``explore`` (the browser app).
- :mod:`brdfkit.cli.render_commands` — ``render sphere``.
- :mod:`brdfkit.cli.fit_commands` — ``fit``.
- :mod:`brdfkit.cli._group` — the group class (one-line errors, SIGTERM).
- :mod:`brdfkit.cli._common` — model options, directions, JSON.
- :mod:`brdfkit.cli._progress` — progress on stderr.

To add a command: write it with ``@click.command(...)`` in a module under
``brdfkit/cli/`` and add one ``main.add_command(...)`` line below.

Public objects
--------------
- :data:`main` — the click group (entry point ``brdfkit``).
"""

from __future__ import annotations

import click

import brdfkit
from brdfkit.cli._group import BrdfkitGroup
from brdfkit.cli.analysis import albedo_cmd, check_cmd, figure_cmd, table2_cmd
from brdfkit.cli.data_commands import export_cmd, materials_cmd
from brdfkit.cli.explore_commands import explore_cmd
from brdfkit.cli.fit_commands import fit_cmd
from brdfkit.cli.model_commands import eval_cmd, models_cmd
from brdfkit.cli.render_commands import render_group, sphere_cmd

__all__ = ["main"]


@click.group("brdfkit", cls=BrdfkitGroup, context_settings={"help_option_names": ["-h", "--help"]})
@click.version_option(brdfkit.__version__, prog_name="brdfkit")
def main() -> None:
    """brdfkit: physically plausible reflectance models (BRDFs).

    Angles are in degrees on the command line. Run 'brdfkit COMMAND --help'
    for a command's options.
    """


main.add_command(models_cmd)
main.add_command(eval_cmd)
main.add_command(albedo_cmd)
main.add_command(check_cmd)
main.add_command(table2_cmd)
main.add_command(figure_cmd)
main.add_command(materials_cmd)
main.add_command(export_cmd)
main.add_command(explore_cmd)
render_group.add_command(sphere_cmd)
main.add_command(render_group)
main.add_command(fit_cmd)
