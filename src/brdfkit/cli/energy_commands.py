"""
The energy verdicts command: ``verdicts``
=========================================

- ``brdfkit verdicts [--json | --markdown] [--row LABEL ...] [--spec JSON ...] [--list]`` —
  the energy table of issue 22 §3 (:mod:`brdfkit.report.energy_table`): for each row
  reciprocity, energy and where, the white furnace 1 − a(θ) at 0, 60, 80, 89°, E_avg and
  divergence, each with its accuracy, beside its paper's claim; then the findings
  (:mod:`brdfkit.report.energy_findings`) with their numbers.

Like ``table2``: progress on stderr when it is a terminal (never in ``--json`` output);
``--json`` prints ``{"rows": [...], "findings": [...]}`` (strict JSON: an infinite error
estimate, where the engine did not converge, is null). A plain click command;
:mod:`brdfkit.cli` adds it to the group.
"""

from __future__ import annotations

import json

import click

import brdfkit.cli._progress as _progress
from brdfkit.cli._common import emit_json
from brdfkit.errors import BrdfkitError

__all__ = ["parse_spec_option", "verdicts_cmd"]


def parse_spec_option(text: str) -> dict:
    """``--spec JSON``: the dict form of a model spec, with an optional ``"label"`` → a
    row entry (no claim). One-line errors name the option and what was received."""
    from brdfkit.report.energy_table import spec_row
    from brdfkit.spec import ModelSpec

    try:
        d = json.loads(text)
    except json.JSONDecodeError as exc:
        raise BrdfkitError(f"--spec must be a JSON object such as "
                           f"'{{\"model\": \"microfacet\", \"params\": {{\"alpha\": 0.5}}}}'; "
                           f"got {text!r} ({exc.msg})") from None
    if not isinstance(d, dict):
        raise BrdfkitError(f"--spec must be a JSON object (the dict form of a model spec); "
                           f"got {text!r}")
    label = d.pop("label", None)
    if label is not None and not isinstance(label, str):
        raise BrdfkitError(f"--spec: label must be a string; got {label!r}")
    ModelSpec.from_dict(d)  # validated here: a bad spec fails before any row is computed
    return spec_row(d, label)


@click.command("verdicts")
@click.option("--json", "as_json", is_flag=True,
              help='Print {"rows": [...], "findings": [...]} as JSON.')
@click.option("--markdown", "as_md", is_flag=True, help="Print Markdown (table, findings).")
@click.option("--row", "labels", multiple=True, metavar="LABEL",
              help="Only the row LABEL (repeatable; 'brdfkit verdicts --list' prints them).")
@click.option("--spec", "specs", multiple=True, metavar="JSON",
              help='Add a row for a model spec in its dict form, e.g. \'{"model": '
                   '"microfacet", "params": {"distribution": "ggx", "alpha": 0.5}, '
                   '"label": "mine"}\' (repeatable; at white settings if you want the '
                   'furnace to mean a = 1).')
@click.option("--list", "list_rows", is_flag=True, help="Print the row labels and stop.")
def verdicts_cmd(as_json, as_md, labels, specs, list_rows):
    """Energy verdicts of today's answers beside the papers' (issue 22): a table like
    Lewis's Table 2.

    For each row (a model spec at white settings: rho = 1, F = 1): reciprocity (max
    relative asymmetry), energy (check's verdict, max albedo and where), the white
    furnace deficit 1 - a(theta) at 0, 60, 80, 89 deg, E_avg and divergence, each with
    the albedo engine's accuracy, the paper's claim and whether they agree; then the
    findings with their numbers. The full table takes a few minutes.
    """
    from brdfkit.report.energy_findings import findings, format_findings
    from brdfkit.report.energy_table import (
        ROWS,
        energy_table,
        format_markdown,
        format_table,
        select_rows,
    )

    if as_json and as_md:
        raise BrdfkitError("give at most one of --json and --markdown")
    if list_rows:
        if labels or specs or as_json or as_md:
            raise BrdfkitError("--list prints the row labels only; drop --row, --spec, "
                               "--json and --markdown")
        click.echo("\n".join(r["label"] for r in ROWS))
        return
    given = [parse_spec_option(s) for s in specs]
    rows = select_rows(labels) if labels else ([] if given else list(ROWS))
    show = not as_json and _progress.stderr_is_interactive()
    with _progress.counter("verdicts", enabled=show) as progress:
        table = energy_table(rows=[*rows, *given], progress=progress)
    found = findings(table)
    if as_json:
        emit_json({"rows": table, "findings": found})
    elif as_md:
        click.echo(format_markdown(table))
        click.echo("\n**Findings**\n")
        click.echo(format_findings(found))
    else:
        click.echo("Energy verdicts (issue 22): today's answers beside the papers', at white "
                   "settings (rho = 1, F = 1)\n")
        click.echo(format_table(table))
        click.echo("\nFindings")
        click.echo(format_findings(found))
