"""
A tabulated material on the MERL grid as a brdfkit model
========================================================

:class:`MeasuredBRDF` turns a :class:`~brdfkit.data.merl.MerlTable` (the
format, read and written exactly by :mod:`brdfkit.data.merl`) into a model:
its kernel and compiled lookups (``nearest``: the reference reader's bin;
``linear``: trilinear between bin centres; the index arithmetic is in
:mod:`brdfkit.data._merl_index`, the lookup rules in :mod:`brdfkit.data.merl`'s
docstring), found in blocks whose bins are computed first and then read
(random reads of the 35 MB table overlap), its lobe width and azimuthal
symmetry read from the table, and a sampler tabulated from its values.

Public objects
--------------
- :class:`MeasuredBRDF` — a tabulated material as a brdfkit model.
"""

from __future__ import annotations

import math
import os

import numba
import numpy as np

from brdfkit.data._merl_index import (
    _NQ,
    _half_diff,
    _index_tables,
    _linear,
    _nearest_index,
    _table_driver,
)
from brdfkit.data.merl import N_BINS, SHAPE, MerlTable, bin_centres
from brdfkit.data.merl_formulas import measured_formulas
from brdfkit.data.sampler import TabulatedSampler
from brdfkit.errors import ParameterError
from brdfkit.models._base import DerivedBRDF, Lobe, Param

__all__ = ["MeasuredBRDF"]



#: Offset of the table in a packed row: [lookup mode, table …].
_TABLE = 1
NEAREST, LINEAR = 0, 1


@numba.njit(cache=True)
def _measured_kernel(ix, iy, iz, ox, oy, oz, p):
    if iz <= 0.0 or oz <= 0.0:
        return 0.0
    theta_h, theta_d, phi_d = _half_diff(ix, iy, iz, ox, oy, oz)
    if p[0] == LINEAR:
        return _linear(p, 1, _TABLE, theta_h, theta_d, phi_d)
    return p[_TABLE + _nearest_index(theta_h, theta_d, phi_d)]


def _width_from_table(values: np.ndarray) -> float:
    """Half-width (rad, in θ_h) of the tabulated peak: where the luminance-like mean over
    channels, φ_d and θ_d < 10°, minus its floor, falls to half its value at θ_h = 0."""
    th, _, _ = bin_centres()
    v = np.where(np.isfinite(values), values, np.nan)
    prof = np.nanmean(v[:, :, :10, :], axis=(0, 2, 3))
    if not np.any(np.isfinite(prof)):
        return 0.5 * math.pi
    prof = np.nan_to_num(prof, nan=0.0)
    floor = float(np.min(prof))
    peak = float(prof[0]) - floor
    if peak <= 0.0:
        return 0.5 * math.pi
    below = np.nonzero(prof - floor < 0.5 * peak)[0]
    if below.size == 0:
        return 0.5 * math.pi
    return float(max(th[below[0]], th[0]))


@numba.njit(cache=True)
def _mirror_symmetric_kernel(v):  # pragma: no cover - compiled
    for c in range(v.shape[0]):
        for i in range(v.shape[1]):
            for j in range(v.shape[2]):
                for p in range(90):
                    a = v[c, i, j, p]
                    b = v[c, i, j, 179 - p]
                    if a != a or b != b:  # NaN: unmeasured; must be so in both
                        if not (a != a and b != b):
                            return False
                    elif abs(a - b) > 1e-9 * max(abs(a), abs(b)):
                        return False
    return True


def _mirror_symmetric(values: np.ndarray) -> bool:
    """Whether the table is even in the relative azimuth: f(ω_i, ω_o) = f(ω_i', ω_o') for
    the pair mirrored in the plane of incidence. The mirror maps φ_d to −φ_d, which the
    lookup folds to π − φ_d: bin i_φd ↔ 179 − i_φd (nearest) and bin centre ↔ bin centre
    (linear). Compared to 1e-9 relative — the rounding of a tabulated symmetric function,
    far below any measurement's noise; unmeasured bins (NaN) must be unmeasured in both.
    A compiled loop that stops at the first asymmetric pair of bins."""
    return bool(_mirror_symmetric_kernel(np.ascontiguousarray(values).reshape(3, 90, 90, 180)))


class MeasuredBRDF(TabulatedSampler, DerivedBRDF):
    """A tabulated material on the MERL grid as a brdfkit model.

    ======  ========  ===============  ========================================
    name    default   choices          meaning
    ======  ========  ===============  ========================================
    lookup  nearest   nearest, linear  ``nearest``: the reference reader's bin
                                       (values agree with every MERL tool);
                                       ``linear``: trilinear between bin
                                       centres (continuous: fitting, rendering)
    ======  ========  ===============  ========================================

    Unmeasured bins (negative in the file) are NaN in the model's table:
    ``eval`` returns NaN where a ``nearest`` lookup lands on one (there is no
    measurement there — never 0, never a clamp), ``linear`` interpolates over
    the measured neighbours and is NaN only where all eight are unmeasured.
    Analyses report NaN values (the albedo engine's status NONFINITE).

    Albedo on tabulated data: the ``nearest`` table is piecewise constant with
    jumps on the bin boundaries, which the adaptive quadrature cannot resolve
    to 1e-7 — results carry status MAX_LEVEL_REACHED and an error estimate of
    the jumps' size; use ``linear`` for albedos (continuous; converges to the
    interpolant's albedo).

    Reciprocal by construction (the φ_d fold maps the swapped pair to the same
    bin); f depends on the azimuths only through φ_i − φ_o (φ_h is dropped):
    ``isotropic`` True. It is even in φ_i − φ_o — ``mirror_symmetric`` True, so the
    albedo engine integrates half the azimuths — only when the table equals its
    mirror image, bin φ_d ↔ bin 179 − φ_d (:func:`_mirror_symmetric`; a mirrored
    pair's φ_d folds to π − φ_d). A table of a reciprocal isotropic function is; a
    table of a non-reciprocal one (each bin holds f(ω_i, ω_o) of its own centre
    only) or a noisy measurement is not, and declares ``mirror_symmetric`` False
    (the engine then integrates all azimuths: halving cost 1.1 % of the albedo of
    a tabulated Lewis Phong at θ_i = 20° while reporting 3e-6 error).

    Sampling: from the table's own values (:mod:`brdfkit.data.sampler`: per-θ_o
    bilinear half-vector tables of f̄ cos θ_i mixed with the cosine), built on
    the first ``sample``/``pdf`` (~50 ms); the density is positive on the whole
    upper hemisphere, unmeasured bins included.

    Plausibility verdicts (:func:`brdfkit.analysis.check`) on measured data:
    *reciprocal* is a property of the lookup, not of the measurement — MERL
    stores one value per (θ_h, θ_d, φ_d mod π) bin, and swapping ω_i and ω_o
    only flips φ_d by π, so every table is reciprocal whatever was measured
    (a verdict about the storage, not evidence that the material is). With
    ``nearest`` the indices are computed from ω_i (as the reference reader), and
    a pair on a bin edge can round to the neighbouring bin when swapped: the
    verdict is then "not reciprocal" by the difference of two neighbouring bins
    (2e-6 for a smooth tabulated Phong; measured noise is larger). ``linear``
    is reciprocal to rounding. Pairs that land on unmeasured bins are left
    out of the verdict and counted in its notes. *Energy*:
    a ``nearest`` table's albedo does not converge to the engine's tolerance
    (jumps at bin edges), so the verdict is ``undetermined`` when the maximum
    albedo lies within its error estimate of 1 and otherwise reflects the
    table's albedo ± that error; unmeasured bins make the albedo NaN where they
    are reached and the verdict ``undetermined`` (no value is invented for them).
    """

    def __init__(self, table: MerlTable, *, name: str | None = None, lookup: str = "nearest",
                 citation: str = ("Matusik et al. 2003 (MERL BRDF database, CC-BY-SA-4.0); "
                                  "MERL .binary format")):
        if not isinstance(table, MerlTable):
            raise ParameterError(f"MeasuredBRDF: table must be a MerlTable (read_binary); got "
                                 f"{type(table).__name__}")
        self.table = table
        values = np.where(table.valid, table.values, np.nan).reshape(3, N_BINS)
        self._values_table = values
        self._interleaved = None  # built on the first eval (see _driver_data)
        self._width = _width_from_table(values.reshape(3, *SHAPE))
        label = name or f"merl-file:{os.path.basename(table.source)}"
        super().__init__(
            name=label, params=(Param("lookup", "nearest", kind="choice",
                                      choices=("nearest", "linear"),
                                      doc="nearest bin (reference reader) or trilinear"),),
            values={"lookup": lookup}, citation=citation,
            summary=f"tabulated material ({table.source}), MERL grid 90x90x180",
            reciprocal=True, has_sampler=True, kernel=_measured_kernel,
            isotropic=True, mirror_symmetric=_mirror_symmetric(values))
        self.n_channels = 3
        # one bin computation per pair for all channels
        self._driver = _table_driver(self._values["lookup"])

    def _pack(self) -> np.ndarray:
        mode = LINEAR if self._values["lookup"] == "linear" else NEAREST
        out = np.empty((3, _TABLE + N_BINS))
        out[:, 0] = mode
        out[:, _TABLE:] = self._values_table
        return out

    def _driver_data(self) -> np.ndarray:
        """What the table loops (:func:`~brdfkit.data._merl_index._table_driver`) read
        (built once): the index tables, then the channel-interleaved table."""
        if self._interleaved is None:
            t = np.empty(_NQ + 3 * N_BINS)
            t[:_NQ] = _index_tables()
            # written in place, channel-interleaved: .T.reshape(-1) made a temporary copy
            # first, 0.15-0.7 s of a loaded machine against 0.05 s (a .binary's reload)
            t[_NQ:].reshape(-1, 3)[:] = self._values_table.T
            t.flags.writeable = False
            self._interleaved = t
        return self._interleaved

    def lobes(self):
        return [Lobe("diffuse", 0.5 * math.pi), Lobe("half", self._width)]

    def formulas(self):
        """The lookup as a formula over the packed row, the cosine + GGX proxy of the
        table's lobe as sampler (:func:`brdfkit.data.merl_formulas.measured_formulas`): the
        Mitsuba bridge's traced route, the table one Dr.Jit array."""
        return measured_formulas(self)

    def provenance(self) -> str:
        """Verdicts on this model are verdicts on the table and its lookup (docstring)."""
        return (f"the tabulated values of {self.table.source} ({self.values['lookup']} "
                "lookup on the MERL grid): reciprocal by the grid's fold, whatever was "
                "measured; its albedo is the table's")

    def with_params(self, **changes) -> MeasuredBRDF:
        unknown = set(changes) - {"lookup"}
        if unknown:
            raise ParameterError(f"{self.name}: unknown parameter {sorted(unknown)[0]!r}; valid "
                                 "parameters: lookup")
        return MeasuredBRDF(self.table, name=self.name,
                            lookup=changes.get("lookup", self._values["lookup"]),
                            citation=self.citation)

    def to_dict(self) -> dict:
        return {"model": self.name, "params": dict(self._values)}

    def __repr__(self) -> str:
        return f"MeasuredBRDF({self.table.source!r}, lookup={self._values['lookup']!r})"
