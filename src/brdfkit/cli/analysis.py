"""
Analysis commands: ``albedo``, ``check``, ``table2``, ``figure``
================================================================

- ``brdfkit albedo MODEL -p ... [--theta 0:89.9:90] [--phi DEG] [--json|--csv] [--plot FILE]``
- ``brdfkit check MODEL -p ... [--phi DEG] [--json]`` — reciprocity and energy verdicts.
- ``brdfkit table2 [--json | --markdown]`` — Lewis's Table 2 for every model.
- ``brdfkit figure NAME --out FILE`` — a paper figure (PNG or SVG);
  ``brdfkit figure list`` — the names.

Angles are in degrees on the command line. ``--phi`` is the incidence azimuth
(:func:`parse_phi`, default 0): an anisotropic model's albedo depends on it, and its
JSON (``phi_deg``) and CSV (a ``phi_deg`` column) record it; an isotropic model's
numbers do not depend on it, its output is unchanged at 0 and, given another value, the
text output says in one line that it has no effect (the JSON then records ``phi_deg``).
Files are written atomically
(temp file + ``os.replace``). Plain click commands; :mod:`brdfkit.cli` adds
them to the ``brdfkit`` group.
"""

from __future__ import annotations

import click
import numpy as np

import brdfkit.cli._progress as _progress
from brdfkit.cli._common import (
    build_model,
    build_model_words,
    deprecated_alias,
    emit_json,
    model_options,
    model_word_options,
    split_model_words,
)
from brdfkit.errors import BrdfkitError
from brdfkit.spec import ModelSpec

__all__ = ["MAX_ANGLES", "parse_theta", "parse_phi", "albedo_cmd", "check_cmd", "table2_cmd",
           "figure_cmd"]

#: Largest number of --theta angles. Each angle is an adaptive quadrature (milliseconds
#: to seconds), so 100 000 is already hours of work and megabytes of output; the cap turns
#: a typo such as 0:89:1000000000000 into an error instead of a memory error.
MAX_ANGLES = 100_000

_THETA_FORMS = ("--theta must be START:STOP:COUNT (COUNT angles, inclusive, like "
                "numpy.linspace) or a comma-separated list, in degrees (e.g. 0:89.9:90 or "
                "0,30,60)")


def _compensated(d: dict) -> str:
    """The text outputs' note of a compensation (none when the model has none)."""
    return f"  compensated ({d['compensate']['method']})" if "compensate" in d else ""


def parse_theta(text: str) -> np.ndarray:
    """``START:STOP:COUNT`` (inclusive, like numpy.linspace) or ``a,b,c`` in degrees → degrees.

    Raises
    ------
    BrdfkitError
        Malformed spec, an empty list item (``0,,30``), COUNT < 1 or more than
        :data:`MAX_ANGLES` angles, or an angle outside [0, 90) degrees.
    """
    s = str(text).strip()
    if ":" in s:
        parts = s.split(":")
        try:
            if len(parts) != 3:
                raise ValueError
            start, stop, count = float(parts[0]), float(parts[1]), int(parts[2])
        except ValueError:
            raise BrdfkitError(f"{_THETA_FORMS}; got {text!r}") from None
        if not 1 <= count <= MAX_ANGLES:
            raise BrdfkitError(f"--theta COUNT must be from 1 to {MAX_ANGLES} angles; got "
                               f"{count} in {text!r}")
        out = np.linspace(start, stop, count)
    else:
        items = [x.strip() for x in s.split(",")]
        if any(x == "" for x in items):
            raise BrdfkitError(f"{_THETA_FORMS}; got an empty item in {text!r}")
        if len(items) > MAX_ANGLES:
            raise BrdfkitError(f"--theta may list at most {MAX_ANGLES} angles; got {len(items)}")
        try:
            out = np.array([float(x) for x in items])
        except ValueError:
            raise BrdfkitError(f"{_THETA_FORMS}; got {text!r}") from None
    if not np.all(np.isfinite(out)) or np.any((out < 0.0) | (out >= 90.0)):
        bad = out[~((out >= 0.0) & (out < 90.0))]
        raise BrdfkitError(f"--theta angles must lie in [0, 90) degrees; got {bad.flat[0]:g}")
    return out


def parse_phi(text: str) -> float:
    """``--phi DEG``: the incidence azimuth, any finite number of degrees → degrees.

    Raises
    ------
    BrdfkitError
        Not a number, or not finite (nan, inf).
    """
    try:
        value = float(str(text).strip())
    except ValueError:
        value = None
    if value is None or not np.isfinite(value):
        raise BrdfkitError(f"--phi must be a finite number of degrees (the incidence azimuth, "
                           f"any finite value, e.g. --phi 45); got {text!r}")
    return value


_PHI_HELP = ("Incidence azimuth in DEGREES (any finite value; default 0: the light in the "
             "xz-plane). Only an anisotropic model depends on it.")


def _phi_note(m, phi_deg: float) -> str | None:
    """The one line of text output saying that --phi has no effect on an isotropic model."""
    if m.isotropic and phi_deg != 0.0:
        return (f"--phi {phi_deg:g} has no effect: {m.name} is isotropic (its albedo does "
                "not depend on the incidence azimuth)")
    return None


@click.command("albedo")
@model_options
@click.option("--theta", default="0:89.9:90", show_default=True, metavar="SPEC",
              help="Incidence angles in DEGREES, each in [0, 90): START:STOP:COUNT "
                   f"(inclusive) or a comma-separated list; at most {MAX_ANGLES} angles.")
@click.option("--phi", "phi", default="0", metavar="DEG", help=_PHI_HELP)
@click.option("--tol", type=float, default=1e-7, show_default=True,
              help="Absolute accuracy goal of the quadrature.")
@click.option("--json", "as_json", is_flag=True,
              help='Print {"model", "params", "theta_deg", "albedo", "error"} (and "phi_deg" '
                   'for an anisotropic model or a --phi other than 0).')
@click.option("--csv", "as_csv", is_flag=True,
              help="Print CSV: theta_deg, albedo(s), error(s) (a phi_deg column after "
                   "theta_deg for an anisotropic model or a --phi other than 0).")
@click.option("--plot", "plot", default=None, metavar="FILE",
              help="Also write a plot of a(theta_i) to FILE (.png or .svg; the directory "
                   "must exist): a dense curve (every degree, to 1e-5) with the --theta "
                   "angles marked, R/G/B in red/green/blue, the line a = 1.")
def albedo_cmd(model, param, compensate, pump, times, theta, phi, tol, as_json, as_csv, plot):
    """Directional albedo a(theta_i) = int f_r cos(theta_o) dw_o of MODEL, with error estimates.

    Deterministic lobe-aware quadrature to the --tol goal (1e-7 absolute by default); each
    angle's error estimate is printed beside it. Example:
    brdfkit albedo modified-phong -p n=5000 --theta 0:89:90 --json
    """
    from brdfkit.analysis import albedo
    from brdfkit.figures import check_output_path

    if as_json and as_csv:
        raise BrdfkitError("give at most one of --json and --csv")
    phi_deg = parse_phi(phi)
    th = parse_theta(theta)
    if plot:
        check_output_path(plot, option="--plot")  # fail before the quadrature, not after
    with _progress.working(f"albedo of {model}", as_json=as_json):
        m = build_model(model, param, pump=pump, times=times, compensate=compensate)
        r = albedo(m, np.radians(th), phi=np.radians(phi_deg), tol=tol)
    d = m.to_dict()
    a = np.asarray(r.albedo)
    e = np.asarray(r.error)
    # the azimuth is recorded where it matters or was asked for (isotropic output at 0 as
    # it always was)
    with_phi = not m.isotropic or phi_deg != 0.0
    if plot:
        _plot_albedo(m, th, a, plot, phi_deg if with_phi else None)
    # an angle that did not converge (e.g. NaN in the integrand) says so: the result's
    # status and message, present only then (the output of converged runs is unchanged)
    unconverged = {k: v for k, v in r.to_dict().items() if k in ("status", "message")}
    if as_json:
        emit_json({"model": d["model"], "params": d["params"],
                   **{k: d[k] for k in ("compensate", "pump") if k in d},
                   "theta_deg": th, **({"phi_deg": phi_deg} if with_phi else {}),
                   "albedo": a, "error": e, **unconverged})
        return
    if unconverged:
        click.echo(f"brdfkit: warning: {unconverged['message']}", err=True)
    coloured = a.ndim == 2
    if as_csv:
        if coloured:
            cols = [f"albedo_{c}" for c in range(a.shape[1])] + \
                   [f"error_{c}" for c in range(a.shape[1])]
        else:
            cols = ["albedo", "error"]
        click.echo(",".join(["theta_deg", *(["phi_deg"] if with_phi else []), *cols]))
        for k in range(th.size):
            vals = (list(a[k]) + list(e[k])) if coloured else [a[k], e[k]]
            click.echo(",".join([f"{th[k]:.10g}", *([f"{phi_deg:.10g}"] if with_phi else [])]
                                + [f"{v:.12g}" for v in vals]))
        return
    click.echo(f"# {d['model']} {d['params']}{_compensated(d)}")
    note = _phi_note(m, phi_deg)
    if note:
        click.echo(f"# note: {note}")
    click.echo("# theta_deg  albedo  (error estimate)"
               + (f"  at phi = {phi_deg:g} deg" if not m.isotropic else ""))
    for k in range(th.size):
        if coloured:
            vals = "  ".join(f"{v:.9f}" for v in a[k])
            click.echo(f"{th[k]:10.4f}  {vals}  ({float(np.max(e[k])):.1e})")
        else:
            click.echo(f"{th[k]:10.4f}  {a[k]:.9f}  ({e[k]:.1e})")


def _plot_albedo(m, th, a, path, phi_deg=None):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from brdfkit.figures import save_atomic
    from brdfkit.figures.albedo import albedo_figure

    fig = albedo_figure(m, th, a, phi_deg=phi_deg)
    try:
        save_atomic(fig, path, option="--plot")
    finally:
        plt.close(fig)


@click.command("check")
@model_options
@click.option("--phi", "phi", default="0", metavar="DEG",
              help=_PHI_HELP + " Sets the azimuth of the energy verdict; the reciprocity "
                   "pairs of an anisotropic model cover several azimuths whatever it is.")
@click.option("--tol", type=float, default=1e-7, show_default=True,
              help="Absolute accuracy goal of the albedo quadrature behind the energy verdict "
                   "(as albedo --tol); a verdict its accuracy cannot support is 'undetermined'.")
@click.option("--json", "as_json", is_flag=True,
              help='Print {"model", "params", "reciprocal", "max_asymmetry", "energy", '
                   '"max_albedo", "theta_max_deg", "divergence_exponent", "max_scale", '
                   '"notes", ...}.')
def check_cmd(model, param, compensate, pump, times, phi, tol, as_json):
    """Plausibility verdict of MODEL: reciprocity, energy conservation, objections.

    energy is 'conserves' (max albedo <= 1), 'exceeds' (bounded; max_scale is
    the largest factor that makes it conserve) or 'diverges' (a ~ cos(theta_i)^-p
    as theta_i -> 90 deg, p decided from 89, 89.9, 89.99, 89.999 deg).
    """
    from brdfkit.analysis import check

    phi_deg = parse_phi(phi)
    with _progress.working(f"checking {model}", as_json=as_json):
        m = build_model(model, param, pump=pump, times=times, compensate=compensate)
        v = check(m, phi=np.radians(phi_deg), tol=tol)
    d = v.to_dict()
    if as_json:
        emit_json(d)
        return
    click.echo(f"model:        {d['model']}  {d['params']}{_compensated(d)}")
    if not m.isotropic:
        click.echo(f"azimuth:      phi = {phi_deg:g} deg (anisotropic: the energy verdict is "
                   "at this incidence azimuth)")
    note = _phi_note(m, phi_deg)
    if note:
        click.echo(f"note:         {note}")
    recip = {"reciprocal": "yes", "not reciprocal": "no"}.get(d["reciprocity"],
                                                                d["reciprocity"] or "no")
    click.echo(f"reciprocal:   {recip} "
               f"(max relative asymmetry {d['max_asymmetry']:.3g})")
    energy = d["energy"]
    if energy == "diverges":
        energy += f" at grazing incidence, a ~ (cos theta_i)^-{d['divergence_exponent']:g}"
    elif energy == "exceeds":
        energy += f" 1 (bounded); conserves when scaled by <= {d['max_scale']:.6g}"
    click.echo(f"energy:       {energy}")
    click.echo(f"max albedo:   {d['max_albedo']:.6g} at {d['theta_max_deg']:g} deg")
    graz = ", ".join(f"{k}: {v:.4g}" for k, v in d["grazing_albedo"].items())
    click.echo(f"grazing:      {graz}")
    for n in d["notes"]:
        click.echo(f"note:         {n}")


@click.command("table2")
@click.option("--json", "as_json", is_flag=True, help="Print the rows as JSON.")
@click.option("--markdown", "as_md", is_flag=True, help="Print a Markdown table.")
@click.argument("models", nargs=-1, metavar="[MODEL]...")
@deprecated_alias("--model", "models_old", "give the models as arguments: brdfkit table2 "
                  "MODEL...", multiple=True)
def table2_cmd(as_json, as_md, models, models_old):
    """Lewis (1993) Table 2 regenerated by computation, extended to every registered model.

    For each model: computed reciprocity and energy verdict (conserves /
    exceeds with the scale that fixes it / diverges with its rate), the
    maximum albedo, the paper's claim where Lewis's Table 2 or Neumann et al.
    make one, whether they agree, and notes with the reasons.

    MODEL... (default: every registered model) are rows of their own: a model name,
    a material (merl:nickel, rgl:NAME, nielsen:NAME, a .binary file), a .py or .brdf
    model file, or a model with its words, quoted, e.g. 'nielsen -p k_s=5 --pump max'
    (as --compare takes it).
    """
    from brdfkit.analysis.lewis_table2 import format_markdown, format_table, table2

    if as_json and as_md:
        raise BrdfkitError("give at most one of --json and --markdown")
    show = not as_json and _progress.stderr_is_interactive()
    with _progress.counter("table2", enabled=show) as progress:
        # registered names by name (their rows carry the paper's claims); materials and
        # user files built
        rows = table2(models=[_table2_row(n) for n in (*models_old, *models)] or None,
                      progress=progress)
    if as_json:
        emit_json(rows)
    elif as_md:  # the legend too (a Markdown paragraph above the table)
        click.echo(TABLE2_LEGEND + "\n")
        click.echo(format_markdown(rows))
    else:
        click.echo(TABLE2_LEGEND + "\n")
        click.echo(format_table(rows))


def _table2_row(text: str):
    """A registered name by name (its row carries the paper's claims); anything else (a
    material, a file, a model with its words) built."""
    spec, params, pump, times, compensate = split_model_words(text, option="MODEL")
    if not (params or pump or times is not None or compensate) and \
            ModelSpec(spec).kind == "model":
        return spec
    return build_model(spec, params, pump=pump, times=times, compensate=compensate)


#: What table2's columns mean, printed above the plain and the Markdown table.
TABLE2_LEGEND = ("Lewis 1993 Table 2, regenerated by computation (energy: conserves = max "
                 "albedo <= 1; exceeds (xs) = bounded, conserves when scaled by s; diverges "
                 "p = a ~ cos(theta_i)^-p; paper E/R = Lewis's 'conserves energy?' / "
                 "'reciprocal?')")


@click.command("figure")
@click.argument("name", metavar="NAME")
@click.argument("model", required=False, metavar="[MODEL]")
@click.option("--out", "out", default=None, metavar="FILE",
              help="Output file (.png or .svg; the directory must exist). Required to build a "
                   "figure; not used by 'figure list'.")
@click.option("--dpi", type=click.IntRange(min=30, max=1200), default=150, show_default=True,
              help="Resolution of PNG output, 30 to 1200.")
@deprecated_alias("--model", "model_old", "give the model after the figure's name: "
                  "brdfkit figure slices MODEL ...")
@model_word_options
@click.option("--compare", multiple=True, metavar="'SPEC [-p NAME=VALUE]...'",
              help="Further models drawn next to MODEL (repeatable; up to 3): a spec with "
                   "its own -p, --compensate, --pump, --times words, quoted, e.g. --compare "
                   "'nielsen -p k_s=5 -p s=200'; a bare spec is at its defaults.")
@click.option("--spp", type=click.IntRange(min=1, max=4096), default=None, metavar="N",
              help="Monte-Carlo figures (neumann-fig8): samples per pixel (default 16, not "
                   "render's 64: the figure is 12 renders; with --panel-size S, S x 0.75 S x N "
                   "at most 2^30). Cost: 12 renders of S x 0.75 S x N "
                   "paths of up to 6 bounces (Mitsuba traces ~0.26 M single-bounce samples/s "
                   "on 2 cores); memory stays under ~2 GB.")
@click.option("--panel-size", "panel_size", type=click.IntRange(min=16, max=2048), default=None,
              metavar="S",
              help="Figures of rendered panels: width of each panel in pixels (neumann-fig8: "
                   "S x 0.75 S panels, default 320; nielsen-fig1: S x S spheres, default "
                   "160).")
@deprecated_alias("--size", "size_old", "use --panel-size (the width of each panel; --size is "
                  "an image's side in render sphere)", type=click.IntRange(min=16, max=2048))
@click.option("--seed", type=click.IntRange(min=0), default=None, metavar="K",
              help="Monte-Carlo figures (neumann-fig8): the sampler's seed, 0 to 2^32 - 1 "
                   "(Mitsuba's seeds are 32-bit; default 0).")
def figure_cmd(name, model, out, dpi, model_old, param, compensate, pump, times, compare, spp,
               panel_size, size_old, seed):
    """Reproduce a paper figure by computation and write it to FILE (PNG or SVG).

    NAME is one of the registered figures (e.g. lewis-fig3 ... lewis-fig10,
    neumann-fig1 ... neumann-fig7); 'brdfkit figure list' prints them.
    'slices' draws in-plane slices and the albedo of MODEL (and --compare
    models; -p, --compensate, --pump, --times describe MODEL), e.g.
    brdfkit figure slices merl:nickel --compare merl:nickel@abc --out n.png

    Building takes seconds to a minute (neumann-fig8, a Monte-Carlo render
    through Mitsuba, a few minutes: --spp and --panel-size trade time for noise
    and resolution); when stderr is a terminal a 'building ...' line (or
    a progress bar) shows it is working.
    """
    from brdfkit.figures import (
        FIGURE_OPTIONS,
        MODEL_FIGURES,
        check_output_path,
        figure_names,
        resolve_figure,
        save_figure,
    )

    if name == "list":
        if out is not None:
            raise BrdfkitError(f"'figure list' only prints the names and writes no file; "
                               f"drop --out {out}")
        click.echo("\n".join(figure_names()))
        return
    key = resolve_figure(name)  # an unknown name is told before a missing --out
    if out is None:
        raise BrdfkitError(f"figure {key} needs --out FILE (.png or .svg), e.g. "
                           f"brdfkit figure {key} --out {key}.png")
    if model is not None and model_old is not None:
        raise BrdfkitError(f"give the model once: {model} (the argument) or --model "
                           f"{model_old}, not both")
    model = model if model is not None else model_old
    size = panel_size if panel_size is not None else size_old
    check_output_path(out, option="--out")
    if model is None and (param or compensate or pump or times is not None or compare):
        raise BrdfkitError("-p, --compensate, --pump, --times and --compare describe MODEL; "
                           f"give it after the figure's name (brdfkit figure {name} MODEL; "
                           "figures that take one: " + ", ".join(MODEL_FIGURES) + ")")
    if key in MODEL_FIGURES and model is None:
        raise BrdfkitError(f"figure {key} draws a given model: give it after the name (e.g. "
                           f"brdfkit figure {key} merl:nickel --out {key}.png)")
    models = () if model is None else (build_model(model, param, pump=pump, times=times,
                                                   compensate=compensate),
                                       *(build_model_words(s, option="--compare")
                                         for s in compare))
    options = {k: v for k, v in (("spp", spp), ("size", size), ("seed", seed)) if v is not None}
    own_bar = key in FIGURE_OPTIONS  # the Monte-Carlo figures draw their own progress bar
    with _progress.status(f"building {key}",
                          enabled=_progress.stderr_is_interactive() and not own_bar):
        save_figure(key, out, dpi=dpi, option="--out", models=models, options=options)
    click.echo(out)
