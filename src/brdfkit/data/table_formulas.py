"""
Primitives of the measured materials' formulas
==============================================

The formula contract (:mod:`brdfkit._dual`) reads a packed row ``p`` by constant
index only (``p[3]``). A measured material's formula reads its *tables* (NPF's 1-D
factors, a MERL table of 1,458,000 bins per channel) at an index computed from the
directions: :func:`brdfkit.tables.row_at` (re-exported here), one of the table
primitives that every table-reading model shares; the model declares where its
tables start with ``Formulas(tables=K)``, and the traced route gathers them
(:mod:`brdfkit.traced_tables`, the one design for tables in the trace).

Public objects
--------------
- :func:`row_at` — :func:`brdfkit.tables.row_at` (Numba ``p[int(i)]``; Dr.Jit a gather).
- :func:`expm1` — ``exp(x) − 1``, a primitive (Numba ``math.expm1``; Dr.Jit Kahan's
  form, accurate near 0).

References
----------
- W. Kahan, as given by N. J. Higham, *Accuracy and Stability of Numerical
  Algorithms*, 2nd ed., SIAM 2002, §1.14.1 (expm1 as (u − 1)·x/log u, u = eˣ).
"""

from __future__ import annotations

import math

import numba

from brdfkit._dual import primitive
from brdfkit.tables import row_at

__all__ = ["row_at", "expm1"]


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
