"""
The MERL ``.binary`` format, exactly
====================================

Matusik et al. (2003) store an isotropic BRDF on a half/difference-angle grid
of 90 θ_h × 90 θ_d × 180 φ_d bins, three colour channels. This module reads
and writes that format bit-exactly, looks values up exactly as MERL's
reference reader (``BRDFRead.cpp``) does, and turns a table into a brdfkit
model (:class:`MeasuredBRDF`).

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
  silently clamped (see :class:`MeasuredBRDF`'s ``invalid`` parameter).

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

Public objects
--------------
- :class:`MerlTable` — a table as stored (raw values) with scaled values and mask.
- :func:`read_binary`, :func:`write_binary` — exact I/O with precise errors.
- :func:`merl_indices` — the reference reader's bin indices of direction pairs.
- :func:`table_from_function` — tabulate any f(wi, wo) on the MERL grid.
- :class:`MeasuredBRDF` — a tabulated material as a brdfkit model.
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

import functools
import math
import os
from dataclasses import dataclass

import numba
import numpy as np

from brdfkit._io import write_atomic
from brdfkit.errors import DataFileError, ParameterError
from brdfkit.models._base import DerivedBRDF, Lobe, Param, _unit_pair

__all__ = ["MerlTable", "read_binary", "write_binary", "merl_indices", "table_from_function",
           "MeasuredBRDF", "SCALES", "SHAPE", "N_BINS"]

#: Bins per axis: θ_h, θ_d, φ_d (φ_d over [0, π): reciprocity folds [π, 2π) onto it).
SHAPE = (90, 90, 180)
N_BINS = SHAPE[0] * SHAPE[1] * SHAPE[2]  # 1,458,000 per channel
#: The reference reader's channel scales (RED_SCALE, GREEN_SCALE, BLUE_SCALE).
SCALES = np.array([1.0 / 1500.0, 1.15 / 1500.0, 1.66 / 1500.0])
_HEADER_BYTES = 12
_FILE_BYTES = _HEADER_BYTES + 3 * N_BINS * 8


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


def read_binary(path) -> MerlTable:
    """Read a MERL ``.binary`` file (layout in the module docstring).

    Raises
    ------
    DataFileError
        Naming the file and what was expected vs found: not a file, header not
        (90, 90, 180), truncated or too long, NaN/inf entries, every entry invalid.
    """
    p = os.fspath(path)
    if not os.path.exists(p):
        raise DataFileError(f"{p}: no such file")
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
                raise DataFileError(
                    f"{p}: header: expected dimensions (90, 90, 180); found "
                    f"({', '.join(str(int(x)) for x in dims)}) — not a MERL isotropic .binary")
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
@numba.njit(cache=True, inline="always")
def _half_diff_vec(ix, iy, iz, ox, oy, oz):
    """(h_z, d_x, d_y, d_z): the half vector's z and the difference vector, as the reference
    reader computes them up to rounding.

    The reference takes φ_h = atan2(h_y, h_x) and rotates by −φ_h and −θ_h with
    cos/sin of those angles; here cos φ_h = h_x/ρ, sin φ_h = h_y/ρ (ρ = √(h_x² + h_y²)),
    cos θ_h = h_z, sin θ_h = ρ — the same rotations from the components, without
    transcendental calls (the indices agree with the reference formulas' except within
    rounding of a bin boundary: tests/test_data_merl.py).
    """
    hx = ix + ox
    hy = iy + oy
    hz = iz + oz
    n = math.sqrt(hx * hx + hy * hy + hz * hz)
    if n <= 0.0:
        return 1.0, 1.0, 0.0, 0.0  # wi = −wo (only below the horizon): θ_h = 0, θ_d = π/2
    inv = 1.0 / n  # one division, three products (not three divisions)
    hx *= inv
    hy *= inv
    hz *= inv
    rho = math.sqrt(hx * hx + hy * hy)
    if rho > 0.0:
        inv = 1.0 / rho
        cp, sp = hx * inv, hy * inv  # cos φ_h, sin φ_h
    else:
        cp, sp = 1.0, 0.0  # h = N: atan2(0, 0) = 0
    # rotate wi about the normal by −φ_h, then about the binormal (y) by −θ_h
    tx = ix * cp + iy * sp
    ty = iy * cp - ix * sp
    tz = iz
    ct, st = hz, rho  # cos θ_h, sin θ_h (θ_h ∈ [0, π])
    dx = tx * ct - tz * st
    dy = ty
    dz = tz * ct + tx * st
    return hz, dx, dy, dz


@numba.njit(cache=True, inline="always")
def _half_diff(ix, iy, iz, ox, oy, oz):
    """(θ_h, θ_d, φ_d) of the pair, as the reference reader computes them (φ_d ∈ (−π, π])."""
    hz, dx, dy, dz = _half_diff_vec(ix, iy, iz, ox, oy, oz)
    # cosines of (nearly) unit vectors, clamped to [−1, 1] against rounding before acos
    theta_h = math.acos(min(1.0, max(-1.0, hz)))
    theta_d = math.acos(min(1.0, max(-1.0, dz)))
    phi_d = math.atan2(dy, dx)
    return theta_h, theta_d, phi_d


@numba.njit(cache=True, inline="always")
def _theta_h_index(theta_h):
    if theta_h <= 0.0:
        return 0
    return min(max(int(math.sqrt(theta_h / (0.5 * math.pi) * 90.0 * 90.0)), 0), 89)


@numba.njit(cache=True, inline="always")
def _theta_d_index(theta_d):
    return min(max(int(theta_d / (0.5 * math.pi) * 90.0), 0), 89)


@numba.njit(cache=True, inline="always")
def _phi_d_index(phi_d):
    if phi_d < 0.0:
        phi_d += math.pi
    return min(max(int(phi_d / math.pi * 180.0), 0), 179)


@numba.njit(cache=True, inline="always")
def _nearest_index(theta_h, theta_d, phi_d):
    return _phi_d_index(phi_d) + 180 * _theta_d_index(theta_d) + 16200 * _theta_h_index(theta_h)


@numba.njit(cache=True)
def _theta_h_index_of_cos(hz):
    """The reference's θ_h index as a function of h_z alone (non-increasing)."""
    return _theta_h_index(math.acos(min(1.0, max(-1.0, hz))))


@numba.njit(cache=True)
def _theta_d_index_of_cos(dz):
    """The reference's θ_d index as a function of d_z alone (non-increasing)."""
    return _theta_d_index(math.acos(min(1.0, max(-1.0, dz))))


# ---- the fast nearest index (no transcendental call; the same index as the formulas) ----
# θ_h and θ_d: each index is a non-increasing step function of one float (h_z, d_z), so it
# is given exactly by the 89 floats where it steps (found once per process by bisection on
# the formula itself, _index_tables): a cheap first guess, then compare-and-step to them.
# φ_d: a cheap guess of the bin, then the side of the bin's two boundary rays (cross
# products); only a pair within _PHI_MARGIN rad of a boundary calls atan2.
_Q_TH = 0  # T_h[0..90]: ih(h_z) = k ⟺ T_h[k+1] ≤ h_z < T_h[k]; T_h[0] = inf, T_h[90] = −inf
_Q_TD = 91  # T_d[0..90], the same for i_θd(d_z)
_Q_B = 182  # the φ_d bin boundaries k·π/180, k = 0..180, as (cos, sin) pairs
_Q_OK = _Q_B + 2 * 181  # 1.0: the tables hold; 0.0: use the formulas (see _index_tables)
_NQ = _Q_OK + 1
#: Half-width (rad) of the band about a φ_d boundary inside which atan2 decides. The
#: formula's φ_d differs from the exact angle of (d_x, d_y) by a few ulp (atan2 ≤ 1 ulp,
#: the +π fold and ·180/π ≤ 2 ulp of π: < 2e-15 rad) and the side test's rounding is
#: < 2e-15 (|d_x| + |d_y|): outside 1e-12 rad both give the same bin (a band of
#: 2e-12 rad per boundary: ~1e-10 of random pairs take the atan2 path).
_PHI_MARGIN = 1e-12
#: Below this |d_x| + |d_y| (θ_d ≈ 0, where φ_d is undefined) atan2 decides: keeps the side
#: products far from subnormal numbers, where their relative rounding bound would not hold.
_PHI_TINY = 1e-100
_TH_SCALE = 90.0 * 90.0 / (0.5 * math.pi)  # u_θh² per radian
_TD_SCALE = 90.0 / (0.5 * math.pi)  # θ_d bins per radian
_PD_SCALE = 180.0 / math.pi  # φ_d bins per radian


@numba.njit(cache=True, inline="always")
def _acos_guess(x):
    """acos x for x ∈ [0, 1] within 7e-5 rad (Abramowitz & Stegun 4.4.45): a first guess."""
    return math.sqrt(1.0 - x) * (1.5707288 + x * (-0.2121144 + x * (0.0742610
                                                                     - 0.0187293 * x)))


@numba.njit(cache=True, inline="always")
def _atan_guess(r):
    """atan r for r ∈ [0, 1] within 1e-5 rad (Hastings' odd polynomial): a first guess."""
    r2 = r * r
    return r * (0.99997726 + r2 * (-0.33262347 + r2 * (0.19354346 + r2 * (
        -0.11643287 + r2 * (0.05265332 - 0.01172120 * r2)))))


@numba.njit(cache=True, inline="always")
def _phi_side(Q, k, x, y):
    """(cos φ_k) y − (sin φ_k) x: > 0 where (x, y) is counter-clockwise of boundary k."""
    return Q[_Q_B + 2 * k] * y - Q[_Q_B + 2 * k + 1] * x


@numba.njit(cache=True, inline="always")
def _fast_index(hz, dx, dy, dz, Q):
    """The flat nearest index of (h_z, d) — equal to ``_nearest_index`` of the angles the
    formulas give (exactly: see the comment above _Q_TH), with no acos and almost no atan2."""
    if Q[_Q_OK] == 0.0:
        return _nearest_index(math.acos(min(1.0, max(-1.0, hz))),
                              math.acos(min(1.0, max(-1.0, dz))), math.atan2(dy, dx))
    # θ_h: guess from acos ≈ (A&S), then step until T_h[k+1] ≤ h_z < T_h[k]
    x = min(max(hz, 0.0), 1.0)  # h_z < 0 (θ_h > π/2, below the horizon only): guess 89
    kh = min(int(math.sqrt(_acos_guess(x) * _TH_SCALE)), 89)
    while hz >= Q[_Q_TH + kh]:  # T_h[0] = inf stops it
        kh -= 1
    while hz < Q[_Q_TH + kh + 1]:  # T_h[90] = −inf stops it
        kh += 1
    # θ_d: the same with T_d (d_z ≤ 0: θ_d ≥ π/2, guessed as the last bin)
    kd = min(int(_acos_guess(min(max(dz, 0.0), 1.0)) * _TD_SCALE), 89)
    while dz >= Q[_Q_TD + kd]:
        kd -= 1
    while dz < Q[_Q_TD + kd + 1]:
        kd += 1
    return _fast_phi_index(dx, dy, Q) + 180 * kd + 16200 * kh


@numba.njit(cache=True, inline="always")
def _fast_phi_index(dx, dy, Q):
    """The φ_d bin of (d_x, d_y): a guess, then the side tests (fallback: atan2). Written
    with selects rather than branches where the data decide (a random φ_d mispredicts
    half of such branches; measured 66 → 40 ns per pair)."""
    # fold (d_x, d_y) to the upper half plane (the formula's +π for φ_d < 0); d_y = −0 is
    # folded too, which puts (x, y) on the boundary φ = 0 or π: the side test sends it to
    # atan2, which decides as the formula does
    sgn = math.copysign(1.0, dy)
    x = dx * sgn
    y = abs(dy)
    ax = abs(x)
    scale = ax + y  # |d_x| + |d_y|
    a = _atan_guess(min(ax, y) / max(ax, y))  # the angle to the nearer axis (NaN for 0/0)
    phi = a + (1.0 if y > ax else 0.0) * (0.5 * math.pi - 2.0 * a)  # in [0, π/2]
    phi = phi + (1.0 if x < 0.0 else 0.0) * (math.pi - 2.0 * phi)  # in [0, π]
    kp = min(max(int(phi * _PD_SCALE), 0), 179) if phi == phi else 0
    m = _PHI_MARGIN * scale
    if _phi_side(Q, kp, x, y) > m and _phi_side(Q, kp + 1, x, y) < -m:
        return kp  # inside bin kp by more than the margin on both sides: nearly always
    if not scale > _PHI_TINY:  # also NaN
        return _phi_d_index(math.atan2(dy, dx))
    while kp > 0 and _phi_side(Q, kp, x, y) < -m:
        kp -= 1
    while kp < 179 and _phi_side(Q, kp + 1, x, y) > m:
        kp += 1
    # inside bin kp by more than the margin on both sides, or atan2 decides
    if not (abs(_phi_side(Q, kp, x, y)) > m and abs(_phi_side(Q, kp + 1, x, y)) > m):
        kp = _phi_d_index(math.atan2(dy, dx))
    return kp


#: Floats checked on each side of every step of the θ_h and θ_d indices (_index_tables).
_STEP_WINDOW = 64


@numba.njit(cache=True)
def _steps(which, T):  # pragma: no cover - compiled
    """Fill T[0..90] with the steps of the θ_h (which = 0: of h_z) or θ_d (1: of d_z) index
    g, a non-increasing step function on [0, 1] with g(0) = 89, g(1) = 0: T[k] = the
    smallest float z ∈ [0, 1] with g(z) < k, by bisection on the bit patterns (positive
    floats order as their bits). Returns whether g steps cleanly there: g ≥ k on the
    _STEP_WINDOW floats below T[k], g < k on T[k] and the floats above."""
    ib = np.empty(1, dtype=np.int64)
    fb = ib.view(np.float64)  # fb[0]: the float whose bits are ib[0]
    fb[0] = 1.0
    one = ib[0]
    T[0] = math.inf
    T[90] = -math.inf
    ok = True
    for k in range(1, 90):
        lo, hi = 0, one  # the bits of 0.0 and 1.0: g(lo) ≥ k > g(hi)
        while hi - lo > 1:
            ib[0] = (lo + hi) // 2
            g = _theta_h_index_of_cos(fb[0]) if which == 0 else _theta_d_index_of_cos(fb[0])
            if g < k:
                hi = ib[0]
            else:
                lo = ib[0]
        for i in range(-_STEP_WINDOW, _STEP_WINDOW):
            ib[0] = hi + i
            g = _theta_h_index_of_cos(fb[0]) if which == 0 else _theta_d_index_of_cos(fb[0])
            ok &= (g < k) if i >= 0 else (g >= k)
        ib[0] = hi
        T[k] = fb[0]
    return ok


@functools.cache
def _index_tables() -> np.ndarray:
    """The tables of :func:`_fast_index` (built once per process, milliseconds).

    The steps come from the compiled formulas on this machine's libm, so the fast index
    equals the formulas' bit for bit as long as acos is monotonic near each step; that is
    checked on _STEP_WINDOW floats either side, and where it fails (a libm defect) the
    tables are switched off (Q[_Q_OK] = 0: the formulas are evaluated)."""
    Q = np.empty(_NQ)
    ok_h = _steps(0, Q[_Q_TH:_Q_TH + 91])
    ok_d = _steps(1, Q[_Q_TD:_Q_TD + 91])
    phi = np.arange(181) * (math.pi / 180.0)
    Q[_Q_B:_Q_OK:2] = np.cos(phi)
    Q[_Q_B + 1:_Q_OK:2] = np.sin(phi)
    Q[_Q_OK] = 1.0 if (ok_h and ok_d) else 0.0
    Q.flags.writeable = False
    return Q


@numba.njit(cache=True, parallel=True)
def _indices(wi, wo, Q, out):  # pragma: no cover - compiled
    for j in numba.prange(wi.shape[0]):
        hz, dx, dy, dz = _half_diff_vec(wi[j, 0], wi[j, 1], wi[j, 2], wo[j, 0], wo[j, 1],
                                        wo[j, 2])
        out[j] = _fast_index(hz, dx, dy, dz, Q)


@numba.njit(cache=True, parallel=True)
def _indices_formula(wi, wo, out):  # pragma: no cover - compiled
    """The index from the angles (acos, atan2), as the reference: the fast path's check."""
    for j in numba.prange(wi.shape[0]):
        th, td, pd = _half_diff(wi[j, 0], wi[j, 1], wi[j, 2], wo[j, 0], wo[j, 1], wo[j, 2])
        out[j] = _nearest_index(th, td, pd)


def merl_indices(wi, wo, *, method: str = "fast") -> np.ndarray:
    """Flat bin index (``i_φd + 180 i_θd + 16200 i_θh``) of each pair, as ``BRDFRead.cpp``.

    ``method="formula"`` evaluates the reference's acos/atan2 formulas; ``"fast"`` (what
    :class:`MeasuredBRDF` uses) gives the same indices without them (see _fast_index).
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


#: Offset of the table in a packed row: [lookup mode, table …].
_TABLE = 1
NEAREST, LINEAR = 0, 1


@numba.njit(cache=True, inline="always")
def _linear_coords(theta_h, theta_d, phi_d):
    """The trilinear cell of (θ_h, θ_d, φ_d): the flat index of its first corner
    (h0, d0, p0), the step from p0 to the next φ_d bin (+1, or −179 across the period),
    and the fractions (t_h, t_d, t_p) in index coordinates between bin centres."""
    uh = math.sqrt(max(theta_h, 0.0) / (0.5 * math.pi)) * 90.0 - 0.5
    ud = theta_d / (0.5 * math.pi) * 90.0 - 0.5
    if phi_d < 0.0:
        phi_d += math.pi
    up = phi_d / math.pi * 180.0 - 0.5
    # θ_h, θ_d: clamp to the centres of the end bins; φ_d: periodic (period 180 bins)
    uh = min(max(uh, 0.0), 89.0)
    ud = min(max(ud, 0.0), 89.0)
    h0 = min(int(uh), 88)
    d0 = min(int(ud), 88)
    fp = math.floor(up)
    p0 = int(fp) % 180
    step = 1 if p0 < 179 else -179
    return p0 + 180 * d0 + 16200 * h0, step, uh - h0, ud - d0, up - fp


@numba.njit(cache=True, inline="always")
def _linear_sum(t, stride, offset, k0, step, th, td, tp):
    """The weighted mean over the cell's eight corners of the table whose bin i is
    ``t[offset + stride·i]``, NaN (unmeasured) corners left out and the weights of the
    others renormalised; NaN when all eight are unmeasured."""
    acc = 0.0
    wsum = 0.0
    for a in range(2):
        wa = th if a == 1 else 1.0 - th
        for b in range(2):
            wb = td if b == 1 else 1.0 - td
            for c in range(2):
                wc = tp if c == 1 else 1.0 - tp
                w = wa * wb * wc
                v = t[offset + stride * (k0 + (step if c == 1 else 0) + 180 * b + 16200 * a)]
                if v == v and w > 0.0:  # v == v: not NaN (an unmeasured bin)
                    acc += w * v
                    wsum += w
    if wsum <= 0.0:
        return math.nan
    return acc / wsum


@numba.njit(cache=True, inline="always")
def _linear(t, stride, offset, theta_h, theta_d, phi_d):
    """Trilinear interpolation between bin centres of the table whose bin i is
    ``t[offset + stride·i]`` (a planar row: stride 1; the channel-interleaved table: stride
    C) (:func:`_linear_coords`, :func:`_linear_sum`)."""
    k0, step, th, td, tp = _linear_coords(theta_h, theta_d, phi_d)
    return _linear_sum(t, stride, offset, k0, step, th, td, tp)


@numba.njit(cache=True)
def _measured_kernel(ix, iy, iz, ox, oy, oz, p):
    if iz <= 0.0 or oz <= 0.0:
        return 0.0
    theta_h, theta_d, phi_d = _half_diff(ix, iy, iz, ox, oy, oz)
    if p[0] == LINEAR:
        return _linear(p, 1, _TABLE, theta_h, theta_d, phi_d)
    return p[_TABLE + _nearest_index(theta_h, theta_d, phi_d)]


#: Pairs per task of the table drivers: the bins of a block are found first (arithmetic),
#: then read (random reads of a 35 MB table, cache and TLB misses): the reads of a block
#: are independent, so the memory system serves many at once (measured on this 2-core
#: machine: 1.7-2.2x one loop that finds and reads each pair's bin in turn).
_BLOCK = 256
_BAD, _BELOW = -2, -1  # block markers: not a finite unit pair; below the horizon


@numba.njit(cache=True, inline="always")
def _status(ix, iy, iz, ox, oy, oz):
    """0 for a pair to look up, _BAD (not finite unit vectors), _BELOW (f_r = 0)."""
    if not _unit_pair(ix, iy, iz, ox, oy, oz):
        return _BAD
    if iz <= 0.0 or oz <= 0.0:
        return _BELOW
    return 0


@numba.njit(cache=True, inline="always")
def _fill(out, j, n_channels, status):
    """Row j of a pair that is not looked up: NaN (bad) or 0 (below the horizon)."""
    v = math.nan if status == _BAD else 0.0
    for c in range(n_channels):
        out[j, c] = v


@numba.njit(cache=True, parallel=True)
def _nearest_driver(wi, wo, data, out):  # pragma: no cover - compiled
    """:meth:`BRDF.eval`'s checked pass for the ``nearest`` lookup. ``data`` (flat): the
    index tables (:func:`_index_tables`, _NQ numbers), then the channel-interleaved table
    (bin i, channel c at ``_NQ + C·i + c``): the bin is found once per pair for all
    channels, whose values share a cache line (the generic loop around
    :func:`_measured_kernel` finds it per channel and reads three planar rows: ~3 cache
    and TLB misses per random pair). Blocks of _BLOCK pairs. Returns the number of pairs
    that are not finite unit vectors (their rows NaN), as the generic driver does."""
    n = wi.shape[0]
    n_channels = out.shape[1]
    Q = data[:_NQ]
    n_bad = 0
    for q in numba.prange((n + _BLOCK - 1) // _BLOCK):
        lo = q * _BLOCK
        hi = min(n, lo + _BLOCK)
        k = np.empty(_BLOCK, dtype=np.int64)  # the bin's offset in data, or a marker
        for j in range(lo, hi):
            ix, iy, iz = wi[j, 0], wi[j, 1], wi[j, 2]
            ox, oy, oz = wo[j, 0], wo[j, 1], wo[j, 2]
            s = _status(ix, iy, iz, ox, oy, oz)
            if s == 0:
                hz, dx, dy, dz = _half_diff_vec(ix, iy, iz, ox, oy, oz)
                k[j - lo] = _NQ + n_channels * _fast_index(hz, dx, dy, dz, Q)
            else:
                k[j - lo] = s
        for j in range(lo, hi):
            kj = k[j - lo]
            if kj >= 0:
                for c in range(n_channels):
                    out[j, c] = data[kj + c]
            else:
                _fill(out, j, n_channels, kj)
                if kj == _BAD:
                    n_bad += 1
    return n_bad


@numba.njit(cache=True, parallel=True)
def _linear_driver(wi, wo, data, out):  # pragma: no cover - compiled
    """:func:`_nearest_driver` for the ``linear`` lookup (the same ``data``): the cell and
    weights are computed once per pair for all channels."""
    n = wi.shape[0]
    n_channels = out.shape[1]
    n_bad = 0
    for q in numba.prange((n + _BLOCK - 1) // _BLOCK):
        lo = q * _BLOCK
        hi = min(n, lo + _BLOCK)
        k = np.empty(_BLOCK, dtype=np.int64)  # the cell's first corner, or a marker
        step = np.empty(_BLOCK, dtype=np.int64)
        frac = np.empty((_BLOCK, 3))
        for j in range(lo, hi):
            ix, iy, iz = wi[j, 0], wi[j, 1], wi[j, 2]
            ox, oy, oz = wo[j, 0], wo[j, 1], wo[j, 2]
            s = _status(ix, iy, iz, ox, oy, oz)
            if s == 0:
                theta_h, theta_d, phi_d = _half_diff(ix, iy, iz, ox, oy, oz)
                i = j - lo
                k[i], step[i], frac[i, 0], frac[i, 1], frac[i, 2] = _linear_coords(
                    theta_h, theta_d, phi_d)
            else:
                k[j - lo] = s
        for j in range(lo, hi):
            i = j - lo
            if k[i] >= 0:
                for c in range(n_channels):
                    out[j, c] = _linear_sum(data, n_channels, _NQ + c, k[i], step[i],
                                            frac[i, 0], frac[i, 1], frac[i, 2])
            else:
                _fill(out, j, n_channels, k[i])
                if k[i] == _BAD:
                    n_bad += 1
    return n_bad


# --------------------------------------------------------------------------- tabulation
def bin_centres() -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """θ_h, θ_d, φ_d at the bin centres (radians): the index coordinates i + ½ mapped back
    (θ_h = (u/90)²·π/2 — MERL's quadratic spacing), shapes (90,), (90,), (180,)."""
    u = np.arange(90) + 0.5
    theta_h = (u / 90.0) ** 2 * (0.5 * np.pi)
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


# --------------------------------------------------------------------------- the model
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


class MeasuredBRDF(DerivedBRDF):
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
    bin) and isotropic (φ_h is dropped). Sampling: the cosine fallback.
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
            reciprocal=True, has_sampler=False, kernel=_measured_kernel)
        self.n_channels = 3
        # one bin computation per pair for all channels
        self._driver = (_linear_driver if self._values["lookup"] == "linear"
                        else _nearest_driver)

    def _pack(self) -> np.ndarray:
        mode = LINEAR if self._values["lookup"] == "linear" else NEAREST
        out = np.empty((3, _TABLE + N_BINS))
        out[:, 0] = mode
        out[:, _TABLE:] = self._values_table
        return out

    def _driver_data(self) -> np.ndarray:
        """What :func:`_nearest_driver` and :func:`_linear_driver` read (built once): the
        index tables, then the channel-interleaved table."""
        if self._interleaved is None:
            t = np.empty(_NQ + 3 * N_BINS)
            t[:_NQ] = _index_tables()
            t[_NQ:] = self._values_table.T.reshape(-1)
            t.flags.writeable = False
            self._interleaved = t
        return self._interleaved

    def lobes(self):
        return [Lobe("diffuse", 0.5 * math.pi), Lobe("half", self._width)]

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
