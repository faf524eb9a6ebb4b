"""
The Dr.Jit side of every table read (the Mitsuba bridge's traced route)
=======================================================================

One design serves every model whose formulas read data packed into its row past
its parameters (``Formulas(tables=K)``): a pumped or Turquin-compensated model's
albedo lookups, ``phong-energy-conserving``'s H_s, NPF's 1-D factors, a MERL table
of 1,458,000 bins per channel. On the traced route
(:mod:`brdfkit.render.mitsuba_traced`) such a row is a :class:`TableRow`: the K
parameter columns as a tuple (floats, colours), carrying a :class:`TracedTables`
that holds the packed rows as one Dr.Jit array, read by the formula primitives of
:mod:`brdfkit.tables`:

====================  ===============================  ===============================
primitive             Numba                            Dr.Jit (here)
====================  ===============================  ===============================
``lookup(p, o, μ)``   ``_lookup`` (two-level cubic)    :func:`lookup_drjit`: the same
``lookup_w(p, o, μ)`` ``_lookup_w`` (uniform in √μ)    cells and Horner, ``dr.gather``
``row_at(p, i)``      ``p[int(i)]`` (a computed bin)   :meth:`TracedTables.gather`
``row_from(p, n)``    ``p[n:]`` (a view)               the tail, tables shifted
====================  ===============================  ===============================

The array is channel-interleaved (column j of channel c at C·j + c), so that the
channels of one column share a cache line (a MERL bin's three values: one memory
access); channels whose tables are all equal share one row (C = 1). Offsets, cell
and interval counts are read in Python (:meth:`TracedTables.column`: compile-time
constants of the trace); headers, cubics and bins by ``dr.gather``. A new kind of
table read is a primitive in :mod:`brdfkit.tables` and its factory here (design
record: ``docs/architecture.md``, "Tables in the trace").

A low layer: NumPy only (Dr.Jit arrives as the argument of the factories).

Public objects
--------------
- :class:`TracedTables`, :class:`TableRow` — the data.
- :func:`lookup_drjit`, :func:`lookup_w_drjit`, :func:`row_at_drjit`,
  :func:`row_from_drjit` — the primitives' Dr.Jit factories (registered by
  :mod:`brdfkit.tables`).
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

__all__ = ["TableRow", "TracedTables", "lookup_drjit", "lookup_w_drjit", "row_at_drjit",
           "row_from_drjit"]


class TracedTables:
    """A model's packed rows, for the Dr.Jit reads of the table primitives (module
    docstring); the tables are the columns from *start* on.

    The rows (C, W) are held once as one Dr.Jit array of *float_type*, channel-interleaved
    (column j of channel c at C·j + c); channels whose table columns are all equal (NaN
    equal to NaN: a measured table's unmeasured bins) share one row. *combine* turns the
    per-channel values of a read into the row's colour type (``mi.Color3f`` for three
    channels; one value is returned as it is).
    """

    def __init__(self, rows: np.ndarray, start: int, float_type, combine: Callable):
        rows = np.atleast_2d(np.asarray(rows, dtype=np.float64))
        tail = rows[:, start:]
        if np.array_equal(tail, np.broadcast_to(tail[:1], tail.shape), equal_nan=True):
            rows = rows[:1]  # one table for every channel
        self.rows = rows
        self.start = int(start)
        self.shift = 0  # the row's columns before the formula's column 0 (row_from)
        self.width = rows.shape[1]
        self.channels = rows.shape[0]
        self.float_type = float_type
        self.data = float_type(np.ascontiguousarray(rows.T, dtype=np.float32).reshape(-1))
        self.combine = combine

    def read(self, dr, column, c: int):
        """Channel *c*'s value at *column* (an int or an unsigned Dr.Jit index array, the
        stored row's column: :meth:`offset` applied) by ``dr.gather``, unmasked."""
        if self.channels == 1:
            return dr.gather(self.float_type, self.data, column)
        return dr.gather(self.float_type, self.data, column * self.channels + c)

    def gather(self, dr, i):
        """The table at the formula's column *i* (a Float holding an integer, a computed
        bin: :func:`brdfkit.tables.row_at`), every channel combined. An index outside the
        tables' columns (a NaN from a discarded lane of a select included) reads 0 and
        never leaves the array (``dr.gather``'s mask)."""
        j = i + float(self.shift) if self.shift else i
        ok = (j >= float(self.start)) & (j < float(self.width))  # NaN: False
        index = dr.uint32_array_t(self.float_type)
        col = index(dr.select(ok, j, 0.0))
        if self.channels > 1:
            col = col * self.channels
        return self.combine([dr.gather(self.float_type, self.data, col + c, ok)
                             for c in range(self.channels)])

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


def row_at_drjit(dr):
    def row_at_(p, i):
        """:func:`brdfkit.tables.row_at`: the tables gathered at column *i*."""
        return p.tables.gather(dr, i)
    return row_at_


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


def _cubic_drjit(dr, tabs: TracedTables, b, ch: int, t):
    """The cubic whose 4 coefficients start at column *b* of channel *ch*, at *t*."""
    c = [tabs.read(dr, b + i, ch) for i in range(4)]
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
            m = int(tabs.rows[c, o])  # cells: a constant of the trace
            j = dr.minimum(index(mu * m), m - 1)  # mu = 1: the last cell
            h = o + 1 + 4 * j
            anchor, inv_h, first, last = (tabs.read(dr, h + i, c) for i in range(4))
            y = dr.maximum((mu - anchor) * inv_h, 0.0)  # >= 0 (float32 rounding of the anchor)
            k = dr.minimum(index(y), index(last))  # the cell's last node
            out.append(_cubic_drjit(dr, tabs, o + index(first) + 4 * k, c,
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
            out.append(_cubic_drjit(dr, tabs, o + 4 + 4 * j, c, x - tabs.float_type(j)))
        return tabs.combine(out)
    return lookup_w_
