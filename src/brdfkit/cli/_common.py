"""Shared machinery of the ``brdfkit`` commands.

Every command that works on one model reuses these pieces so that models are
named, parameterised and reported the same way everywhere:

- :func:`model_options` — decorator adding the ``MODEL`` argument and the
  ``-p/--param NAME=VALUE``, ``--pump [max|controlled]`` and ``--times K``
  options.
- :func:`parse_param_items` — ``NAME=VALUE`` strings → keyword arguments
  (numbers, comma-separated per-channel/per-lobe lists, choice words; ``beta``
  in degrees → radians).
- :func:`build_model` — the model, optionally pumped (:mod:`brdfkit.pumping`).
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
from collections.abc import Callable, Iterable, Mapping

import click
import numpy as np

from brdfkit._io import to_jsonable
from brdfkit._specs import canonical_name, model_params
from brdfkit._specs import model as build_spec
from brdfkit.cli._group import EXIT_USAGE
from brdfkit.errors import BrdfkitError, ParameterError
from brdfkit.pumping import MAX_TIMES
from brdfkit.pumping import pump as pump_model

__all__ = [
    "EXIT_USAGE",
    "PUMP_MAX_TIMES",
    "THETA_MAX_DEG",
    "model_options",
    "parse_param_items",
    "build_model",
    "parse_direction",
    "to_jsonable",
    "emit_json",
]

#: Largest ``--times``: the library's bound (each pumping tabulates the previous stage's
#: albedo, so the cost grows with the number of stages; see ``brdfkit.pumping.MAX_TIMES``).
PUMP_MAX_TIMES = MAX_TIMES
_TIMES_REASON = ("each pumping tabulates the previous stage's albedo, so the cost grows with "
                 "the number of stages: times=8 takes about a minute")

#: Largest polar angle of a command-line direction, degrees. Above 90 the direction is
#: below the horizon and every BRDF is 0 there (the package convention); 180 is straight
#: down. Larger values would wrap around (390 = 30) and are refused instead.
THETA_MAX_DEG = 180.0

PARAM_HELP = (
    "Model parameter NAME=VALUE (repeatable). VALUE is a number, comma-separated "
    "numbers for per-channel colour or per-lobe parameters (e.g. rho_d=0.1,0.2,0.3), "
    "a word for choice parameters (e.g. distribution=ggx) or 'none' for optional ones. "
    "'beta' (lobe half-angle) is in DEGREES here (radians in the API). "
    "See 'brdfkit models' for each model's parameters."
)


# --------------------------------------------------------------------------- parameters


def _parse_number(text: str, name: str, model: str, bounds: str) -> float:
    try:
        return float(text)
    except ValueError:
        raise ParameterError(
            f"{model}: parameter {name!r} must be a number{bounds}; got {text!r}"
        ) from None


def parse_param_items(model_name: str, items: Iterable[str] | Mapping, *,
                      option: str = "-p") -> dict:
    """Convert ``NAME=VALUE`` strings to keyword arguments for model *model_name*.

    Parameters
    ----------
    model_name : str
        A registered name or alias, or a material spec (``merl:nickel``, a
        ``.binary`` path; raises :class:`~brdfkit.errors.UnknownModelError`).
    items : iterable of str, or mapping
        ``NAME=VALUE`` strings as typed on the command line. A mapping is
        taken as already parsed and returned as a dict (no unit conversion).
    option : str
        The command-line option the items came from, named in the error for a
        malformed item (``-p``, ``--start``).

    Returns
    -------
    dict
        Keyword arguments: floats, lists of floats (per channel/lobe), strings
        (choices) or None (``none`` for optional parameters); ``beta`` is
        converted from degrees to radians.

    Raises
    ------
    ParameterError
        Malformed item, repeated name or a value that is not a number.
    """
    label = canonical_name(model_name)
    if isinstance(items, Mapping):
        return dict(items)
    decls = {p.name: p for p in model_params(model_name)}
    out: dict = {}
    for item in items:
        name, sep, text = str(item).partition("=")
        name, text = name.strip(), text.strip()
        if not sep or not name or not text:
            raise ParameterError(
                f"parameter must be given as NAME=VALUE (e.g. {option} rho_d=0.5); got {item!r}"
            )
        if name in out:
            raise ParameterError(f"{label}: parameter {name!r} given twice")
        if name == "beta":
            deg = _parse_number(text, "beta", label, " of degrees in (0, 90)")
            if not 0.0 < deg < 90.0:
                raise ParameterError(
                    f"{label}: parameter 'beta' (half-angle, degrees on the command line) "
                    f"must lie in (0, 90); got {text}"
                )
            out[name] = math.radians(deg)
            continue
        p = decls.get(name)
        if p is None:
            out[name] = text  # the model names the unknown parameter and lists the valid ones
            continue
        bounds = f" in {p.bounds_text()}"
        if p.optional and text.lower() in ("none", "null"):
            out[name] = None
        elif p.kind == "choice":
            out[name] = text
        elif p.kind in ("colour", "lobes") and "," in text:
            out[name] = [_parse_number(t.strip(), name, label, bounds)
                         for t in text.split(",")]
        else:
            out[name] = _parse_number(text, name, label, bounds)
    return out


def _times_problem(times) -> str | None:
    """Why *times* is not a valid ``--times`` (without the option name), or None."""
    try:
        ok = not isinstance(times, bool) and int(times) == times and 1 <= times <= PUMP_MAX_TIMES
    except (TypeError, ValueError):  # not a number at all (e.g. a string through the API)
        ok = False
    if not ok:
        return (f"must be an integer from 1 to {PUMP_MAX_TIMES}; got {times} "
                f"({_TIMES_REASON})")
    return None


def build_model(name: str, params: Iterable[str] | Mapping = (), pump: str | None = None,
                times: int | None = None):
    """Build model *name* from command-line parameters, pumped if asked.

    Parameters
    ----------
    name : str
        Registered name or alias, or a material spec (``merl:nickel``,
        ``rgl:NAME``, ``nielsen:NAME``, a ``.binary`` path).
    params : iterable of ``NAME=VALUE`` str, or mapping
        See :func:`parse_param_items`.
    pump : {None, "max", "controlled"}
        Apply :func:`brdfkit.pumping.pump` with this g.
    times : int, optional
        How many times to pump, 1 … :data:`PUMP_MAX_TIMES` (default 1); only
        with *pump*.

    Raises
    ------
    BrdfkitError
        Unknown model, bad parameter, *times* out of range, or *times*
        given without *pump* (it would be silently ignored).
    """
    kwargs = parse_param_items(name, params)
    if pump is None and times is not None:
        raise BrdfkitError(f"--times {times} needs --pump max or --pump controlled (it says how "
                           "many times to pump); add --pump or drop --times")
    m = build_spec(name, **kwargs)
    if pump is None:
        return m
    times = 1 if times is None else times
    problem = _times_problem(times)
    if problem is not None:
        raise BrdfkitError(f"--times {problem}")
    return pump_model(m, g=pump, times=int(times))


def _times_callback(ctx: click.Context, param: click.Parameter, value):
    problem = None if value is None else _times_problem(value)
    if problem is not None:
        raise click.BadParameter(problem, ctx=ctx, param=param)
    return value


def model_options(func: Callable) -> Callable:
    """Decorator adding ``MODEL``, ``-p/--param``, ``--pump`` and ``--times`` to a command.

    The command receives ``model`` (str), ``param`` (tuple of str), ``pump``
    (str or None) and ``times`` (int, or None when not given); pass them to
    :func:`build_model`.
    """
    func = click.option("--times", type=int, default=None, callback=_times_callback,
                        metavar="K",
                        help=f"Apply the pumping K times (needs --pump; 1 to {PUMP_MAX_TIMES}, "
                             f"default 1; {_TIMES_REASON}).")(func)
    func = click.option("--pump", type=click.Choice(["max", "controlled"]), default=None,
                        help="Pump up the albedo (Neumann et al. 1999, eqs. 16-21) with "
                             "g1 ('max') or g2 ('controlled').")(func)
    func = click.option("-p", "--param", "param", multiple=True, metavar="NAME=VALUE",
                        help=PARAM_HELP)(func)
    func = click.argument("model", metavar="MODEL")(func)
    return func


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
