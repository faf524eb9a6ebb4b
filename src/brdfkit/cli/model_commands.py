"""
Model commands: ``models`` and ``eval``
=======================================

- ``brdfkit models [--json]`` — the registry: parameters (default, bounds,
  unit), citation, reciprocity claim, sampler.
- ``brdfkit models FILE [--json]`` — the model(s) a user's ``.py`` or ``.brdf`` file
  defines: parameters (kind, default, bounds, doc), detected isotropy and its reason,
  the file's claims, notes (e.g. unsupported constructs ignored).
- ``brdfkit eval MODEL -p NAME=VALUE ... --wi THETA,PHI --wo THETA,PHI`` —
  one BRDF value f_r in 1/sr.

Plain click commands; :mod:`brdfkit.cli` adds them to the ``brdfkit`` group.
"""

from __future__ import annotations

import click

import brdfkit
from brdfkit.cli._common import build_model, emit_json, model_options, parse_direction
from brdfkit.errors import BrdfkitError

__all__ = ["models_cmd", "eval_cmd"]


# --------------------------------------------------------------------------- models
def _yes(flag: bool) -> str:
    return "yes" if flag else "no"


def _param_row(p: dict) -> tuple[str, str, str, str]:
    default = "none" if p["default"] is None else str(p["default"])
    bounds = "{" + ", ".join(p["choices"]) + "}" if "choices" in p else p["bounds"]
    per = {"colour": " per channel", "lobes": " per lobe"}.get(p["kind"], "")
    unit = p["unit"] or "-"
    return p["name"], default, bounds, f"{unit}{per}"


#: The header of a parameter table (the columns of _param_row, then the doc).
_PARAM_HEADER = ("parameter", "default", "bounds", "unit", "meaning")


def _param_table(rows, header=_PARAM_HEADER) -> list[str]:
    """Lines of a parameter table with its header, columns aligned (the last one free)."""
    if not rows:
        return ["      (no parameters)"]
    rows = [header, *rows]
    widths = [max(len(r[i]) for r in rows) for i in range(len(header) - 1)]
    return ["      " + "  ".join([*(c.ljust(w) for c, w in zip(r, widths, strict=False)),
                                   r[-1]]).rstrip() for r in rows]


@click.command("models")
@click.argument("spec", required=False, metavar="[NAME|FILE]")
@click.option("--json", "as_json", is_flag=True, help="Print JSON (a list of model descriptions).")
def models_cmd(spec: str | None, as_json: bool) -> None:
    """List every registered model with its parameters, citation and claims; with NAME (a
    registered name or alias) that model only; with FILE (a .py or .brdf file, PATH.py:NAME
    for one of several), the models it defines.

    For each model: aliases, whether its formula claims to be reciprocal,
    whether it has an importance sampler, the citation (paper and equation),
    and a table of its parameters: default, bounds, unit and meaning. 'beta' (where
    listed) is the lobe half-angle alternative to the width parameter, in degrees on the
    command line. For a FILE: each parameter's kind and doc, the detected
    isotropy and why, the file's claims (reciprocity measured at the defaults
    when not claimed), its sampler and notes. Built-in materials: 'brdfkit materials'.
    """
    from brdfkit.spec import ModelSpec

    if spec is not None and ModelSpec(spec).kind in ("python-file", "brdf-file"):
        _file_models(spec, as_json)
        return
    if spec is not None and ModelSpec(spec).kind != "model":
        raise BrdfkitError(f"brdfkit models takes a registered model name, a .py or a .brdf "
                           f"file; {spec!r} is a material or a MERL file (brdfkit materials "
                           "lists the built-in materials)")
    classes = (list(brdfkit.MODELS.values()) if spec is None
               else [brdfkit.models.resolve(spec)])  # an unknown name: one line, valid names
    descriptions = [cls.describe() for cls in classes]
    if as_json:
        emit_json(descriptions)
        return
    if spec is None:
        click.echo(f"{len(descriptions)} models (reciprocal = formula claims f(wi,wo) = "
                   "f(wo,wi); sampler = importance sampler beyond the cosine fallback)\n")
    for d in descriptions:
        aliases = f"  (aliases: {', '.join(d['aliases'])})" if d["aliases"] else ""
        click.echo(f"{d['name']}{aliases}")
        click.echo(f"    reciprocal: {_yes(d['reciprocal'])}   sampler: {_yes(d['has_sampler'])}"
                   f"   cite: {d['citation']}")
        if d["summary"]:
            click.echo(f"    {d['summary']}")
        rows = [(*_param_row(p), p.get("doc") or "") for p in d["params"]]
        if d["beta"]:
            rows.append(("beta", "-", "(0, 90)", "deg", f"lobe half-angle; sets {d['beta']}"))
        for line in _param_table(rows):
            click.echo(line)
        click.echo("")


def _claim(value) -> str:
    return "not claimed" if value is None else f"claimed {_yes(value)}"


def _file_models(file: str, as_json: bool) -> None:
    from brdfkit.spec import ModelSpec
    from brdfkit.user.model import FormulaBRDF

    kind = ModelSpec(file).kind
    if kind not in ("python-file", "brdf-file"):
        raise BrdfkitError(f"brdfkit models FILE takes a .py or .brdf file (PATH.py:NAME for "
                           f"one model of several); got {file!r} ('brdfkit models' lists the "
                           "registered models)")
    if kind == "python-file" and file.strip().lower().endswith(".py"):  # every model of it
        from brdfkit.user.python_file import definitions
        models = [FormulaBRDF(d) for d in definitions(file.strip())]
    else:
        models = [brdfkit.model(file)]
    descriptions = [m.describe() for m in models]
    if as_json:
        emit_json(descriptions)
        return
    for d in descriptions:
        click.echo(f"{d['name']}  ({d['source']}; spec {d['target']})")
        if d["summary"]:
            click.echo(f"    {d['summary']}")
        click.echo(f"    isotropic: {_yes(d['isotropic'])} ({d['isotropy_reason']})")
        claims = d["claims"]
        measured = ("" if claims["reciprocal"] is not None else
                    f" (measured at the defaults: {_yes(d['reciprocal'])})")
        click.echo(f"    reciprocal: {_claim(claims['reciprocal'])}{measured}   energy "
                   f"conserving: {_claim(claims['energy_conserving'])} (brdfkit check "
                   "computes both)")
        click.echo("    sampler: " + ("the file's own" if d["own_sampler"] else
                                      "tabulated from its values (cosine + half vector)"))
        if d["citation"]:
            click.echo(f"    cite: {d['citation']}")
        for note in d["notes"]:
            click.echo(f"    note: {note}")
        rows = [(*_param_row(p)[:3], p["kind"], p["doc"] or "") for p in d["params"]]
        for line in _param_table(rows, ("parameter", "default", "bounds", "kind", "meaning")):
            click.echo(line)
        click.echo("")


# --------------------------------------------------------------------------- eval
@click.command("eval")
@model_options
@click.option("--wi", required=True, metavar="THETA,PHI",
              help="Direction toward the light: polar angle from the normal and azimuth, "
                   "in DEGREES.")
@click.option("--wo", required=True, metavar="THETA,PHI",
              help="Direction toward the viewer: polar angle and azimuth, in DEGREES.")
@click.option("--json", "as_json", is_flag=True,
              help='Print {"model": ..., "params": {...}, "value": ...} (a list per channel).')
def eval_cmd(model: str, param: tuple[str, ...], compensate: str | None, pump: str | None,
             times: int, wi: str, wo: str, as_json: bool) -> None:
    """Evaluate the BRDF f_r(wi, wo) of MODEL in 1/sr (without the cosine factor).

    Example: brdfkit eval modified-phong -p rho_s=0.5 -p n=50 --wi 30,0 --wo 30,180

    THETA is the polar angle from the normal in [0, 180] degrees; above 90
    the direction is below the horizon and the BRDF is 0 there. PHI is the
    azimuth in degrees. 'beta' is given in degrees here.
    """
    m = build_model(model, param, pump=pump, times=times, compensate=compensate)
    vi = parse_direction(wi, "--wi")
    vo = parse_direction(wo, "--wo")
    value = m.eval(vi, vo)
    if as_json:
        d = m.to_dict()
        emit_json({"model": d["model"], "params": d["params"],
                   **{k: d[k] for k in ("compensate", "pump") if k in d}, "value": value})
        return
    v = value.tolist() if hasattr(value, "tolist") else value
    click.echo(" ".join(repr(float(x)) for x in v) if isinstance(v, list) else repr(float(v)))
