"""
The ``brdfkit`` command line
============================

A thin layer over the library (click). Angles are in DEGREES on the command
line (radians in the API); every command that prints data has ``--json``.
Bad input prints one line ``brdfkit: error: <message>`` on stderr and exits
with status 2.

Commands defined here
---------------------
- ``brdfkit models [--json]`` — the registry: parameters (default, bounds,
  unit), citation, reciprocity claim, sampler.
- ``brdfkit eval MODEL -p NAME=VALUE ... --wi THETA,PHI --wo THETA,PHI`` —
  one BRDF value f_r in 1/sr.

Other modules add their commands to :data:`main` when imported below.

Public objects
--------------
- :data:`main` — the click group (entry point ``brdfkit``).
"""

from __future__ import annotations

import click

import brdfkit
from brdfkit.cli._common import (
    build_model,
    emit_json,
    fail,
    handle_errors,
    model_options,
    parse_direction,
)
from brdfkit.errors import BrdfkitError

__all__ = ["main"]


class BrdfkitGroup(click.Group):
    """Click group that reports :class:`BrdfkitError` from any command as one line, exit 2."""

    def invoke(self, ctx: click.Context):
        try:
            return super().invoke(ctx)
        except BrdfkitError as exc:
            fail(str(exc))


@click.group(cls=BrdfkitGroup, context_settings={"help_option_names": ["-h", "--help"]})
@click.version_option(brdfkit.__version__, prog_name="brdfkit")
def main() -> None:
    """brdfkit: physically plausible reflectance models (BRDFs).

    Angles are in degrees on the command line. Run 'brdfkit COMMAND --help'
    for a command's options.
    """


# --------------------------------------------------------------------------- models
def _yes(flag: bool) -> str:
    return "yes" if flag else "no"


def _param_row(p: dict) -> tuple[str, str, str, str]:
    default = "none" if p["default"] is None else str(p["default"])
    bounds = "{" + ", ".join(p["choices"]) + "}" if "choices" in p else p["bounds"]
    per = {"colour": " per channel", "lobes": " per lobe"}.get(p["kind"], "")
    unit = p["unit"] or "-"
    return p["name"], default, bounds, f"{unit}{per}"


@main.command("models")
@click.option("--json", "as_json", is_flag=True, help="Print JSON (a list of model descriptions).")
@handle_errors
def models_cmd(as_json: bool) -> None:
    """List every registered model with its parameters, citation and claims.

    For each model: aliases, whether its formula claims to be reciprocal,
    whether it has an importance sampler, the citation (paper and equation),
    and each parameter's default, bounds and unit. 'beta' (where listed) is
    the lobe half-angle alternative to the width parameter, in degrees on the
    command line.
    """
    descriptions = [cls.describe() for cls in brdfkit.MODELS.values()]
    if as_json:
        emit_json(descriptions)
        return
    click.echo(f"{len(descriptions)} models (reciprocal = formula claims f(wi,wo) = f(wo,wi); "
               "sampler = importance sampler beyond the cosine fallback)\n")
    for d in descriptions:
        aliases = f"  (aliases: {', '.join(d['aliases'])})" if d["aliases"] else ""
        click.echo(f"{d['name']}{aliases}")
        click.echo(f"    reciprocal: {_yes(d['reciprocal'])}   sampler: {_yes(d['has_sampler'])}"
                   f"   cite: {d['citation']}")
        if d["summary"]:
            click.echo(f"    {d['summary']}")
        rows = [_param_row(p) for p in d["params"]]
        if d["beta"]:
            rows.append(("beta", "-", "(0, 90)", f"deg (sets {d['beta']})"))
        widths = [max(len(r[i]) for r in rows) for i in range(4)] if rows else []
        for r in rows:
            click.echo("      " + "  ".join(c.ljust(w) for c, w in zip(r, widths, strict=True))
                       .rstrip())
        click.echo("")


# --------------------------------------------------------------------------- eval
@main.command("eval")
@model_options
@click.option("--wi", required=True, metavar="THETA,PHI",
              help="Direction toward the light: polar angle from the normal and azimuth, "
                   "in DEGREES.")
@click.option("--wo", required=True, metavar="THETA,PHI",
              help="Direction toward the viewer: polar angle and azimuth, in DEGREES.")
@click.option("--json", "as_json", is_flag=True,
              help='Print {"model": ..., "params": {...}, "value": ...} (a list per channel).')
@handle_errors
def eval_cmd(model: str, param: tuple[str, ...], pump: str | None, times: int, wi: str, wo: str,
             as_json: bool) -> None:
    """Evaluate the BRDF f_r(wi, wo) of MODEL in 1/sr (without the cosine factor).

    Example: brdfkit eval modified-phong -p rho_s=0.5 -p n=50 --wi 30,0 --wo 30,180

    Directions below the horizon (THETA > 90) give 0. 'beta' is given in
    degrees here.
    """
    m = build_model(model, param, pump=pump, times=times)
    vi = parse_direction(wi, "--wi")
    vo = parse_direction(wo, "--wo")
    value = m.eval(vi, vo)
    if as_json:
        d = m.to_dict() if hasattr(m, "to_dict") else {"model": model, "params": {}}
        emit_json({"model": d["model"], "params": d["params"],
                   **({"pump": d["pump"]} if "pump" in d else {}), "value": value})
        return
    v = value.tolist() if hasattr(value, "tolist") else value
    click.echo(" ".join(repr(float(x)) for x in v) if isinstance(v, list) else repr(float(v)))


# --------------------------------------------------------------------------- more commands
# Modules that add commands to `main` are imported here (after `main` exists).
from brdfkit.cli import analysis as _analysis  # noqa: E402,F401  (albedo, check, table2, figure)
