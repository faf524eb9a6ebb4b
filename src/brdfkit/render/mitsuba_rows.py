"""
A packed row with a table, for the traced route
===============================================

The traced BSDF (:mod:`brdfkit.render.mitsuba_traced`) passes a model's packed
row to its formula as a tuple of per-column values: a Python float where every
channel has the same value, a ``Color3f`` where they differ. A model whose
formulas are :class:`~brdfkit.data.table_formulas.TableFormulas` reads the
columns ``table = (start, stop)`` at computed indices
(:func:`~brdfkit.data.table_formulas.row_at`); :class:`TracedRow` holds those
columns as one Dr.Jit array (built once per BSDF) and reads them with
``dr.gather``:

- every channel equal over the table: one ``Float`` of ``stop − start`` values,
  a gather gives a ``Float``;
- else channel-interleaved, ``C·(stop − start)`` values (column *j*, channel *c*
  at ``C·j + c``), a gather gives a ``Color3f`` of the three channels (RGB and
  mono variants: the traced class's colour handling applies, as to the other
  columns).

An index outside ``[start, stop)`` (a NaN from a discarded lane of a
:func:`~brdfkit._dual.select` included) reads 0 and never leaves the array
(``dr.gather``'s mask). Column *k* outside the table is ``row[k]``, as in the
tuple.

Public objects
--------------
- :class:`TracedRow` — the row object (``row[k]``, ``row.gather(i)``).
- :func:`traced_row` — a model's packed rows as a :class:`TracedRow`.
"""

from __future__ import annotations

import numpy as np

__all__ = ["TracedRow", "traced_row"]


class TracedRow:
    """A packed row for the traced route: constant columns and one gathered table."""

    def __init__(self, mi, dr, columns: list, start: int, table, n_channels: int):
        self._mi, self._dr = mi, dr
        self._columns = columns  # None at the table's columns
        self._start = start
        self._table = table
        self._n = n_channels
        self._size = dr.width(table) // n_channels

    def __getitem__(self, k):
        value = self._columns[k]
        if value is None:
            raise IndexError(f"column {k} is in the table (read it with row_at)")
        return value

    def __len__(self) -> int:
        return len(self._columns)

    def gather(self, i):
        """The table at column *i* (a Float holding an integer): Float or Color3f."""
        mi, dr = self._mi, self._dr
        j = i - float(self._start)
        ok = (j >= 0.0) & (j < float(self._size))  # NaN: False
        idx = mi.UInt32(dr.select(ok, j, 0.0))
        if self._n == 1:
            return dr.gather(mi.Float, self._table, idx, ok)
        # one gather of the three consecutive channels of column j (a packet read)
        return dr.gather(mi.Color3f, self._table, idx, ok)


def traced_row(mi, dr, packed: np.ndarray, table: tuple) -> TracedRow:
    """*packed* (C, K) as a :class:`TracedRow` whose columns ``table = (start, stop)`` are
    one Dr.Jit array (module docstring); the other columns a float (every channel equal)
    or a ``Color3f`` (C = 3)."""
    rows = np.atleast_2d(np.asarray(packed, dtype=np.float64))
    start, stop = int(table[0]), int(table[1])
    columns: list = []
    for k in range(rows.shape[1]):
        if start <= k < stop:
            columns.append(None)
            continue
        c = rows[:, k]
        columns.append(float(c[0]) if np.all(c == c[0]) else mi.Color3f(*c.tolist()))
    block = rows[:, start:stop]
    same = bool(np.array_equal(block, np.broadcast_to(block[:1], block.shape), equal_nan=True))
    n = 1 if same or rows.shape[0] == 1 else rows.shape[0]
    flat = block[0] if n == 1 else np.ascontiguousarray(block.T).reshape(-1)
    return TracedRow(mi, dr, columns, start, mi.Float(flat.astype(np.float32)), n)
