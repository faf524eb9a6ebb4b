"""``brdfkit fit``: fit a model to a measured material.

- ``brdfkit fit MODEL --to SPEC [-p NAME=VALUE …] [--pump max --times K] [--loss …]
  [--procedure …] [--seed N] [--starts N] [--theta-max DEG] [--json] [--plot FILE]``

``-p`` values are *held fixed* (every other parameter is fitted). The JSON is
``{"model", "params", "metrics", "albedo", "convergence", …}``
(:meth:`brdfkit.fitting.FitResult.to_dict`), so the fitted ``params`` can be
passed back as ``-p``. SPEC is resolved by :func:`brdfkit.data.material`
(``merl:NAME[@rep]``, ``rgl:NAME``, ``nielsen:NAME``, a ``.binary`` path).
"""

from __future__ import annotations

import math

import click

from brdfkit.cli._common import emit_json, model_options, parse_param_items
from brdfkit.errors import BrdfkitError

__all__ = ["fit_cmd"]


@click.command("fit")
@model_options
@click.option("--to", "to", required=True, metavar="SPEC",
              help="The material to fit: merl:NAME[@nbrdf|npf|abc|sgd], rgl:NAME, "
                   "nielsen:NAME or a MERL .binary path.")
@click.option("--loss", type=click.Choice(["l1", "l2", "ngan", "log", "perceptual"]),
              default="l1", show_default=True, help="The loss minimised (docs/fitting.md).")
@click.option("--procedure", type=click.Choice(["auto", "staged", "nielsen", "direct"]),
              default="auto", show_default=True, help="The fitting procedure.")
@click.option("--seed", type=int, default=0, show_default=True, help="Seed of random starts.")
@click.option("--starts", type=click.IntRange(min=1), default=3, show_default=True,
              help="Runs of the shape stage (first guess, defaults, random).")
@click.option("--theta-max", "theta_max", type=click.FloatRange(0.0, 90.0, min_open=True),
              default=None, metavar="DEG", help="Keep pairs with theta_i, theta_o <= DEG.")
@click.option("--json", "as_json", is_flag=True, help="Print the result as JSON.")
@click.option("--plot", "plot", default=None, metavar="FILE",
              help="Write in-plane slices and albedo curves, measured vs fitted (.png/.svg).")
def fit_cmd(model, param, pump, times, to, loss, procedure, seed, starts, theta_max, as_json,
            plot):
    """Fit MODEL's parameters to a measured material (-p NAME=VALUE holds a parameter).

    Example: brdfkit fit nielsen --to merl:nickel --json
    """
    import brdfkit.data
    from brdfkit.cli._common import build_model
    from brdfkit.figures import check_output_path, save_atomic
    from brdfkit.fitting import fit

    if plot:
        check_output_path(plot, option="--plot")  # fail before the fit, not after
    m = build_model(model, param, pump=pump, times=times)
    given = parse_param_items(model, param)
    if "beta" in given:
        if m.width_param is None:
            raise BrdfkitError(f"{model}: has no lobe width, so 'beta' is not a parameter")
        given[m.width_param] = m.values[m.width_param]
        del given["beta"]
    fixed = {k: m.values[k] for k in given}
    target = brdfkit.data.material(to)
    r = fit(m, target, loss=loss, procedure=procedure, fixed=fixed, seed=seed, n_starts=starts,
            theta_max=None if theta_max is None else math.radians(theta_max))
    if plot:
        from brdfkit.figures.fitting import fit_figure

        save_atomic(fit_figure(r, target), plot, option="--plot")
    if as_json:
        emit_json(r.to_dict())
        return
    d = r.to_dict()
    click.echo(f"# {d['model']} fitted to {to} ({loss}, {r.convergence['procedure']}): "
               f"{r.message}")
    for k, v in d["params"].items():
        click.echo(f"{k:>10s} = {v}")
    click.echo("# metrics: " + ", ".join(f"{k}={v:.6g}" for k, v in r.metrics.items()))
    c = r.convergence
    click.echo(f"# {c['evaluations']} model evaluations in {c['time_s']:.2f} s, "
               f"{len(c['starts'])} starts, {c['n_samples']} samples")
    fixed_args = " ".join(f"-p {k}={','.join(f'{x:.6g}' for x in v) if isinstance(v, list) else v}"
                          for k, v in d["params"].items() if v is not None)
    click.echo(f"# as a model: brdfkit eval {d['model']} {fixed_args}")
