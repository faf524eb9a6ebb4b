"""
The operators a model spec applies
==================================

:data:`OPERATORS` (key → :class:`OperatorKind`) is the registry that
:class:`brdfkit.spec.ModelSpec` reads: how each operator's dict form is read,
checked, applied and written back. Each operator's module is imported on first use,
not with the package (``import brdfkit``, every command's start, does not pay for the
albedo engine):

- ``pump`` — :func:`brdfkit.pumping.pump` with ``g`` (``max``, ``controlled``) and
  ``times`` (1 … ``MAX_TIMES``): ``"pump": {"g": G, "times": K}``, a list of those, or
  the flat ``"pump": G`` with ``"times": K`` beside it;
- ``compensate`` — :func:`brdfkit.compensation.compensate` with ``method``
  (``kulla-conty``, ``turquin``): ``"compensate": {"method": M}`` or the flat
  ``"compensate": M``.

``None``/``"none"`` as an operator's value: not applied. ``docs/architecture.md``,
"Model spec", says how to add an operator.

Public objects
--------------
- :class:`OperatorKind`, :data:`OPERATORS`.
- :func:`times_problem` — why a number of pumpings is invalid, or None.
- :data:`TIMES_REASON`.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass

from brdfkit.errors import ParameterError
from brdfkit.models import BRDF

__all__ = ["OPERATORS", "OperatorKind", "TIMES_REASON", "times_problem"]


# brdfkit.pumping is imported on first use, not with the package (`import brdfkit`, every
# command's start, does not pay ~7 ms for it); so are PUMP_CHOICES (its G_CHOICES) and MAX_TIMES.
def _pumping():
    import brdfkit.pumping
    return brdfkit.pumping


def _compensation():  # as _pumping: imported on first use
    import brdfkit.compensation
    return brdfkit.compensation


#: Why the number of pumpings is bounded (:data:`MAX_TIMES`), for messages and help.
TIMES_REASON = ("each pumping tabulates the previous stage's albedo, so the cost grows with "
                "the number of stages: times=4 takes 1-2.5 minutes on 2 cores")


def times_problem(times) -> str | None:
    """Why *times* is not a valid number of pumpings (without the option name), or None."""
    try:
        top = _pumping().MAX_TIMES
        ok = not isinstance(times, bool) and int(times) == times and 1 <= times <= top
    except (TypeError, ValueError):  # not a number at all (e.g. a string through the API)
        ok = False
    if not ok:
        return (f"must be an integer from 1 to {_pumping().MAX_TIMES}; got {times} "
                f"({TIMES_REASON})")
    return None


@dataclass(frozen=True)
class OperatorKind:
    """One operator a spec can apply: ``key``, its name and dict key; ``stages(value, d)``,
    the dict form's value (*d*: the whole dict, for flat siblings) → one argument mapping
    per operator; ``check(args)``, validated and canonical; ``apply(model, args)``;
    ``value(stages)``, the dict form's value; ``flat``, the flat form's sibling keys."""

    key: str
    stages: Callable[[object, Mapping], list]
    check: Callable[[Mapping], dict]
    apply: Callable[[BRDF, dict], BRDF]
    value: Callable[[list], object]
    flat: tuple = ()


def _none(value) -> bool:
    return value is None or (isinstance(value, str) and value.strip().lower() in ("", "none"))


# --------------------------------------------------------------------------- pump
def _pump_stages(value, d: Mapping) -> list:
    if _none(value):
        return []  # a flat "times" without a pump is the page's unused field: not read
    if isinstance(value, str):
        times = d.get("times")
        return [{"g": value, "times": 1 if times is None else times}]
    if isinstance(value, Mapping):
        return [value]
    if isinstance(value, list | tuple) and all(isinstance(s, Mapping) for s in value):
        return list(value)
    raise ParameterError(f"pump must be 'max', 'controlled', none, {{'g': G, 'times': K}} or "
                         f"a list of those; got {value!r}")


def _pump_check(args: Mapping) -> dict:
    unknown = sorted(set(args) - {"g", "times"})
    if unknown:
        raise ParameterError(f"pump: unknown argument {unknown[0]!r}; valid: g, times")
    g = args.get("g", "max")
    if g == "custom":
        raise ParameterError("from_dict: a custom g cannot be rebuilt from a dict")
    if g not in _pumping().G_CHOICES:
        raise ParameterError(f"pump must be 'max', 'controlled' or none; got {g!r}")
    times = args.get("times", 1)
    problem = times_problem(times)
    if problem is not None:
        raise ParameterError(f"times {problem}")
    return {"g": g, "times": int(times)}


def _one_or_list(stages: list) -> object:
    return stages[0] if len(stages) == 1 else stages


# --------------------------------------------------------------------------- compensate
def _compensate_stages(value, d: Mapping) -> list:
    if _none(value):
        return []
    if isinstance(value, str):
        return [{"method": value}]
    if isinstance(value, Mapping):
        return [value]
    raise ParameterError("compensate must be a method name ("
                         + ", ".join(_compensation().METHODS)
                         + f"), none or {{'method': M}}; got {value!r}")


def _compensate_check(args: Mapping) -> dict:
    unknown = sorted(set(args) - {"method"})
    if unknown:
        raise ParameterError(f"compensate: unknown argument {unknown[0]!r}; valid: method")
    return {"method": _compensation().compensation_method(
        args.get("method", "kulla-conty")).key}


#: The operators a spec applies, by key (in the dict form, applied in the order of the keys).
OPERATORS: dict[str, OperatorKind] = {
    "pump": OperatorKind("pump", _pump_stages, _pump_check,
                         lambda m, a: _pumping().pump(m, a["g"], times=a["times"]), _one_or_list,
                         flat=("times",)),
    "compensate": OperatorKind(
        "compensate", _compensate_stages, _compensate_check,
        lambda m, a: _compensation().compensate(m, a["method"]), _one_or_list),
}
