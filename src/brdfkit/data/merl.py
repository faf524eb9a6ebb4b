"""
The MERL ``.binary`` format, exactly
====================================

Matusik et al. (2003) store an isotropic BRDF on a half/difference-angle grid
of 90 θ_h × 90 θ_d × 180 φ_d bins, three colour channels. This module reads
and writes that format bit-exactly and finds the bins of direction pairs
exactly as MERL's reference reader (``BRDFRead.cpp``) does; a table becomes a
brdfkit model in :mod:`brdfkit.data.measured`
(:class:`~brdfkit.data.measured.MeasuredBRDF`).

File layout
-----------
- header: three little-endian int32, which must be exactly (90, 90, 180)
  (the reference reader only checks their product; we check each);
- then 3 × 1,458,000 little-endian float64, planar (all red, then green, then
  blue), each channel in C order [θ_h][θ_d][φ_d];
- stored values are scaled on read by 1/1500, 1.15/1500, 1.66/1500 (red,
  green, blue) to give f_r in 1/sr. :class:`MerlTable` keeps the file's raw
  values, so writing a table that was read gives back the same bytes (a
  multiplication by 1/1500 is not invertible in floating point: two raw values
  can round to one scaled value).
- negative entries mark bins that were not measured. brdfkit keeps them as a
  **validity mask** (:attr:`MerlTable.valid`): never reflectance 0, never
  silently clamped (see :class:`~brdfkit.data.measured.MeasuredBRDF`).

Lookup (``BRDFRead.cpp``, ``lookup_brdf_val``)
----------------------------------------------
h = normalise(ω_i + ω_o), θ_h = acos h_z, φ_h = atan2(h_y, h_x);
d = rot_y(−θ_h) · rot_z(−φ_h) · ω_i, θ_d = acos d_z, φ_d = atan2(d_y, d_x);
i_θh = 0 if θ_h ≤ 0 else ⌊√(θ_h/(π/2)·90·90)⌋, i_θd = ⌊θ_d/(π/2)·90⌋,
i_φd = ⌊(φ_d + π if φ_d < 0 else φ_d)/π·180⌋, each clamped to its range;
index = i_φd + 180·i_θd + 180·90·i_θh. The ``linear`` lookup interpolates
trilinearly between bin centres in these index coordinates (u_θh = √(θ_h/(π/2))·90,
u_θd = θ_d/(π/2)·90, u_φd = φ_d/π·180; centres at i + ½; θ_h and θ_d clamped at
the ends, φ_d periodic with period π — φ_d and φ_d + π are the same bin).
The compiled lookups find the same ``nearest`` bin without acos/atan2
(exact step tables of h_z and d_z, φ_d boundary side tests:
:mod:`brdfkit.data._merl_index`).

Public objects
--------------
- :class:`MerlTable` — a table as stored (raw values) with scaled values and mask.
- :func:`read_binary`, :func:`write_binary` — exact I/O with precise errors.
- :func:`merl_indices` — the reference reader's bin indices of direction pairs.
- :func:`table_from_function` — tabulate any f(wi, wo) on the MERL grid.
- :func:`bin_centres`, :func:`half_diff_to_directions` — the grid's angles, as directions.
- :data:`SCALES`, :data:`SHAPE`, :data:`N_BINS`.

References
----------
- [Matusik2003] W. Matusik, H. Pfister, M. Brand, L. McMillan, *A Data-Driven
  Reflectance Model*, ACM TOG 22(3), 2003; the MERL BRDF database (CC-BY-SA-4.0)
  and its reference reader ``BRDFRead.cpp``.
- [Rusinkiewicz1998] S. Rusinkiewicz, *A New Change of Variables for Efficient
  BRDF Representation*, EGWR 1998 (the half/difference angles).
"""

from __future__ import annotations

import os
from dataclasses import dataclass

import numba
import numpy as np

from brdfkit._io import write_atomic
from brdfkit.data._merl_index import (
    _index_tables,
    _indices,
    _indices_formula,
)
from brdfkit.errors import DataFileError, ParameterError
from brdfkit.geometry import merl_theta_h

__all__ = ["MerlTable", "read_binary", "write_binary", "merl_indices", "table_from_function",
           "bin_centres", "half_diff_to_directions", "SCALES", "SHAPE", "N_BINS"]

#: Bins per axis: θ_h, θ_d, φ_d (φ_d over [0, π): reciprocity folds [π, 2π) onto it).
SHAPE = (90, 90, 180)
N_BINS = SHAPE[0] * SHAPE[1] * SHAPE[2]  # 1,458,000 per channel
#: The reference reader's channel scales (RED_SCALE, GREEN_SCALE, BLUE_SCALE).
SCALES = np.array([1.0 / 1500.0, 1.15 / 1500.0, 1.66 / 1500.0])
_HEADER_BYTES = 12
_FILE_BYTES = _HEADER_BYTES + 3 * N_BINS * 8
#: A header dimension shown in an error: MERL's layouts have ≤ 360 bins per axis; larger or
#: non-positive values are other bytes (text, another format), not echoed.
_MAX_SHOWN_DIM = 1024


# --------------------------------------------------------------------------- the table
@dataclass(frozen=True, eq=False)
class MerlTable:
    """A MERL table: the file's raw values, as stored.

    Attributes
    ----------
    raw : ndarray, shape (3, 90, 90, 180), float64
        The stored values (unscaled; negative = not measured). Read-only.
    source : str
        Where it came from (a path or a description).
    """

    raw: np.ndarray
    source: str = "<memory>"

    def __post_init__(self):
        raw = np.asarray(self.raw, dtype=np.float64).reshape(3, *SHAPE)
        raw = np.array(raw, copy=True) if raw.flags.writeable else raw
        raw.flags.writeable = False
        object.__setattr__(self, "raw", raw)

    @property
    def values(self) -> np.ndarray:
        """f_r in 1/sr, shape (3, 90, 90, 180): raw × channel scale (negative where invalid)."""
        return self.raw * SCALES[:, None, None, None]

    @property
    def valid(self) -> np.ndarray:
        """Validity mask (3, 90, 90, 180): True where the bin was measured (raw ≥ 0)."""
        return self.raw >= 0.0

    @property
    def valid_fraction(self) -> float:
        """Fraction of bins (all channels) that were measured."""
        return float(np.mean(self.valid))

    @classmethod
    def from_values(cls, values, source: str = "<memory>") -> MerlTable:
        """A table from f_r values in 1/sr, shape (3, 90, 90, 180) (scales inverted)."""
        v = np.asarray(values, dtype=np.float64)
        if v.shape != (3, *SHAPE):
            raise ParameterError(f"values must have shape (3, 90, 90, 180); got {v.shape}")
        if not np.all(np.isfinite(v)):
            raise ParameterError("values must be finite (mark unmeasured bins with -1, not NaN)")
        return cls(v / SCALES[:, None, None, None], source)


def _dims_like(dims) -> bool:
    return all(0 < int(x) <= _MAX_SHOWN_DIM for x in dims)


def read_binary(path) -> MerlTable:
    """Read a MERL ``.binary`` file (layout in the module docstring).

    Raises
    ------
    DataFileError
        Naming the file and what was expected vs found: no such file, a symbolic
        link loop or a dangling link (the OS's reason), not a file, header not
        (90, 90, 180), truncated or too long, NaN/inf entries, every entry invalid.
    """
    p = os.fspath(path)
    try:
        os.stat(p)
    except FileNotFoundError:
        if os.path.islink(p):
            raise DataFileError(f"{p}: a symbolic link to a missing file "
                                f"({os.readlink(p)})") from None
        raise DataFileError(f"{p}: no such file") from None
    except OSError as err:  # e.g. a symbolic link loop, a permission denied on the path
        raise DataFileError(f"{p}: cannot be read ({err.strerror})") from None
    if not os.path.isfile(p):
        raise DataFileError(f"{p}: not a regular file")
    size = os.path.getsize(p)
    if size < _HEADER_BYTES:
        raise DataFileError(f"{p}: header: expected 12 bytes (three int32 90, 90, 180); the "
                            f"file has {size} bytes")
    try:
        with open(p, "rb") as fh:
            dims = np.fromfile(fh, dtype="<i4", count=3)
            if tuple(int(x) for x in dims) != SHAPE:
                # dimensions a table could have are shown; other bytes are not echoed (the
                # explorer reports this message for a path from a request: no file content)
                swapped = dims.byteswap()
                if _dims_like(dims):
                    found = f"({', '.join(str(int(x)) for x in dims)})"
                elif _dims_like(swapped):
                    found = (f"({', '.join(str(int(x)) for x in swapped)}) read big-endian "
                             "(MERL files are little-endian)")
                else:
                    found = "bytes that are not table dimensions"
                raise DataFileError(
                    f"{p}: header: expected dimensions (90, 90, 180); found {found} — not a "
                    "MERL isotropic .binary")
            if size != _FILE_BYTES:
                what = "truncated" if size < _FILE_BYTES else "too long"
                raise DataFileError(
                    f"{p}: {what}: expected {_FILE_BYTES} bytes (12-byte header + 3 x "
                    f"{N_BINS} float64); found {size}")
            raw = np.fromfile(fh, dtype="<f8", count=3 * N_BINS)
    except OSError as exc:
        raise DataFileError(f"{p}: cannot read: {exc.strerror or exc}") from None
    raw = raw.astype(np.float64, copy=False).reshape(3, *SHAPE)
    finite = np.isfinite(raw)
    if not finite.all():
        c, ih, idd, ip = np.argwhere(~finite)[0]
        raise DataFileError(
            f"{p}: data: expected finite values; found {int((~finite).sum())} NaN/inf entries, "
            f"the first in channel {'RGB'[c]} at (theta_h, theta_d, phi_d) bin "
            f"({ih}, {idd}, {ip})")
    if not np.any(raw >= 0.0):
        raise DataFileError(f"{p}: data: every entry is negative (no bin was measured)")
    return MerlTable(raw, p)


def write_binary(path, table) -> str:
    """Write *table* (a :class:`MerlTable`, or f_r values (3, 90, 90, 180) in 1/sr) as a
    MERL ``.binary`` file, atomically. A table read from a file is written back with its
    raw values, byte for byte. Returns the path."""
    t = table if isinstance(table, MerlTable) else MerlTable.from_values(table)

    def write(fh):
        np.asarray(SHAPE, dtype="<i4").tofile(fh)
        np.ascontiguousarray(t.raw, dtype="<f8").tofile(fh)

    return write_atomic(path, write, option="path")


# --------------------------------------------------------------------------- lookup
# the index arithmetic (half/difference angles, bins, the fast index, trilinear cells) is
# in brdfkit.data._merl_index


def merl_indices(wi, wo, *, method: str = "fast") -> np.ndarray:
    """Flat bin index (``i_φd + 180 i_θd + 16200 i_θh``) of each pair, as ``BRDFRead.cpp``.

    ``method="formula"`` evaluates the reference's acos/atan2 formulas; ``"fast"`` (what
    :class:`~brdfkit.data.measured.MeasuredBRDF` uses) gives the same indices without them
    (see _fast_index).
    """
    from brdfkit._array import as_directions

    if method not in ("fast", "formula"):
        raise ParameterError(f"merl_indices: method must be 'fast' or 'formula'; got "
                             f"{method!r}")
    wi = as_directions(wi, "wi")
    wo = as_directions(wo, "wo")
    shape = np.broadcast_shapes(wi.shape, wo.shape)
    a = np.ascontiguousarray(np.broadcast_to(wi, shape).reshape(-1, 3))
    b = np.ascontiguousarray(np.broadcast_to(wo, shape).reshape(-1, 3))
    out = np.empty(a.shape[0], dtype=np.int64)
    if method == "fast":
        _indices(a, b, _index_tables(), out)
    else:
        _indices_formula(a, b, out)
    return out.reshape(shape[:-1])


# --------------------------------------------------------------------------- tabulation
def bin_centres() -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """θ_h, θ_d, φ_d at the bin centres (radians): the index coordinates i + ½ mapped back
    (θ_h = (u/90)²·π/2 — MERL's quadratic spacing), shapes (90,), (90,), (180,)."""
    u = np.arange(90) + 0.5
    theta_h = merl_theta_h(u / 90.0)
    theta_d = u / 90.0 * (0.5 * np.pi)
    phi_d = (np.arange(180) + 0.5) / 180.0 * np.pi
    return theta_h, theta_d, phi_d


def half_diff_to_directions(theta_h, theta_d, phi_d) -> tuple[np.ndarray, np.ndarray]:
    """(wi, wo) of half/difference angles (φ_h = 0): the inverse of the lookup's rotations."""
    theta_h, theta_d, phi_d = np.broadcast_arrays(theta_h, theta_d, phi_d)
    d = np.stack([np.sin(theta_d) * np.cos(phi_d), np.sin(theta_d) * np.sin(phi_d),
                  np.cos(theta_d)], axis=-1)
    h = np.stack([np.sin(theta_h), np.zeros_like(theta_h), np.cos(theta_h)], axis=-1)
    # wi = rot_y(θ_h) d (undo rot_y(−θ_h); φ_h = 0); wo = 2 (wi·h) h − wi
    c, s = np.cos(theta_h), np.sin(theta_h)
    wi = np.stack([d[..., 0] * c + d[..., 2] * s, d[..., 1], d[..., 2] * c - d[..., 0] * s],
                  axis=-1)
    wo = 2.0 * np.sum(wi * h, axis=-1, keepdims=True) * h - wi
    return wi, wo


@numba.njit(cache=True)
def _centre_pairs(sh, ch, sd, cd, sp, cp, wi, wo, up):  # pragma: no cover - compiled
    """:func:`half_diff_to_directions` at every bin centre (the same operations in the same
    order, from the per-axis sines and cosines), the pairs with both directions above the
    horizon packed into the first rows of ``wi``, ``wo`` (N_BINS, 3); ``up`` (N_BINS,) marks
    their bins. Returns their number."""
    m = 0
    for ih in range(90):
        c, s = ch[ih], sh[ih]  # h = (sin θ_h, 0, cos θ_h)
        for idd in range(90):
            for ip in range(180):
                d0 = sd[idd] * cp[ip]
                d1 = sd[idd] * sp[ip]
                d2 = cd[idd]
                # wi = rot_y(θ_h) d; wo = 2 (wi·h) h − wi
                a0 = d0 * c + d2 * s
                a1 = d1
                a2 = d2 * c - d0 * s
                t2 = 2.0 * ((a0 * s + a1 * 0.0) + a2 * c)
                b0 = t2 * s - a0
                b1 = t2 * 0.0 - a1
                b2 = t2 * c - a2
                k = ip + 180 * idd + 16200 * ih
                ok = a2 > 0.0 and b2 > 0.0
                up[k] = ok
                if ok:
                    wi[m, 0], wi[m, 1], wi[m, 2] = a0, a1, a2
                    wo[m, 0], wo[m, 1], wo[m, 2] = b0, b1, b2
                    m += 1
    return m


@numba.njit(cache=True)
def _scatter(vals, up, scales, raw):  # pragma: no cover - compiled
    """raw[c, k] = (the next row of vals)[c] / scales[c] where up[k], else −1 (unmeasured)."""
    m = 0
    for k in range(up.shape[0]):
        if up[k]:
            for c in range(3):
                raw[c, k] = vals[m, c] / scales[c]
            m += 1
        else:
            for c in range(3):
                raw[c, k] = -1.0


def table_from_function(f, *, source: str = "<function>") -> MerlTable:
    """Tabulate ``f(wi, wo) -> (N,) or (N, 3)`` (f_r in 1/sr) at the MERL bin centres.

    Bin-centre convention: each bin is evaluated at the centre of its index
    coordinates (:func:`bin_centres`), φ_h = 0 (the directions of
    :func:`half_diff_to_directions`). Bins whose ω_i or ω_o is at or below the
    horizon are marked unmeasured (raw −1), as in MERL files. *f* is called once,
    on the 1,096,216 pairs above the horizon.
    """
    th, td, pd = bin_centres()
    wi = np.empty((N_BINS, 3))
    wo = np.empty((N_BINS, 3))
    up = np.empty(N_BINS, dtype=np.bool_)
    m = _centre_pairs(np.sin(th), np.cos(th), np.sin(td), np.cos(td), np.sin(pd), np.cos(pd),
                      wi, wo, up)
    vals = np.asarray(f(wi[:m], wo[:m]), dtype=np.float64)
    vals = vals.reshape(vals.shape[0], -1)
    if vals.shape[1] == 1:
        vals = np.repeat(vals, 3, axis=1)
    if vals.shape[1] != 3:
        raise ParameterError(f"table_from_function: f must return (N,) or (N, 3) values; got "
                             f"{vals.shape[1]} channels")
    if not np.all(np.isfinite(vals)):
        raise ParameterError("table_from_function: f returned NaN or inf above the horizon")
    raw = np.empty((3, N_BINS))
    _scatter(vals, up, SCALES, raw)
    raw.flags.writeable = False  # MerlTable keeps a read-only array as it is (no copy)
    return MerlTable(raw.reshape(3, *SHAPE), source)

