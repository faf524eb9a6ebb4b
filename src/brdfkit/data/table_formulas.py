"""
Formulas that read a model's packed row at a computed index
===========================================================

The formula contract (:mod:`brdfkit._dual`) reads a packed row ``p`` by constant
index only (``p[3]``): in Numba ``p`` is a float64 array, in the Mitsuba bridge's
traced route a tuple of per-column values. A measured material's formula reads
its *tables* (NPF's 1-D factors, a MERL table of 1,458,000 bins per channel) at an
index computed from the directions; :func:`row_at` is that read, a primitive:

==============  ====================================  =================================
name            Numba                                 Dr.Jit
==============  ====================================  =================================
row_at(p, i)    ``p[int(i)]`` (*i* a float holding     ``p.gather(i)``: the traced row's
                an exact integer)                     table as one ``mi.Float`` array,
                                                      read with ``dr.gather``
==============  ====================================  =================================

A model whose formula calls :func:`row_at` returns :class:`TableFormulas`: the
:class:`~brdfkit._dual.Formulas` plus ``table = (start, stop)``, the columns of the
packed row that are read only through :func:`row_at` (between them the constant
columns stay ordinary). The traced route (:mod:`brdfkit.render.mitsuba_rows`)
turns those columns into one Dr.Jit array, once per BSDF, instead of one Python
value per column (a MERL row has 1,458,001 columns), and passes a row object whose
``[k]`` is column *k* for a constant *k* and whose ``gather(i)`` reads the table.

Public objects
--------------
- :func:`row_at` — the primitive (Numba function; Dr.Jit: the row's ``gather``).
- :class:`TableFormulas` — :class:`~brdfkit._dual.Formulas` with the table's columns.
- :func:`expm1` — ``exp(x) − 1``, a primitive (Numba ``math.expm1``; Dr.Jit Kahan's
  form, accurate near 0).

References
----------
- W. Kahan, as given by N. J. Higham, *Accuracy and Stability of Numerical
  Algorithms*, 2nd ed., SIAM 2002, §1.14.1 (expm1 as (u − 1)·x/log u, u = eˣ).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numba

from brdfkit._dual import Formulas, primitive

__all__ = ["row_at", "TableFormulas", "expm1"]


@numba.njit(cache=True, inline="always")
def row_at(p, i):
    """``p[i]`` for a float *i* holding an exact integer index (a formula's computed bin)."""
    return p[int(i)]


def _row_at_drjit(dr):
    def row_at_(p, i):
        return p.gather(i)  # the traced route's row (brdfkit.render.mitsuba_rows)
    return row_at_


primitive(row_at, _row_at_drjit)


@numba.njit(cache=True, inline="always")
def expm1(x):
    """exp(x) − 1, accurate near 0."""
    return math.expm1(x)


def _expm1_drjit(dr):
    def expm1_(x):
        u = dr.exp(x)
        # Kahan: (u − 1)·x/log u is accurate where u rounds; u = 1: x; u = inf: inf
        # (x/log u = 1 there: the select keeps inf·1 rather than inf/inf)
        d = dr.log(u)
        ok = (u != 1.0) & (d < math.inf)
        return dr.select(ok, (u - 1.0) * (x / dr.select(ok, d, 1.0)),
                         dr.select(u == 1.0, x, u - 1.0))
    return expm1_


primitive(expm1, _expm1_drjit)


@dataclass(frozen=True)
class TableFormulas(Formulas):
    """:class:`~brdfkit._dual.Formulas` of a model that reads the packed row's columns
    ``table = (start, stop)`` through :func:`row_at` (module docstring)."""

    table: tuple | None = None
