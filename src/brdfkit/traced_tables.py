"""
The Dr.Jit side of the table reads (the Mitsuba bridge's traced route)
======================================================================

A model's formulas read tables packed into its row with the primitives
:func:`brdfkit.tables.lookup` / :func:`~brdfkit.tables.lookup_w`; on the traced
route (:mod:`brdfkit.render.mitsuba_traced`) the row is a :class:`TableRow`: the
parameter columns as a tuple (floats, colours), carrying a :class:`TracedTables` that
holds the packed rows from the tables' column on as one Dr.Jit array. The reads here
are the same cubic reads as the compiled :func:`brdfkit.tables._lookup` and
``_lookup_w``, with ``dr.gather`` (design record: ``docs/architecture.md``, "Tables in
the trace").

A low layer: NumPy only (Dr.Jit arrives as the argument of the factories).

Public objects
--------------
- :class:`TracedTables`, :class:`TableRow` — the data.
- :func:`lookup_drjit`, :func:`lookup_w_drjit`, :func:`row_from_drjit` — the
  primitives' Dr.Jit factories (registered by :mod:`brdfkit.tables`).
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

__all__ = ["TableRow", "TracedTables", "lookup_drjit", "lookup_w_drjit", "row_from_drjit"]


class TracedTables:
    """A model's packed rows from column *start* on, for the Dr.Jit reads of :func:`lookup`.

    The rows (C, W) are held once as one Dr.Jit array of *float_type* (channel c's row at
    c·W); channels whose table columns are all equal share one row. *combine* turns the
    per-channel values of a read into the row's colour type (``mi.Color3f`` for three
    channels; one value is returned as it is). The offsets, cell counts and interval counts
    of the tables are read in Python (compile-time constants of the trace); the headers
    and cubics by ``dr.gather``.
    """

    def __init__(self, rows: np.ndarray, start: int, float_type, combine: Callable):
        rows = np.atleast_2d(np.asarray(rows, dtype=np.float64))
        if np.all(rows[:, start:] == rows[:1, start:]):
            rows = rows[:1]  # one table for every channel
        self.rows = rows
        self.start = int(start)
        self.shift = 0  # the row's columns before the formula's column 0 (row_from)
        self.width = rows.shape[1]
        self.channels = rows.shape[0]
        self.float_type = float_type
        self.data = float_type(np.ascontiguousarray(rows.reshape(-1), dtype=np.float32))
        self.combine = combine

    def shifted(self, n: int) -> TracedTables:
        """The same tables for the row from column *n* on (:func:`row_from_drjit`)."""
        out = object.__new__(TracedTables)
        out.__dict__.update(self.__dict__)
        out.shift = self.shift + int(n)
        return out

    def column(self, i: int):
        """Column *i* (negative: from the end) of every channel: a float when they agree,
        else a tuple of the channels' values (an offset a lookup reads per channel)."""
        col = self.rows[:, i if i < 0 else self.shift + i]
        return float(col[0]) if np.all(col == col[0]) else tuple(float(x) for x in col)

    def offset(self, off, c: int) -> int:
        """Channel *c*'s table offset in its stored row from *off* (a number, or a tuple of
        them per channel), the formula's column."""
        return self.shift + int(off[c] if isinstance(off, tuple) else off)


class TableRow(tuple):
    """The row a traced formula receives (:mod:`brdfkit.render.mitsuba_traced`): its
    parameters (columns before the tables' start, floats or colours) as a tuple, and
    ``tables`` (:class:`TracedTables`) for :func:`lookup`; an index from the tables' start
    on, or negative (a trailer), reads :meth:`TracedTables.column`."""

    def __new__(cls, params, tables: TracedTables):
        row = super().__new__(cls, params)
        row.tables = tables
        return row

    def __getitem__(self, i):
        if isinstance(i, int) and not 0 <= i < len(self):
            return self.tables.column(i)
        return tuple.__getitem__(self, i)


def row_from_drjit(dr):
    def row_from_(p, n):
        """The row from column *n* on; a :class:`TableRow` keeps its tables (shifted)."""
        if isinstance(p, TableRow):
            return TableRow(tuple.__getitem__(p, slice(n, None)), p.tables.shifted(n))
        return tuple(p)[n:]
    return row_from_


def _unit_drjit(dr, mu):
    """μ clamped to [0, 1], NaN to 0 (as :func:`brdfkit._kern.clamp_unit`)."""
    return dr.select(mu >= 0.0, dr.minimum(mu, 1.0), 0.0)


def _cubic_drjit(dr, tabs: TracedTables, b, t):
    """The cubic whose 4 coefficients start at index *b* of ``tabs.data``, at *t*."""
    c = [dr.gather(tabs.float_type, tabs.data, b + i) for i in range(4)]
    return ((c[0] * t + c[1]) * t + c[2]) * t + c[3]


def lookup_drjit(dr):
    def lookup_(p, off, mu):
        """:func:`brdfkit.tables._lookup` per channel with gathers (same cells, cubics)."""
        tabs = p.tables
        index = dr.uint32_array_t(tabs.float_type)
        mu = _unit_drjit(dr, mu)
        out = []
        for c in range(tabs.channels):
            o = tabs.offset(off, c)
            base = c * tabs.width + o
            m = int(tabs.rows[c, o])  # cells: a constant of the trace
            j = dr.minimum(index(mu * m), m - 1)  # mu = 1: the last cell
            h = base + 1 + 4 * j
            anchor, inv_h, first, last = (dr.gather(tabs.float_type, tabs.data, h + i)
                                          for i in range(4))
            y = dr.maximum((mu - anchor) * inv_h, 0.0)  # >= 0 (float32 rounding of the anchor)
            k = dr.minimum(index(y), index(last))  # the cell's last node
            out.append(_cubic_drjit(dr, tabs, base + index(first) + 4 * k,
                                    y - tabs.float_type(k)))
        return tabs.combine(out)
    return lookup_


def lookup_w_drjit(dr):
    def lookup_w_(p, off, mu):
        """:func:`brdfkit.tables._lookup_w` per channel with gathers."""
        tabs = p.tables
        index = dr.uint32_array_t(tabs.float_type)
        w = dr.sqrt(_unit_drjit(dr, mu))
        out = []
        for c in range(tabs.channels):
            o = tabs.offset(off, c)
            w0, inv_h, n, w_min = (float(v) for v in tabs.rows[c, o:o + 4])
            x = dr.maximum((dr.maximum(w, w_min) - w0) * inv_h, 0.0)  # held below w_min
            j = dr.minimum(index(x), int(n) - 1)  # w = 1: the last interval
            out.append(_cubic_drjit(dr, tabs, c * tabs.width + o + 4 + 4 * j,
                                    x - tabs.float_type(j)))
        return tabs.combine(out)
    return lookup_w_
