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

import json
import math

import click
import numpy as np

import brdfkit.cli._progress as _progress
from brdfkit.cli._common import COMPENSATE_HELP, VALUE_HELP, emit_json
from brdfkit.cli._group import OneLineError, Stopped, one_line
from brdfkit.errors import BrdfkitError
from brdfkit.fitting import LOSSES, PROCEDURES  # the registries' names (--loss, --procedure)
from brdfkit.fitting.batch import CONNECT_TIMEOUT_S
from brdfkit.spec import COMPENSATE_CHOICES, PUMP_CHOICES, ModelSpec, canonical_name, parse_items

__all__ = ["fit_cmd"]


@click.command("fit")
@click.argument("models", nargs=-1, required=True, metavar="MODEL...")
@click.option("-p", "--param", "param", multiple=True, metavar="NAME=VALUE",
              help="Hold parameter NAME of MODEL fixed at VALUE (repeatable; one MODEL "
                   "only). " + VALUE_HELP)
@click.option("--start", "start", multiple=True, metavar="NAME=VALUE",
              help="Start a parameter at VALUE and fit it (-p holds it instead); frees an "
                   "optional one that is off by default, e.g. --start eta=1.5 fits a "
                   "Fresnel index.")
@click.option("--compensate", type=click.Choice(list(COMPENSATE_CHOICES)), default=None,
              help="Fit the compensated model (its base parameters are fitted; one fit). "
                   + COMPENSATE_HELP)
@click.option("--pump", type=click.Choice(list(PUMP_CHOICES)), default=None,
              help="Fit the pumped model (its base parameters are fitted).")
@click.option("--times", type=int, default=None, metavar="K", help="Pump K times (with --pump).")
@click.option("--to", "to", required=True, multiple=True, metavar="SPEC",
              help="The material(s) to fit (repeatable): merl:NAME[@nbrdf|npf|abc|sgd], "
                   "rgl:NAME, nielsen:NAME, a MERL .binary path, or merl:all, rgl:all, "
                   "nielsen:all (every built-in material of the source).")
@click.option("--loss", type=click.Choice(list(LOSSES)),
              default="l1", show_default=True, help="The loss minimised (docs/fitting.md).")
@click.option("--procedure", type=click.Choice(list(PROCEDURES)),
              default="auto", show_default=True, help="The fitting procedure.")
@click.option("--seed", type=click.IntRange(min=0), default=0, show_default=True,
              help="Seed of the random starts, an integer >= 0.")
@click.option("--starts", type=click.IntRange(min=1), default=3, show_default=True,
              help="Runs of the shape stage (first guess, defaults, random).")
@click.option("--theta-max", "theta_max", type=click.FloatRange(0.0, 90.0, min_open=True),
              default=None, metavar="DEG", help="Keep pairs with theta_i, theta_o <= DEG.")
@click.option("--json", "as_json", is_flag=True, help="Print the result as JSON (one fit).")
@click.option("--plot", "plot", default=None, metavar="FILE",
              help="Write in-plane slices and albedo curves, measured vs fitted (.png/.svg; "
                   "one fit).")
@click.option("--out", "out", default=None, metavar="FILE.csv|FILE.parquet",
              help="Batch: every (MODEL, SPEC) fit as a row of FILE (.csv, or .parquet with "
                   "pyarrow), written atomically as each finishes; re-running resumes "
                   "(finished rows are skipped).")
@click.option("--workers", type=click.IntRange(1, 256), default=1, show_default=True,
              help="Batch: local worker processes (at most one per CPU and per fit: more "
                   "are capped, with a note).")
@click.option("--scheduler", default=None, metavar="ADDRESS",
              help="Batch: run on this Dask distributed scheduler (tcp://HOST:PORT) instead; "
                   f"it must answer within {CONNECT_TIMEOUT_S:g} s.")
def fit_cmd(models, param, start, compensate, pump, times, to, loss, procedure, seed, starts,
            theta_max, as_json, plot, out, workers, scheduler):
    """Fit MODEL's parameters to a measured material (-p NAME=VALUE holds a parameter,
    --start NAME=VALUE starts it there and fits it).

    Example: brdfkit fit nielsen --to merl:nickel --json
    (with a Fresnel factor, η fitted: brdfkit fit nielsen --to merl:nickel --start eta=1.5)

    Batch: several MODELs and/or materials, with --out FILE.csv, e.g.
    brdfkit fit modified-phong nielsen --to merl:all --out fits.csv --workers 2
    (--scheduler ADDRESS runs the same batch on a Dask cluster). A progress bar
    shows on a terminal; Ctrl-C keeps every finished row; re-run to resume. Exit
    status 1 when fits failed (their rows say why; a re-run retries them), 2 for bad
    input (an --out another batch is writing, a foreign file, an unreachable scheduler).
    """
    from brdfkit.fitting.batch import expand_targets

    targets = expand_targets(to)
    if out is not None or len(models) > 1 or len(targets) > 1:
        if compensate is not None:
            raise BrdfkitError("--compensate is for one fit (one MODEL, one SPEC); a batch does "
                               "not take it")
        _batch(models, targets, param=param, start=start, pump=pump, times=times, loss=loss,
               procedure=procedure, seed=seed, theta_max=theta_max, as_json=as_json,
               plot=plot, out=out, workers=workers, scheduler=scheduler)
        return
    if workers != 1 or scheduler is not None:
        raise BrdfkitError("--workers and --scheduler are for batches: add --out FILE.csv")
    model, to = models[0], targets[0]
    import brdfkit.data
    from brdfkit.fitting import fit

    if plot:  # matplotlib is imported only for a plot (~0.4 s of a one-line fit)
        from brdfkit.figures import check_output_path, save_atomic

        check_output_path(plot, option="--plot")  # fail before the fit, not after
    held = parse_items(model, param)
    started = parse_items(model, start, option="--start")
    both = sorted(set(held) & set(started))
    if both:
        raise BrdfkitError(f"{', '.join(both)}: given with both -p (held) and --start (fitted); "
                           "use one")
    spec = ModelSpec.parse(model, {**started, **held}, pump=pump, times=times,
                           compensate=compensate)
    m = spec.build()
    # a held beta (half-angle) is held as the width parameter the spec resolved it into
    width = next(iter(set(spec.params) - set(started) - set(held)), None)
    fixed = {k: m.values[k] for k in (width if k == "beta" else k for k in held)}
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
    off = [p for p in m.params if p.default is None and d["params"].get(p.name) is None]
    for p in off:  # an optional factor left out is said, with how to fit it
        click.echo(f"# {p.name} unset, so not fitted ({p.doc}); --start {p.name}=VALUE fits it")
    click.echo("# metrics: " + ", ".join(f"{k}={v:.6g}" for k, v in r.metrics.items()))
    click.echo(_albedo_line(r))
    c = r.convergence
    click.echo(f"# {c['evaluations']} model evaluations in {c['time_s']:.2f} s, "
               f"{len(c['starts'])} starts, {c['n_samples']} samples")
    fixed_args = " ".join(f"-p {k}={','.join(f'{x:.6g}' for x in v) if isinstance(v, list) else v}"
                          for k, v in d["params"].items() if v is not None)
    click.echo(f"# as a model: brdfkit eval {d['model']} {fixed_args}")


#: Incidence angles (degrees) of the text output's albedo line.
ALBEDO_LINE_DEG = (0.0, 30.0, 60.0, 75.0, 85.0)


def _albedo_line(r) -> str:
    """'# albedo model/target: 0: 0.2/0.19, ...' (the channels' mean) at ALBEDO_LINE_DEG."""
    th = list(np.asarray(r.theta_deg, dtype=float))
    a_m = np.asarray(r.albedo_model).reshape(len(th), -1).mean(axis=1)
    a_t = np.asarray(r.albedo_target).reshape(len(th), -1).mean(axis=1)
    parts = [f"{t:g}: {a_m[th.index(t)]:.3g}/{a_t[th.index(t)]:.3g}"
             for t in ALBEDO_LINE_DEG if t in th]
    return "# albedo model/target (mean of the channels) at theta_i deg: " + ", ".join(parts)


def _batch(models, targets, *, param, start, pump, times, loss, procedure, seed, theta_max, as_json,
           plot, out, workers, scheduler) -> None:
    """``brdfkit fit MODEL... --to SPEC... --out FILE.csv``: one row per fit."""
    from brdfkit.fitting.batch import BatchInterrupted, Job, fit_row, run_batch

    if out is None:
        raise BrdfkitError(f"{len(models)} model(s) x {len(targets)} material(s) is a batch: "
                           "add --out FILE.csv (each finished fit is written as it completes)")
    if param:
        raise BrdfkitError("-p holds parameters of one fit; a batch fits every parameter (drop "
                           "-p, or fit one MODEL to one SPEC)")
    if as_json or plot:
        raise BrdfkitError("--json and --plot describe one fit; a batch writes --out FILE.csv")
    if times is not None and pump is None:
        raise BrdfkitError(f"--times {times} needs --pump max or --pump controlled")
    for m in models:
        canonical_name(m)  # an unknown model fails now, not in every row
    starts = {}
    for m in models if start else ():  # starting values; every model must take them
        starts = parse_items(m, start, option="--start")
        if "beta" in starts:
            raise BrdfkitError("--start beta=...: a batch takes the models' own parameter "
                               "names (the width parameter, not beta)")
    options = tuple(sorted({"seed": seed, **({"pump": pump, "times": times or 1} if pump else {}),
                            **({"params": json.dumps(starts, sort_keys=True)} if starts else {}),
                            **({"theta_max_deg": theta_max} if theta_max else {})}.items()))
    jobs = [Job(m, t, loss=loss, procedure=procedure, options=options)
            for m in models for t in targets]
    show = _progress.stderr_is_interactive()
    try:
        with _progress.counter("fit", enabled=show) as progress:
            report = run_batch(jobs, out=out, run_job=fit_row, workers=workers,
                               scheduler=scheduler, progress=progress, notice=_note)
    except BatchInterrupted as exc:  # Ctrl-C: one 'brdfkit: interrupted: ...' line, status 130
        raise Stopped.interrupted(str(exc).removeprefix("interrupted: ")) from None
    nc = f"{report.not_converged} not converged, " if report.not_converged else ""
    click.echo(f"{report.out}: {report.done} fitted now, {report.skipped} already there, "
               f"{nc}{report.failed} failed, of {report.total} ({report.seconds:.1f} s)")
    if report.failed:
        raise BatchFailed(_failed_message(report))


#: Exit status of a batch that ran to its end with failed rows (bad input is 2, as for
#: every command; a signal 128 + its number).
EXIT_BATCH_FAILED = 1
#: Failed rows whose reasons the error line quotes (the file has them all).
_SHOWN_FAILURES = 3
#: Characters of each quoted reason.
_REASON_CHARS = 160


class BatchFailed(OneLineError):
    """A batch with failed rows: one line ``brdfkit: error: N of M fits failed ...``,
    exit status :data:`EXIT_BATCH_FAILED`."""

    exit_code = EXIT_BATCH_FAILED


def _failed_message(report) -> str:
    reasons = "; ".join(one_line(f)[:_REASON_CHARS] for f in report.failures[:_SHOWN_FAILURES])
    more = (f"; and {report.failed - _SHOWN_FAILURES} more"
            if report.failed > _SHOWN_FAILURES else "")
    return (f"{report.failed} of {report.total} fits failed ({reasons}{more}); every "
            f"message is in the status and message columns of {report.out}; re-run the "
            "same command to retry the failed ones")


def _note(message: str) -> None:
    """What the batch changed on its own (workers capped, invalid rows), one line on stderr."""
    click.echo(f"brdfkit: note: {one_line(message)}", err=True)
