"""
Parameter values from words: the command line's ``NAME=VALUE`` and flat properties
==================================================================================

The one reading of a parameter value written as text, for :mod:`brdfkit.spec` (which
re-exports :func:`parse_items` and :func:`property_value` under its own names):
numbers; comma-separated numbers for per-channel colour or per-lobe parameters;
words for choice and bool parameters (validated by the model); ``none`` for optional
ones; ``beta`` in degrees, converted to radians.

Public objects
--------------
- :func:`parse_words` — ``NAME=VALUE`` words → values, for a model's declarations.
- :func:`property_value` — a flat property's value (a comma list as numbers).
"""

from __future__ import annotations

import math
from collections.abc import Iterable

from brdfkit.errors import ParameterError

__all__ = ["parse_words", "property_value"]


def _parse_number(text: str, name: str, label: str, bounds: str) -> float:
    try:
        return float(text)
    except ValueError:
        raise ParameterError(
            f"{label}: parameter {name!r} must be a number{bounds}; got {text!r}") from None


def parse_words(label: str, params, items: Iterable[str], *, option: str = "-p") -> dict:
    """``NAME=VALUE`` words (as typed after *option*) → values for the model *label*
    whose declarations (:class:`~brdfkit.models.Param`) are *params*
    (:func:`brdfkit.spec.parse_items` says what each form means)."""
    decls = {p.name: p for p in params}
    out: dict = {}
    for item in items:
        key, sep, text = str(item).partition("=")
        key, text = key.strip(), text.strip()
        if not sep or not key or not text:
            raise ParameterError(
                f"parameter must be given as NAME=VALUE (e.g. {option} rho_d=0.5); got {item!r}")
        if key in out:
            raise ParameterError(f"{label}: parameter {key!r} given twice")
        if key == "beta":
            deg = _parse_number(text, "beta", label, " of degrees in (0, 90)")
            if not 0.0 < deg < 90.0:
                raise ParameterError(
                    f"{label}: parameter 'beta' (half-angle, degrees on the command line) "
                    f"must lie in (0, 90); got {text}")
            out[key] = math.radians(deg)
            continue
        p = decls.get(key)
        if p is None:
            out[key] = text
            continue
        bounds = f" in {p.bounds_text()}"
        if p.optional and text.lower() in ("none", "null"):
            out[key] = None
        elif p.kind in ("choice", "bool"):
            out[key] = text  # a word: the model's validation reads it (Param.validate)
        elif p.kind in ("colour", "lobes") and "," in text:
            out[key] = [_parse_number(t.strip(), key, label, bounds) for t in text.split(",")]
        else:
            out[key] = _parse_number(text, key, label, bounds)
    return out


def property_value(key: str, value, *, where: str):
    """A flat property's value: a string with commas as a list of numbers, else as given."""
    if not (isinstance(value, str) and "," in value):
        return value
    try:
        return [float(x) for x in value.split(",")]
    except ValueError:
        raise ParameterError(f"{where}: property {key!r} must be a number, a word or a "
                             f"comma-separated list of numbers; got {value!r}") from None
