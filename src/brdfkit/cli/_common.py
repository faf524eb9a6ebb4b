"""Shared machinery of the ``brdfkit`` commands.

Every command that works on one model reuses these pieces so that models are
named, parameterised and reported the same way everywhere:

- :func:`model_options` — decorator adding the ``MODEL`` argument and the
  ``-p/--param NAME=VALUE``, ``--compensate METHOD``, ``--pump [max|controlled]``
  and ``--times K`` options.
- :func:`parse_param_items` — ``NAME=VALUE`` strings → keyword arguments
  (numbers, comma-separated per-channel/per-lobe lists, choice words; ``beta``
  in degrees → radians): :func:`brdfkit.spec.parse_items`.
- :func:`build_model` — the model, optionally compensated and pumped: a
  :class:`brdfkit.spec.ModelSpec` parsed from the words and built.
- :func:`parse_direction` — ``THETA,PHI`` in degrees → unit vector.
- :func:`emit_json` / :func:`to_jsonable` — JSON output (NumPy → lists,
  NaN/inf → null).
- :data:`PUMP_MAX_TIMES` — the largest ``--times``.

Errors are raised as :class:`~brdfkit.errors.BrdfkitError`; the group
(:mod:`brdfkit.cli._group`) prints them as one line, exit status 2.
"""

from __future__ import annotations

import json
import math
import os
import shlex
from collections.abc import Callable, Iterable, Mapping

import click
import numpy as np

from brdfkit._io import to_jsonable
from brdfkit.cli._group import EXIT_USAGE
from brdfkit.errors import BrdfkitError
from brdfkit.spec import (
    COMPENSATE_CHOICES,
    MAX_TIMES,
    PUMP_CHOICES,
    TIMES_REASON,
    ModelSpec,
    parse_items,
    times_problem,
)

__all__ = [
    "COMPENSATE_HELP",
    "EXIT_USAGE",
    "PUMP_MAX_TIMES",
    "THETA_MAX_DEG",
    "model_options",
    "model_word_options",
    "deprecated_alias",
    "model_entry",
    "parse_param_items",
    "build_model",
    "build_model_words",
    "split_model_words",
    "parse_direction",
    "to_jsonable",
    "emit_json",
]

#: Largest ``--times``: the library's bound (each pumping tabulates the previous stage's
#: albedo, so the cost grows with the number of stages; see ``brdfkit.pumping.MAX_TIMES``).
PUMP_MAX_TIMES = MAX_TIMES
_TIMES_REASON = TIMES_REASON

#: Largest polar angle of a command-line direction, degrees. Above 90 the direction is
#: below the horizon and every BRDF is 0 there (the package convention); 180 is straight
#: down. Larger values would wrap around (390 = 30) and are refused instead.
THETA_MAX_DEG = 180.0

#: How a parameter's VALUE is written (one statement, shared by -p and --start).
VALUE_HELP = (
    "VALUE is a number, comma-separated "
    "numbers for per-channel colour or per-lobe parameters (e.g. rho_d=0.1,0.2,0.3), "
    "a word for choice parameters (e.g. distribution=ggx) or 'none' for optional ones. "
    "'beta' (lobe half-angle) is in DEGREES here (radians in the API). "
    "See 'brdfkit models' for each model's parameters."
)
PARAM_HELP = "Model parameter NAME=VALUE (repeatable). " + VALUE_HELP


COMPENSATE_HELP = ("Compensate the energy lost to multiple scattering before any pumping: "
                   "'kulla-conty' (adds a reciprocal lobe) or 'turquin' (scales the lobe; "
                   "not reciprocal); docs/compensation.md.")


# --------------------------------------------------------------------------- parameters
def parse_param_items(model_name: str, items: Iterable[str] | Mapping, *,
                      option: str = "-p") -> dict:
    """``NAME=VALUE`` strings → keyword arguments for model *model_name*
    (:func:`brdfkit.spec.parse_items`: numbers, comma lists, choice words, ``none``;
    ``beta`` in degrees → radians; a mapping is returned as a dict)."""
    return parse_items(model_name, items, option=option)


def build_model(name: str, params: Iterable[str] | Mapping = (), pump: str | None = None,
                times: int | None = None, compensate: str | None = None):
    """Build model *name* from command-line parameters, compensated and pumped if asked: the
    :class:`~brdfkit.spec.ModelSpec` of the words (:meth:`~brdfkit.spec.ModelSpec.parse`),
    built.

    Raises
    ------
    BrdfkitError
        Unknown model, bad parameter, *times* out of range, or *times*
        given without *pump* (it would be silently ignored).
    """
    return ModelSpec.parse(name, params, pump=pump, times=times,
                           compensate=compensate).build()


#: The words a --compare SPEC may carry after its spec, as MODEL takes them.
_MODEL_WORDS = {"-p": "params", "--param": "params", "--pump": "pump", "--times": "times",
                "--compensate": "compensate"}


def build_model_words(text: str, *, option: str = "--compare"):
    """Build the model of one quoted option value written as a command line writes MODEL:
    ``'SPEC [-p NAME=VALUE]... [--compensate M] [--pump G [--times K]]'`` (shell quoting);
    a bare spec is the model at its defaults. Errors name *option* and the word."""
    return build_model(*split_model_words(text, option=option))


def model_entry(text: str, params=(), pump=None, times=None, compensate=None, *,
                option: str = "SPEC") -> dict:
    """The :class:`~brdfkit.spec.ModelSpec` dict form of *text* (a spec, or quoted model
    words as --compare takes them) with the further words given, checked (the model is
    built): ``{"model", "params", ["compensate"], ["pump"]}``."""
    spec, p, g, k, c = split_model_words(text, option=option)
    g, k, c = g or pump, k if k is not None else times, c or compensate
    built = ModelSpec.parse(spec, [*p, *params], pump=g, times=k, compensate=c)
    built.build()
    return built.to_dict()


def _times_callback(ctx: click.Context, param: click.Parameter, value):
    problem = None if value is None else times_problem(value)
    if problem is not None:
        raise click.BadParameter(problem, ctx=ctx, param=param)
    return value


def deprecated_alias(old: str, dest: str, instead: str, **kwargs) -> Callable:
    """A hidden option *old* kept for scripts written before the one vocabulary
    (docs/cli.md): it still works, stores into *dest*'s ``_old`` twin (the command merges
    it) and prints one line ``brdfkit: note: OLD is deprecated; INSTEAD`` on stderr."""
    def note(ctx, param, value):
        if value not in (None, (), False):
            click.echo(f"brdfkit: note: {old} is deprecated; {instead}", err=True)
        return value
    return click.option(old, dest, hidden=True, callback=note, expose_value=True,
                        **kwargs)


def model_word_options(func: Callable) -> Callable:
    """Decorator adding ``-p/--param``, ``--compensate``, ``--pump`` and ``--times`` (the
    words that describe a model) without the argument itself (:func:`model_options` adds
    it too)."""
    func = click.option("--times", type=int, default=None, callback=_times_callback,
                        metavar="K",
                        help=f"Apply the pumping K times (needs --pump; 1 to {PUMP_MAX_TIMES}, "
                             f"default 1; {_TIMES_REASON}).")(func)
    func = click.option("--pump", type=click.Choice(list(PUMP_CHOICES)), default=None,
                        help="Pump up the albedo (Neumann et al. 1999, eqs. 16-21) with "
                             "g1 ('max') or g2 ('controlled').")(func)
    func = click.option("--compensate", type=click.Choice(list(COMPENSATE_CHOICES)),
                        default=None, help=COMPENSATE_HELP)(func)
    func = click.option("-p", "--param", "param", multiple=True, metavar="NAME=VALUE",
                        help=PARAM_HELP)(func)
    return func


def model_options(func: Callable) -> Callable:
    """Decorator adding ``MODEL``, ``-p/--param``, ``--compensate``, ``--pump`` and
    ``--times`` to a command.

    The command receives ``model`` (str), ``param`` (tuple of str), ``compensate`` (str or
    None), ``pump`` (str or None) and ``times`` (int, or None when not given); pass them to
    :func:`build_model`.
    """
    func = model_word_options(func)
    func = click.argument("model", metavar="MODEL")(func)
    return func


def split_model_words(text: str, *, option: str = "--compare"):
    """``'SPEC [-p NAME=VALUE]... [--compensate M] [--pump G [--times K]]'`` → (spec,
    params, pump, times, compensate), as :func:`build_model_words` reads it."""
    if os.path.exists(str(text)):  # a file whose path has spaces is one spec
        return str(text), [], None, None, None
    try:
        words = shlex.split(str(text))
    except ValueError as exc:
        raise BrdfkitError(f"{option} {text!r}: {exc}") from None
    if not words:
        raise BrdfkitError(f"{option} needs a model spec (e.g. {option} 'nielsen -p k_s=5'); "
                           "got an empty value")
    target, params, ops = words[0], [], {}
    k = 1
    while k < len(words):
        key = _MODEL_WORDS.get(words[k])
        if key is None or k + 1 >= len(words):
            what = "has no value" if key is not None else "is not one of " + ", ".join(
                sorted(set(_MODEL_WORDS) - {"--param"}))
            raise BrdfkitError(f"{option} {text!r}: the word {words[k]!r} {what} (after the "
                               "spec: -p NAME=VALUE, --compensate M, --pump G, --times K)")
        if key == "params":
            params.append(words[k + 1])
        else:
            ops[key] = words[k + 1]
        k += 2
    times = ops.get("times")
    if times is not None:
        try:
            times = int(times)
        except ValueError:
            raise BrdfkitError(f"{option} {text!r}: --times must be a whole number; got "
                               f"{times!r}") from None
    return target, params, ops.get("pump"), times, ops.get("compensate")


# --------------------------------------------------------------------------- directions
def parse_direction(text: str, option: str = "--wi") -> np.ndarray:
    """``THETA,PHI`` in degrees → unit vector (3,) in the local frame (normal +z).

    THETA is the polar angle from the normal, in [0, :data:`THETA_MAX_DEG`]:
    above 90 the direction is below the horizon, where every BRDF is 0. PHI
    is the azimuth, any finite number of degrees (periodic).

    Raises
    ------
    BrdfkitError
        Not two numbers, THETA outside [0, 180], or a non-finite angle; the
        message names *option*, the allowed range and the value.
    """
    example = f"(e.g. {option} 30,0)"
    parts = str(text).split(",")
    try:
        if len(parts) != 2:
            raise ValueError
        theta, phi = (float(s) for s in parts)
    except ValueError:
        raise BrdfkitError(
            f"{option} must be THETA,PHI in degrees {example}; got {text!r}"
        ) from None
    if not 0.0 <= theta <= THETA_MAX_DEG:  # also refuses NaN
        raise BrdfkitError(
            f"{option} THETA,PHI: the polar angle THETA must lie in [0, {THETA_MAX_DEG:g}] "
            f"degrees (above 90 is below the horizon, where the BRDF is 0) {example}; "
            f"got THETA = {parts[0].strip()} in {text!r}")
    if not math.isfinite(phi):
        raise BrdfkitError(
            f"{option} THETA,PHI: the azimuth PHI must be a finite number of degrees "
            f"{example}; got PHI = {parts[1].strip()} in {text!r}")
    t, f = math.radians(theta), math.radians(phi)
    return np.array([math.sin(t) * math.cos(f), math.sin(t) * math.sin(f), math.cos(t)])


# --------------------------------------------------------------------------- JSON
def emit_json(obj, *, indent: int | None = 2) -> None:
    """Print *obj* as strict JSON on stdout (see :func:`to_jsonable`)."""
    click.echo(json.dumps(to_jsonable(obj), indent=indent, allow_nan=False))
