"""
The MERL lookup's index arithmetic, compiled
============================================

The half/difference angles of a direction pair as MERL's reference reader
(``BRDFRead.cpp``) computes them, its bin index formulas, a fast nearest
index that gives the same indices without acos/atan2, and the trilinear cell
of the ``linear`` lookup, and the table loops of
:class:`~brdfkit.data.measured.MeasuredBRDF` (:func:`_table_driver`: the blocked loop
of :mod:`brdfkit.models._drivers` with this module's hooks). Used by
:mod:`brdfkit.data.merl`; see its docstring for the formulas and [Matusik2003],
[Rusinkiewicz1998].

The fast nearest index (:func:`_fast_index`)
--------------------------------------------
θ_h and θ_d: each index is a non-increasing step function of one float (h_z,
d_z), so it is given exactly by the 89 floats where it steps, found once per
process by bisection on the compiled formula itself (:func:`_index_tables`):
a cheap first guess, then compare-and-step. φ_d: a cheap guess of the bin,
then the side of the bin's two boundary rays (cross products); only pairs
within 1e-12 rad of a boundary call atan2. The result equals the formulas'
index bit for bit (tests/test_data_merl.py: 1e7 random pairs and 1e6 pairs on
and within rounding of every kind of bin boundary).

References
----------
- [Matusik2003] W. Matusik, H. Pfister, M. Brand, L. McMillan, *A Data-Driven
  Reflectance Model*, ACM TOG 22(3), 2003 (``BRDFRead.cpp``).
- [Rusinkiewicz1998] S. Rusinkiewicz, *A New Change of Variables for Efficient
  BRDF Representation*, EGWR 1998.
- [AS1964] M. Abramowitz, I. Stegun, *Handbook of Mathematical Functions*,
  4.4.45 (the acos guess); C. Hastings, *Approximations for Digital Computers*,
  1955 (the atan guess).
"""

from __future__ import annotations

import math

import numba
import numpy as np

from brdfkit._cache import memo
from brdfkit.models._drivers import _unit_pair, blocked_driver, loop_driver


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


@memo(maxsize=1)  # one set of tables per process (a few kB)
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


# inline="always": inlined into the loop's prange body, which Numba compiles with the NumPy
# error model (a division by 0 gives inf, no exception), as the former hand-written loops
@numba.njit(cache=True, inline="always")
def _index_kernel(ix, iy, iz, ox, oy, oz, Q):
    """The fast nearest index of one pair (exact as a float64: < 2^53), a kernel of the
    plain loop (models/_drivers) over packed row Q (:func:`_index_tables`)."""
    hz, dx, dy, dz = _half_diff_vec(ix, iy, iz, ox, oy, oz)
    return float(_fast_index(hz, dx, dy, dz, Q))


@numba.njit(cache=True, inline="always")
def _index_formula_kernel(ix, iy, iz, ox, oy, oz, q):
    """The index from the angles (acos, atan2), as the reference: the fast path's check."""
    th, td, pd = _half_diff(ix, iy, iz, ox, oy, oz)
    return float(_nearest_index(th, td, pd))


def _indices(wi, wo, Q, out) -> None:
    """out[j] = the fast nearest index of pair j (int64), through the generated plain loop."""
    col = np.empty((wi.shape[0], 1))
    loop_driver(_index_kernel, loop="plain")(wi, wo, Q.reshape(1, -1), col)
    out[:] = col[:, 0]


def _indices_formula(wi, wo, out) -> None:
    """out[j] = the index from the angles (:func:`_nearest_index`), the plain loop."""
    col = np.empty((wi.shape[0], 1))
    loop_driver(_index_formula_kernel, loop="plain")(wi, wo, np.empty((1, 0)), col)
    out[:] = col[:, 0]


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


# --------------------------------------------------------------------------- table loops
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


# The table loops of MeasuredBRDF.eval: the blocked loop of models/_drivers (locate a block
# of pairs, then read it), generated with these hooks and cached on disk. ``data`` (flat):
# the index tables (:func:`_index_tables`, _NQ numbers; _fast_index reads them by absolute
# index, so the whole array is passed), then the channel-interleaved table (bin i, channel c
# at ``_NQ + C·i + c``): the bin is found once per pair for all channels, whose values share
# a cache line (the checked loop around :func:`_measured_kernel` finds it per channel and
# reads three planar rows: ~3 cache and TLB misses per random pair). Both return the number
# of pairs that are not finite unit vectors (their rows NaN), as the checked loop does.
@numba.njit(cache=True, inline="always")
def _nearest_state():
    return np.empty(_BLOCK, dtype=np.int64)  # the pair's bin, or a marker


@numba.njit(cache=True, inline="always")
def _nearest_pair(k, t, ix, iy, iz, ox, oy, oz, data):
    s = _status(ix, iy, iz, ox, oy, oz)
    if s == 0:
        hz, dx, dy, dz = _half_diff_vec(ix, iy, iz, ox, oy, oz)
        k[t] = _fast_index(hz, dx, dy, dz, data)
    else:
        k[t] = s


@numba.njit(cache=True, inline="always")
def _nearest_emit(k, t, data, out, j):
    n_channels = out.shape[1]
    kj = k[t]
    if kj >= 0:
        base = _NQ + n_channels * kj
        for c in range(n_channels):
            out[j, c] = data[base + c]
        return 0
    _fill(out, j, n_channels, kj)
    return 1 if kj == _BAD else 0


@numba.njit(cache=True, inline="always")
def _linear_state():
    # per pair: the cell's first corner (or a marker), the φ_d step, the fractions (t_h,
    # t_d, t_p); one array (a tuple of arrays built in an inlined hook crashed Numba's
    # parallel lowering), the two integers held exactly as floats (< 2^53)
    return np.empty((_BLOCK, 5))


@numba.njit(cache=True, inline="always")
def _linear_pair(state, t, ix, iy, iz, ox, oy, oz, data):
    s = _status(ix, iy, iz, ox, oy, oz)
    if s == 0:
        theta_h, theta_d, phi_d = _half_diff(ix, iy, iz, ox, oy, oz)
        k, step, th, td, tp = _linear_coords(theta_h, theta_d, phi_d)
        state[t, 0] = k
        state[t, 1] = step
        state[t, 2] = th
        state[t, 3] = td
        state[t, 4] = tp
    else:
        state[t, 0] = s


@numba.njit(cache=True, inline="always")
def _linear_emit(state, t, data, out, j):
    n_channels = out.shape[1]
    k = int(state[t, 0])
    if k >= 0:
        step = int(state[t, 1])
        for c in range(n_channels):
            out[j, c] = _linear_sum(data, n_channels, _NQ + c, k, step,
                                    state[t, 2], state[t, 3], state[t, 4])
        return 0
    _fill(out, j, n_channels, k)
    return 1 if k == _BAD else 0


_TABLE_HOOKS = {"nearest": (_nearest_state, _nearest_pair, _nearest_emit),
                "linear": (_linear_state, _linear_pair, _linear_emit)}


def _table_driver(lookup: str):
    """The blocked loop of lookup *lookup* (``"nearest"`` or ``"linear"``), generated once."""
    state, pair, emit = _TABLE_HOOKS[lookup]
    return blocked_driver(state=state, pair=pair, emit=emit, block=_BLOCK)
