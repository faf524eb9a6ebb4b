"""
Directional albedo by lobe-aware deterministic quadrature
=========================================================

a(ω_i) = ∫_Ω f_r(ω_i, ω_o) cos θ_o dω_o (Lewis's k_ρ, eq. 15; Neumann's
albedo) to ~1e-7 absolute, with an error estimate, for lobes as sharp as
Phong n = 10⁴ or Beckmann α = 0.01 and at incidence up to 89.999°.

Method
------
The outgoing hemisphere is parametrised by polar coordinates (t, φ) about
the axis of the model's sharpest lobe (:meth:`BRDF.lobes`):

- ``mirror`` lobes: about the mirror direction R of ω_i,
  ω_o = cos t R + sin t (cos φ e₁ + sin φ e₂), dω_o = sin t dt dφ;
- ``half`` lobes: over the half vector h = (sin t cos φ, sin t sin φ, cos t),
  ω_o = 2(ω_i·h)h − ω_i, dω_o = 4(ω_i·h) sin t dt dφ;
- ``diffuse`` / ``normal`` lobes: about the normal, dω_o = sin t dt dφ.

For each t the azimuths with ω_o above the horizon form one interval
[0, φ_max(t)] whose end is known in closed form (mirror: cos φ_max =
−cot t cot θ_i; half: cos φ_max = −cos θ_i cos 2t/(sin θ_i sin 2t)), so the
horizon cut never falls inside a quadrature panel. In half-vector space the
azimuths where the V-groove G = min(1, 2(N·H)(N·V)/(V·H), 2(N·H)(N·L)/(L·H))
switches branch are also break points (closed forms in :func:`_phi_breaks`).
The t axis is split at the horizon-tangency angles and graded geometrically
at w, 2w, 4w, 8w, then 32w, 128w … for lobe width w. Every panel uses a smoothstep change of
variable (which removes √-type endpoint singularities such as Ward's
1/√(N·V)) and a 15-point Gauss–Kronrod rule in t and in φ; the embedded
7-point Gauss rule gives an error estimate (a QUADPACK-type heuristic, see
:func:`_reduce`). If the
estimate exceeds the tolerance every panel is halved in both directions and
the angle recomputed (up to 5 times).

Isotropic models are integrated over φ ∈ [0, φ_max] and doubled (mirror
symmetry about the plane of incidence); plain callables over both halves.

Public objects
--------------
- :class:`AlbedoResult` — θ_i, albedo, error estimate.
- :func:`albedo` — deterministic albedo of a model or callable.
- :func:`albedo_mc` — importance-sampled Monte-Carlo estimate (cross-check).
- :func:`hemispherical_albedo` — ρ_hh = (1/π) ∫ a(ω_i) cos θ_i dω_i.
- :func:`H_s` — Lewis's specular integral H_s(S) (§4.1, Fig. 5).

References
----------
- [Lewis1993] eqs. (15)–(19), Fig. 5.
- [Neumann1999] §2, Fig. 1.
- R. Piessens et al., QUADPACK (1983): Gauss–Kronrod 7–15 and its error heuristic.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numba
import numpy as np

from brdfkit.errors import BrdfkitError, ParameterError
from brdfkit.models._base import BRDF

__all__ = ["AlbedoResult", "albedo", "albedo_mc", "hemispherical_albedo", "H_s", "lobe_frame"]

NORMAL, MIRROR, HALF = 0, 1, 2
_MODE = {"diffuse": NORMAL, "normal": NORMAL, "mirror": MIRROR, "half": HALF}
MAX_LEVEL = 5
GRADE = 2.0  # geometric grading of the t panels: w, 2w, 4w, 8w, then x4

# 15-point Kronrod nodes (abscissae on [-1, 1], positive half) and weights, with the
# weights of the embedded 7-point Gauss rule (QUADPACK dqk15).
_XGK = np.array([0.991455371120812639206854697526329, 0.949107912342758524526189684047851,
                 0.864864423359769072789712788640926, 0.741531185599394439863864773280788,
                 0.586087235467691130294144845693013, 0.405845151377397166906606412076961,
                 0.207784955007898467600689403773245, 0.000000000000000000000000000000000])
_WGK = np.array([0.022935322010529224963732008058970, 0.063092092629978553290700663189204,
                 0.104790010322250183839876322541518, 0.140653259715525918745189590510238,
                 0.169004726639267902826583426598550, 0.190350578064785409913256402421014,
                 0.204432940075298892414161999234649, 0.209482141084727828012999174891714])
_WG = np.array([0.129484966168869693270611432679082, 0.279705391489276667901467771423780,
                0.381830050505118944950369775488975, 0.417959183673469387755102040816327])


def _unit_rule() -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """GK15 on [0, 1] after the smoothstep map x = 3u² − 2u³ (nodes, Kronrod, Gauss weights)."""
    u = np.concatenate([-_XGK[:-1], _XGK[::-1]])
    wk = np.concatenate([_WGK[:-1], _WGK[::-1]])
    wg = np.zeros(15)
    # Gauss nodes are the odd-indexed Kronrod nodes ±_XGK[1], ±_XGK[3], ±_XGK[5], 0
    for j, i in enumerate((1, 3, 5)):
        wg[i] = wg[14 - i] = _WG[j]
    wg[7] = _WG[3]
    order = np.argsort(u)
    u, wk, wg = (u[order] + 1.0) / 2.0, wk[order] / 2.0, wg[order] / 2.0
    x = 3.0 * u * u - 2.0 * u ** 3
    jac = 6.0 * u * (1.0 - u)
    return x, wk * jac, wg * jac


_X, _WK, _WGAUSS = _unit_rule()


# --------------------------------------------------------------------------- geometry
@numba.njit(cache=True)
def _t_max(mode, theta):
    if mode == MIRROR:
        return math.pi - (0.5 * math.pi - theta) if theta > 0.0 else 0.5 * math.pi
    if mode == HALF:
        return 0.5 * (0.5 * math.pi + theta)
    return 0.5 * math.pi


@numba.njit(cache=True, inline="always")
def _k2_cos(t, s, c):
    """cos φ on the V-groove kink 2(N·H)(N·V) = V·H at half-vector polar angle t (4cos²t > 1)."""
    ct = math.cos(t)
    st = math.sin(t)
    d = 2.0 * ct * c / (4.0 * ct * ct - 1.0)
    return (d - c * ct) / (s * st)


@numba.njit(cache=True)
def _t_breaks(mode, theta, width, out, kv):
    """Sorted break points of the t axis (including 0 and t_max); returns their count."""
    tmax = _t_max(mode, theta)
    e = 0.5 * math.pi - theta  # elevation of ω_i (and of R) above the horizon
    cand = np.empty(64)
    n = 0
    cand[n] = 0.0
    n += 1
    cand[n] = tmax
    n += 1
    if mode == MIRROR:
        cand[n] = e  # circle about R first touches the horizon
        cand[n + 1] = 0.5 * math.pi  # R·V = 0: the max(0, R·V) clamp of Phong-type lobes
        cand[n + 2] = 2.0 * theta  # the curve N·V = N·L (max(N·L, N·V) models) meets φ = 0
        n += 3
    elif mode == HALF:
        cand[n] = 0.5 * e  # the half-vector circle first maps below the horizon
        cand[n + 1] = e  # V-groove kink 2(N·H)(N·L) = L·H reaches φ = 0
        cand[n + 2] = theta  # V-groove kink N·V = N·L reaches φ = 0
        cand[n + 3] = 0.25 * math.pi  # the three V-groove kink curves cross (2cos²t = 1)
        n += 4
        # V-groove kink 2(N·H)(N·V) = V·H reaches φ = 0 or π: roots of k₂(t) = ±1
        s_ = math.sin(theta)
        c_ = math.cos(theta)
        if s_ <= 1e-12:
            cand[n] = math.pi / 6.0  # normal incidence: the kink is the circle 4cos²t = 3
            n += 1
        else:
            m_scan = 256
            t_hi = math.pi / 3.0 - 1e-9  # k₂ exists where 4 cos²t > 1
            prev_t = 1e-9
            prev = _k2_cos(prev_t, s_, c_)
            for j in range(1, m_scan + 1):
                t = 1e-9 + (t_hi - 1e-9) * j / m_scan
                cur = _k2_cos(t, s_, c_)
                for target in (-1.0, 1.0):
                    if (prev - target) * (cur - target) < 0.0 and n < 40:
                        lo, hi = prev_t, t
                        for _ in range(60):
                            mid = 0.5 * (lo + hi)
                            f_lo = _k2_cos(lo, s_, c_) - target
                            if f_lo * (_k2_cos(mid, s_, c_) - target) <= 0.0:
                                hi = mid
                            else:
                                lo = mid
                        cand[n] = 0.5 * (lo + hi)
                        n += 1
                prev = cur
                prev_t = t
    for i in range(kv.shape[0]):
        lev = kv[i]
        if not (lev > -1.0 and lev < 1.0) or n >= 44:
            continue
        # where the curve N·V = lev meets φ = 0 or π (the signed θ_o there is t ∓ θ in the
        # mirror frame, 2t ∓ θ in the half frame), or the circle itself (normal frame)
        to = math.acos(lev)
        if mode == NORMAL:
            cand[n] = to
            n += 1
        else:
            sc = 1.0 if mode == MIRROR else 0.5
            cand[n] = sc * (theta + to)
            cand[n + 1] = sc * abs(theta - to)
            cand[n + 2] = sc * (to - theta)
            n += 3
    w = max(min(width, 0.5 * math.pi), 1e-9)
    b = w
    while b < tmax and n < 62:
        cand[n] = b
        n += 1
        # lobes fall off like exp(−(t/w)²): beyond 8w only the broad part remains
        b *= GRADE if b < 8.0 * w else 2.0 * GRADE
    # sort, keep points inside [0, tmax], drop near-duplicates
    srt = np.sort(cand[:n])
    m = 0
    for i in range(n):
        x = srt[i]
        if x < 0.0 or x > tmax:
            continue
        if m > 0 and x - out[m - 1] <= 1e-13 * (1.0 + tmax):
            continue
        out[m] = x
        m += 1
    if out[m - 1] < tmax:
        out[m] = tmax
        m += 1
    return m


@numba.njit(cache=True)
def _phi_breaks(mode, t, s, c, level, out, nvnl, kv):
    """Break points 0 = b₀ < … < b_k = φ_max of the azimuth at polar angle t; returns k + 1.

    φ_max is where ω_o meets the horizon (closed form). In half-vector mode
    the azimuths where the branches of the V-groove G cross are added:
    2(N·H)(N·L) = L·H, 2(N·H)(N·V) = V·H, and N·V = N·L, each of the form
    cos φ = (d* − c cos t)/(s sin t) for the value d* of ω_i·h on that curve.
    The curves N·V = k for the levels k in ``kv`` (model-declared kinks, see
    :func:`albedo`) are added in the mirror and half frames:
    mirror: N·V = c cos t + s sin t cos φ, so cos φ = (k − c cos t)/(s sin t);
    half: N·V = 2(ω_i·h) cos t − c, so ω_i·h = (k + c)/(2 cos t).
    """
    st = math.sin(t)
    ct = math.cos(t)
    if mode == NORMAL:
        out[0] = 0.0
        out[1] = math.pi
        return 2
    if mode == MIRROR:
        num = -ct * c
        den = st * s
    else:
        num = -c * (ct * ct - st * st)  # −cos θ cos 2t
        den = s * 2.0 * st * ct  # sin θ sin 2t
    if den <= 1e-300:
        # normal incidence or t = 0: the whole circle is above the horizon iff num < 0
        phimax = math.pi if num < 0.0 else 0.0
    else:
        c0 = num / den
        if c0 <= -1.0:
            phimax = math.pi
        elif c0 >= 1.0:
            phimax = 0.0
        else:
            phimax = math.acos(c0)
    out[0] = 0.0
    k = 1
    if mode == MIRROR and (level >= 1 or nvnl) and s * st > 1e-300 and phimax > 0.0:
        # N·V = N·L: c cos t + s sin t cos φ = c ⇔ cos φ = (c/s) tan(t/2); kink of
        # max(N·L, N·V) denominators (Neumann eq. 22). Only from the first refinement
        # on: most mirror-lobe models are smooth there, and level 0 is the fast path.
        cp = c * (1.0 - ct) / (s * st)
        if -1.0 < cp < 1.0:
            ph = math.acos(cp)
            if 1e-12 < ph < phimax - 1e-12:
                out[k] = ph
                k += 1
    if mode != NORMAL and s * st > 1e-300 and phimax > 0.0:
        for i in range(kv.shape[0]):
            lev = kv[i]
            if not (lev > -1.0 and lev < 1.0) or k >= out.shape[0] - 8:
                continue  # NaN: no kink at this angle
            if mode == MIRROR:
                cp = (lev - c * ct) / (s * st)
            else:
                if ct <= 0.0:
                    continue
                cp = ((lev + c) / (2.0 * ct) - c * ct) / (s * st)
            if -1.0 < cp < 1.0:
                ph = math.acos(cp)
                dup = False
                for q in range(1, k):
                    if abs(out[q] - ph) <= 1e-12:
                        dup = True
                if not dup and 1e-12 < ph < phimax - 1e-12:
                    out[k] = ph
                    k += 1
    if mode == HALF and s * st > 1e-300 and phimax > 0.0:
        dstar = np.empty(3)
        nd = 0
        dstar[nd] = 2.0 * ct * c  # 2(N·H)(N·L) = L·H
        nd += 1
        dstar[nd] = c / ct if ct > 0.0 else -1.0  # N·V = N·L: 2 d cos t − c = c
        nd += 1
        if 4.0 * ct * ct > 1.0:
            dstar[nd] = 2.0 * ct * c / (4.0 * ct * ct - 1.0)  # 2(N·H)(N·V) = V·H
            nd += 1
        for i in range(nd):
            cp = (dstar[i] - c * ct) / (s * st)
            if -1.0 < cp < 1.0:
                ph = math.acos(cp)
                if 1e-12 < ph < phimax - 1e-12:
                    out[k] = ph
                    k += 1
    # insertion sort of out[1:k]
    for i in range(2, k):
        v = out[i]
        j = i - 1
        while j >= 1 and out[j] > v:
            out[j + 1] = out[j]
            j -= 1
        out[j + 1] = v
    out[k] = phimax
    return k + 1


@numba.njit(cache=True, inline="always")
def _direction(mode, st, ct, phi, s, c):
    """ω_o at (t, φ) (given sin t, cos t) and dω_o/(dt dφ)·cos θ_o (0 below the horizon)."""
    sp = math.sin(phi)
    cp = math.cos(phi)
    if mode == MIRROR:
        # R = (−s, 0, c), e₁ = (c, 0, s), e₂ = (0, 1, 0)
        ox = -s * ct + st * cp * c
        oy = st * sp
        oz = c * ct + st * cp * s
        jac = st
    elif mode == HALF:
        hx = st * cp
        hy = st * sp
        d = s * hx + c * ct  # ω_i·h
        ox = 2.0 * d * hx - s
        oy = 2.0 * d * hy
        oz = 2.0 * d * ct - c
        jac = 4.0 * d * st
        if d <= 0.0:
            jac = 0.0
    else:
        ox = st * cp
        oy = st * sp
        oz = ct
        jac = st
    if oz <= 0.0:
        return ox, oy, 0.0, 0.0  # rounding at the horizon: contributes nothing
    return ox, oy, oz, jac * oz


@numba.njit(cache=True)
def _count_nodes(mode, theta, width, level, sym, X, nvnl, kv):
    """Exact number of nodes :func:`_gen_nodes` writes, and the number of error pieces."""
    tb = np.empty(64)
    pb = np.empty(16 + kv.shape[0])
    nt = _t_breaks(mode, theta, width, tb, kv)
    sub = 1 << level
    n_int = (5 if mode == HALF else 2) + kv.shape[0]
    halves = 1 if sym else 2
    s = math.sin(theta)
    c = math.cos(theta)
    n = 0
    for ip in range(nt - 1):
        for q in range(sub):
            a = tb[ip] + (tb[ip + 1] - tb[ip]) * q / sub
            b = tb[ip] + (tb[ip + 1] - tb[ip]) * (q + 1) / sub
            for it in range(15):
                k = _phi_breaks(mode, a + (b - a) * X[it], s, c, level, pb, nvnl, kv)
                n += min(k - 1, n_int) * sub * 15 * halves
    return n, (nt - 1) * sub * halves


@numba.njit(cache=True, error_model="numpy", fastmath={"nsz", "arcp", "contract"})
def _gen_nodes(mode, theta, width, level, sym, X, WK, WG, wo, wk, wg, piece, nvnl, kv):
    """Fill the nodes of one incidence angle; returns the number written.

    wo (N, 3), wk / wg (N,) Kronrod / Gauss weights including the measure and
    cos θ_o, piece (N,) the 2-D panel each node belongs to.
    """
    s = math.sin(theta)
    c = math.cos(theta)
    tb = np.empty(64)
    nt = _t_breaks(mode, theta, width, tb, kv)
    sub = 1 << level
    n_int = (5 if mode == HALF else 2) + kv.shape[0]
    halves = 1 if sym else 2
    fac = 2.0 if sym else 1.0
    pb = np.empty(16 + kv.shape[0])
    n = 0
    tp = 0
    for ip in range(nt - 1):
        for q in range(sub):
            a = tb[ip] + (tb[ip + 1] - tb[ip]) * q / sub
            b = tb[ip] + (tb[ip + 1] - tb[ip]) * (q + 1) / sub
            for it in range(15):
                t = a + (b - a) * X[it]
                wtk = WK[it] * (b - a)
                wtg = WG[it] * (b - a)
                k = _phi_breaks(mode, t, s, c, level, pb, nvnl, kv)
                st = math.sin(t)
                ct = math.cos(t)
                for h in range(halves):
                    sign = 1.0 if h == 0 else -1.0
                    for j in range(n_int):
                        if j >= k - 1:
                            break  # no more azimuth intervals at this t: write no nodes
                        pa = pb[j]
                        pz = pb[j + 1]
                        for r in range(sub):
                            fa = pa + (pz - pa) * r / sub
                            fb = pa + (pz - pa) * (r + 1) / sub
                            # one error piece per t sub-panel and half: the azimuth break
                            # points move with t, so only the strip's total is smooth in t
                            pid = tp * halves + h
                            for iph in range(15):
                                phi = sign * (fa + (fb - fa) * X[iph])
                                ox, oy, oz, jac = _direction(mode, st, ct, phi, s, c)
                                wo[n, 0] = ox
                                wo[n, 1] = oy
                                wo[n, 2] = oz
                                wk[n] = fac * jac * wtk * WK[iph] * (fb - fa)
                                wg[n] = fac * jac * wtg * WG[iph] * (fb - fa)
                                piece[n] = pid
                                n += 1
            tp += 1
    return n


@numba.njit(cache=True)
def _reduce(vals, wk, wg, piece, n_pieces, n, C, out_a, out_e):
    """Sum the Kronrod estimate and the QUADPACK-style error over the panels."""
    K = np.zeros((n_pieces, C))
    G = np.zeros((n_pieces, C))
    A = np.zeros((n_pieces, C))
    for i in range(n):
        p = piece[i]
        for ch in range(C):
            v = vals[i, ch]
            K[p, ch] += wk[i] * v
            G[p, ch] += wg[i] * v
            A[p, ch] += abs(wk[i] * v)
    for ch in range(C):
        tot = 0.0
        err = 0.0
        for p in range(n_pieces):
            tot += K[p, ch]
            d = abs(K[p, ch] - G[p, ch])
            if A[p, ch] > 0.0 and d > 0.0:
                # |K − G| estimates the error of the 7-point Gauss rule; for an analytic
                # integrand the 15-point Kronrod error is ~ A (|K − G|/A)^(23/14) (orders
                # 14 and 23 on a panel). We take the exponent 1.5 (QUADPACK's, without
                # its factor 200^1.5, which overestimates by ~1e5 here; see the tests
                # against closed forms) and never more than |K − G| itself.
                r = d / A[p, ch]
                # ... but at least 2% of |K − G|: a kink inside a panel (a clamp the
                # break points do not know about) makes the Kronrod rule only a little
                # better than the Gauss rule
                err += min(d, max(A[p, ch] * r * math.sqrt(r), 0.02 * d))
        out_a[ch] = tot
        out_e[ch] = err + 1e-15 * abs(tot)  # floor: rounding of the sum


def _gen_all_py(mode, thetas, width, levels, sym, X, WK, WG, offsets, wo, wk, wg, piece,
                nvnl, kvs):
    """Nodes of every angle i at its level, written at offsets[i] (parallel over angles)."""
    for i in numba.prange(thetas.shape[0]):
        o = offsets[i]
        m = offsets[i + 1] - o
        n = _gen_nodes(mode, thetas[i], width, levels[i], sym, X, WK, WG, wo[o:o + m],
                       wk[o:o + m], wg[o:o + m], piece[o:o + m], nvnl, kvs[i])
        for j in range(n, m):  # unused slots (absent azimuth intervals): weight 0
            wo[o + j, 0] = 0.0
            wo[o + j, 1] = 0.0
            wo[o + j, 2] = 0.0  # z = 0: skipped by the evaluator, contributes 0
            wk[o + j] = 0.0
            wg[o + j] = 0.0
            piece[o + j] = 0


def _reduce_all_py(vals, wk, wg, piece, offsets, npieces, out_a, out_e):
    for i in numba.prange(offsets.shape[0] - 1):
        o = offsets[i]
        m = offsets[i + 1] - o
        _reduce(vals[o:o + m], wk[o:o + m], wg[o:o + m], piece[o:o + m], npieces[i], m,
                vals.shape[1], out_a[i], out_e[i])


# Serial and parallel builds: a parallel region costs a thread rendezvous, which on a
# busy machine (or for ~1e5 nodes) is slower than doing the work on one core.
_gen_all_serial = numba.njit(cache=True, error_model="numpy")(_gen_all_py)
_gen_all_parallel = numba.njit(cache=True, parallel=True)(_gen_all_py)
_reduce_all_serial = numba.njit(cache=True)(_reduce_all_py)
_reduce_all_parallel = numba.njit(cache=True, parallel=True)(_reduce_all_py)
PARALLEL_NODES = 2_000_000


# Not cached: a specialisation is keyed on the kernel's dispatcher, new in every
# process, so an on-disk entry is never reused (same reason as models.eval_pairs).
# Serial: compiles in ~0.3 s per model instead of ~1 s for a prange loop (this
# matters for Table 2, which compiles it for every registered model).
@numba.njit
def _eval_kernel(kernel, P, thetas, offsets, wo, vals):  # pragma: no cover - compiled
    """vals[j, c] = kernel(ω_i(θ of j), wo[j], P[c]); NaN/inf replaced by 0."""
    for i in range(thetas.shape[0]):
        ix = math.sin(thetas[i])
        iz = math.cos(thetas[i])
        for j in range(offsets[i], offsets[i + 1]):
            for ch in range(P.shape[0]):
                if wo[j, 2] <= 0.0:
                    vals[j, ch] = 0.0
                    continue
                v = kernel(ix, 0.0, iz, wo[j, 0], wo[j, 1], wo[j, 2], P[ch])
                vals[j, ch] = v if math.isfinite(v) else 0.0  # guard: never propagate NaN


@numba.njit
def _eval_pairs_guarded(kernel, wi, wo, P, out):  # pragma: no cover - compiled
    """:func:`brdfkit.models.eval_pairs` for the integrator: serial (cheaper to compile,
    see :func:`_eval_kernel`) and with NaN/inf replaced by 0, so one bad node of a user
    callable cannot poison a whole albedo."""
    for j in range(wi.shape[0]):
        for ch in range(P.shape[0]):
            v = kernel(wi[j, 0], wi[j, 1], wi[j, 2], wo[j, 0], wo[j, 1], wo[j, 2], P[ch])
            out[j, ch] = v if math.isfinite(v) else 0.0


def evaluate_pairs(model, wi: np.ndarray, wo: np.ndarray) -> np.ndarray:
    """f_r(wi, wo) for (N, 3) arrays → (N, C) (C = 1 for scalar models).

    Compiled models run their kernel directly; anything else is called.
    """
    wi = np.ascontiguousarray(np.broadcast_to(wi, np.broadcast_shapes(wi.shape, wo.shape)),
                              dtype=np.float64)
    wo = np.ascontiguousarray(np.broadcast_to(wo, wi.shape), dtype=np.float64)
    if _is_compiled(model):
        P = np.ascontiguousarray(np.asarray(model.packed, dtype=np.float64))
        out = np.empty((wi.shape[0], P.shape[0]))
        _eval_pairs_guarded(model.kernel, wi, wo, P, out)
        return out
    return np.asarray(model(wi, wo), dtype=np.float64).reshape(wi.shape[0], -1)


#: Memory bounds of :func:`_integrate`: nodes evaluated per call of ``evaluate`` (about
#: 56 + 8C bytes each for a compiled model, ~3x that for a callable) and the most nodes one
#: angle may use. Level 5 of a sharp mirror lobe needs ~9e6 nodes per angle (a table of 64
#: angles at once allocated 19 GB before the bound); past the bound the previous level's
#: result and its error estimate are returned.
MAX_CHUNK_NODES = 3_000_000
MAX_ANGLE_NODES = 6_000_000


def _integrate_chunk(evaluate, th, mode, width, level, sym, nvnl, kvs, counts, npieces, a, e,
                     idx, tol) -> np.ndarray:
    """One level for the angles ``th`` (results written to a[idx], e[idx]); returns the
    mask of angles whose error estimate is still above the goal."""
    th = np.ascontiguousarray(th)
    lv = np.full(th.size, level, dtype=np.int64)
    offsets = np.zeros(th.size + 1, dtype=np.int64)
    np.cumsum(counts, out=offsets[1:])
    total = int(offsets[-1])
    wo = np.empty((total, 3))
    wk = np.empty(total)
    wg = np.empty(total)
    piece = np.empty(total, dtype=np.int64)
    big = total >= PARALLEL_NODES
    gen = _gen_all_parallel if big else _gen_all_serial
    gen(mode, th, width, lv, sym, _X, _WK, _WGAUSS, offsets, wo, wk, wg, piece, nvnl,
        np.ascontiguousarray(kvs))
    vals = np.ascontiguousarray(evaluate(th, offsets, wo), dtype=np.float64)
    del wo
    aa = np.empty((th.size, vals.shape[1]))
    ee = np.empty_like(aa)
    red = _reduce_all_parallel if big else _reduce_all_serial
    red(vals, wk, wg, piece, offsets, np.ascontiguousarray(npieces), aa, ee)
    a[idx] = aa
    e[idx] = ee
    return np.any(ee > np.maximum(tol, 1e-10 * np.abs(aa)), axis=1)


def _integrate(evaluate, thetas: np.ndarray, mode: int, width: float, sym: bool, tol: float,
               n_channels: int, nvnl: bool = False, kinks: np.ndarray | None = None
               ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Level loop shared by the compiled and the callable paths.

    ``evaluate(thetas, offsets, wo) -> vals (N, C)`` evaluates f at the nodes.
    """
    n = thetas.size
    kvs = np.full((n, 0), np.nan) if kinks is None else np.asarray(kinks, dtype=np.float64)
    a = np.zeros((n, n_channels))
    e = np.full((n, n_channels), np.inf)
    levels = np.zeros(n, dtype=np.int64)
    todo = np.arange(n)
    for level in range(MAX_LEVEL + 1):
        counts = np.empty(todo.size, dtype=np.int64)
        npieces = np.empty(todo.size, dtype=np.int64)
        for k, t in enumerate(thetas[todo]):
            counts[k], npieces[k] = _count_nodes(mode, float(t), width, level, sym, _X, nvnl,
                                                 kvs[todo[k]])
        if level > 0:
            # memory bound: an angle whose next level needs more than MAX_ANGLE_NODES keeps
            # the previous level's estimate and its (larger, honest) error estimate
            fits = counts <= MAX_ANGLE_NODES
            todo, counts, npieces = todo[fits], counts[fits], npieces[fits]
            if todo.size == 0:
                break
        # angles in chunks of at most MAX_CHUNK_NODES nodes (one angle may exceed it alone)
        start = 0
        still = []
        while start < todo.size:
            stop = start + 1
            acc = int(counts[start])
            while stop < todo.size and acc + int(counts[stop]) <= MAX_CHUNK_NODES:
                acc += int(counts[stop])
                stop += 1
            idx = todo[start:stop]
            bad = _integrate_chunk(evaluate, thetas[idx], mode, width, level, sym, nvnl, kvs[idx],
                                   counts[start:stop], npieces[start:stop], a, e, idx, tol)
            levels[idx] = level
            still.append(idx[bad])
            start = stop
        todo = np.concatenate(still) if still else todo[:0]
        if todo.size == 0:
            break
    return a, e, levels


# --------------------------------------------------------------------------- public API
@dataclass(frozen=True)
class AlbedoResult:
    """Directional albedo at the incidence angles θ_i.

    Attributes
    ----------
    theta : ndarray
        θ_i in radians (shape of the input; 0-d for a scalar).
    albedo : ndarray
        a(θ_i), shape ``theta.shape`` or ``theta.shape + (C,)`` for coloured models.
    error : ndarray
        Error estimate (absolute), same shape as ``albedo``.
    """

    theta: np.ndarray
    albedo: np.ndarray
    error: np.ndarray

    def to_dict(self) -> dict:
        """JSON-ready: θ in degrees, albedo and error (per-channel lists when coloured)."""
        return {"theta_deg": np.degrees(self.theta).tolist(),
                "albedo": np.asarray(self.albedo).tolist(),
                "error": np.asarray(self.error).tolist()}


def lobe_frame(model) -> tuple[int, float]:
    """(mode, width) of the integration frame: the frame of the sharpest lobe."""
    lobes = model.lobes() if hasattr(model, "lobes") else []
    if not lobes:
        return NORMAL, math.pi / 2
    best = min(lobes, key=lambda lb: lb.width)
    kinds = {lb.kind for lb in lobes}
    mode = _MODE.get(best.kind, NORMAL)
    width = float(best.width)
    if not math.isfinite(width) or width <= 0.0:
        width = math.pi / 2
    if mode == NORMAL and ("mirror" in kinds or "half" in kinds):
        mode = _MODE[next(lb.kind for lb in lobes if lb.kind in ("mirror", "half"))]
    return mode, min(width, math.pi / 2)


#: Registered models whose formula has a max(N·L, N·V) (Neumann et al. eq. 22): their
#: kink N·V = N·L is a break point from the start. Other models can declare
#: ``albedo_kinks = ("nv=nl",)``; any model gets it from the first refinement on.
NVNL_KINK_MODELS = frozenset({"neumann-phong"})


def _has_nvnl_kink(model) -> bool:
    return getattr(model, "name", None) in NVNL_KINK_MODELS or \
        "nv=nl" in tuple(getattr(model, "albedo_kinks", ()))


MAX_KINKS = 12


def _declared_kinks(model, flat: np.ndarray) -> np.ndarray | None:
    """The model's ``albedo_kinks_nv(theta) -> (T, K)`` levels k of N·V where its
    integrand has a kink (NaN: none), or None."""
    kv = model.albedo_kinks_nv(flat)
    if kv is None:
        return None
    kv = np.asarray(kv, dtype=np.float64).reshape(flat.size, -1)
    if kv.shape[1] > MAX_KINKS:
        # keep the engine's break-point arrays small: the rest is left to refinement
        kv = kv[:, :MAX_KINKS]
    return np.ascontiguousarray(kv)


def _check_theta(theta_i) -> np.ndarray:
    th = np.asarray(theta_i, dtype=np.float64)
    if not np.all(np.isfinite(th)):
        raise ParameterError("theta_i must be finite (radians)")
    if np.any((th < 0.0) | (th >= math.pi / 2)):
        bad = th[(th < 0.0) | (th >= math.pi / 2)].flat[0]
        raise ParameterError(
            f"theta_i must lie in [0, pi/2) radians = [0, 90) degrees; got {bad!r} rad")
    return th


def _check_tol(tol: float) -> float:
    try:
        t = float(tol)
    except (TypeError, ValueError):
        raise ParameterError(f"tol must be a positive number; got {tol!r}") from None
    if not (t > 0.0 and math.isfinite(t)):
        raise ParameterError(f"tol must be a positive number; got {tol!r}")
    return t


def _is_compiled(model) -> bool:
    kernel = getattr(model, "kernel", None)
    return hasattr(model, "packed") and hasattr(kernel, "py_func")  # a Numba dispatcher


def albedo(model, theta_i, *, tol: float = 1e-7, mode: str | None = None,
           width: float | None = None) -> AlbedoResult:
    """Directional albedo a(θ_i) = ∫ f_r(ω_i, ω_o) cos θ_o dω_o, deterministic.

    Parameters
    ----------
    model : BRDF or callable
        A brdfkit model (integrated through its compiled kernel, in the frame
        of its sharpest lobe) or any callable ``f(wi, wo) -> array`` taking
        broadcastable (..., 3) arrays and returning (...) or (..., C).
        ω_i lies in the xz-plane at azimuth 0.
    theta_i : float or array_like
        Incidence angles in radians, in [0, π/2).
    tol : float, keyword-only
        Absolute accuracy goal (default 1e-7). Panels are halved until the
        error estimate meets it (or a relative 1e-10), at most 5 times.
    mode : {"diffuse", "mirror", "half"}, optional
        Override the integration frame (default: from ``model.lobes()``;
        ``diffuse`` for callables without ``lobes``).
    width : float, optional
        Override the lobe width (radians) that grades the panels.

    Returns
    -------
    AlbedoResult
        ``theta``, ``albedo`` and ``error`` (absolute error estimate).
        Models with a ``specular_albedo(theta)`` method (a delta term not in
        the kernel, e.g. He–Torrance) have it added, with no extra error.

    Notes
    -----
    A model can declare kinks of its integrand on curves N·V = k (constant
    θ_o, e.g. N·V = N·L for max(N·L, N·V) terms, or the levels where a pumped
    model's g switches branch) with a method ``albedo_kinks_nv(theta) -> (T, K)``
    giving for each θ_i up to 12 levels k (NaN for none); they become panel
    edges in every frame (closed forms in :func:`_phi_breaks`), so the error
    estimate stays honest. At most 6e6 nodes are used per angle
    (``MAX_ANGLE_NODES``): an angle needing more keeps the last level's result
    and its (larger) error estimate.

    Examples
    --------
    >>> import brdfkit, numpy as np
    >>> from brdfkit.analysis import albedo
    >>> r = albedo(brdfkit.model("lambert", rho_d=0.5), np.radians([0, 60, 89]))
    >>> np.allclose(r.albedo, 0.5)
    True
    """
    th = _check_theta(theta_i)
    tol = _check_tol(tol)
    m_mode, m_width = lobe_frame(model)
    if mode is not None:
        if mode not in _MODE:
            raise ParameterError(f"mode must be one of {', '.join(_MODE)}; got {mode!r}")
        m_mode = _MODE[mode]
    if width is not None:
        if not (float(width) > 0.0):
            raise ParameterError(f"width must be > 0 radians; got {width!r}")
        m_width = float(width)
    flat = np.ascontiguousarray(th.reshape(-1))
    if _is_compiled(model):
        P = np.ascontiguousarray(np.asarray(model.packed, dtype=np.float64))
        sym = bool(getattr(model, "isotropic", True))
        kernel = model.kernel

        def evaluate(th, offsets, wo):
            vals = np.empty((wo.shape[0], P.shape[0]))
            _eval_kernel(kernel, P, th, offsets, wo, vals)
            return vals

        a, e, _ = _integrate(evaluate, flat, m_mode, m_width, sym, tol, P.shape[0],
                             _has_nvnl_kink(model),
                             _declared_kinks(model, flat) if isinstance(model, BRDF) else None)
        coloured = getattr(model, "n_channels", None) is not None
    elif callable(model):
        a, e, coloured = _albedo_callable(model, flat, m_mode, m_width, tol)
    else:
        raise BrdfkitError(f"albedo: model must be a BRDF or a callable f(wi, wo); got "
                           f"{type(model).__name__}")
    extra = model.specular_albedo(flat) if isinstance(model, BRDF) else None
    if extra is not None:
        a = a + np.asarray(extra, dtype=np.float64).reshape(flat.size, -1)
    if coloured:
        shape = th.shape + (a.shape[1],)
    else:
        a, e = a[:, 0], e[:, 0]
        shape = th.shape
    return AlbedoResult(theta=th.copy(), albedo=a.reshape(shape), error=e.reshape(shape))


def _albedo_callable(f: Callable, flat: np.ndarray, mode: int, width: float, tol: float):
    """Same rule as the compiled path; nodes built in Numba, f evaluated vectorised."""
    shape_info = {}

    def evaluate(th, offsets, wo):
        idx = np.repeat(np.arange(th.size), np.diff(offsets))
        up = wo[:, 2] > 0.0  # unused slots and rounding below the horizon: not evaluated
        wi = np.stack([np.sin(th[idx]), np.zeros(idx.size), np.cos(th[idx])], axis=-1)[up]
        got = np.asarray(f(wi, np.ascontiguousarray(wo[up])), dtype=np.float64)
        if got.shape[:1] != (wi.shape[0],) or got.ndim > 2:
            raise BrdfkitError(f"albedo: the callable returned shape {got.shape} for "
                               f"{wi.shape[0]} direction pairs; expected (N,) or (N, C)")
        shape_info["coloured"] = got.ndim == 2
        got = np.where(np.isfinite(got), got, 0.0).reshape(wi.shape[0], -1)
        vals = np.zeros((wo.shape[0], got.shape[1]))
        vals[up] = got
        return vals

    probe = evaluate(np.array([0.0]), np.array([0, 1]), np.array([[0.0, 0.0, 1.0]]))
    a, e, _ = _integrate(evaluate, flat, mode, width, False, tol, probe.shape[1])
    return a, e, shape_info["coloured"]


# --------------------------------------------------------------------------- Monte Carlo
def albedo_mc(model, theta_i, *, n_samples: int = 100_000, rng=None,
              defensive: float = 0.1) -> AlbedoResult:
    """Importance-sampled Monte-Carlo albedo with its standard error.

    Directions are drawn from the mixture (1 − δ)·model.sample(·| ω_i) + δ·cos θ/π
    (δ = ``defensive``; the cosine part keeps the estimator unbiased where the
    model's sampler misses part of the support), and the estimator is
    f(ω_i, ω) cos θ / pdf_mix(ω). Callables use cosine sampling only.

    Parameters
    ----------
    model : BRDF or callable
    theta_i : float or array_like
        Radians in [0, π/2).
    n_samples : int, keyword-only
        Samples per angle.
    rng : int or numpy.random.Generator, keyword-only
        Seed or generator (required for reproducibility; None draws fresh entropy).
    defensive : float, keyword-only
        Weight of the cosine component in (0, 1].

    Returns
    -------
    AlbedoResult
        ``error`` is the standard error of the mean (1σ).
    """
    from brdfkit.geometry import pdf_cosine_hemisphere, sample_cosine_hemisphere

    th = _check_theta(theta_i)
    n_samples = int(n_samples)
    if n_samples < 2:
        raise ParameterError(f"n_samples must be >= 2; got {n_samples}")
    if not (0.0 < defensive <= 1.0):
        raise ParameterError(f"defensive must lie in (0, 1]; got {defensive!r}")
    gen = rng if isinstance(rng, np.random.Generator) else np.random.default_rng(rng)
    has_sampler = bool(getattr(model, "has_sampler", False)) and hasattr(model, "sample")
    if not has_sampler:
        defensive = 1.0
    vals_a, vals_e = [], []
    for theta in th.reshape(-1):
        wi = np.array([math.sin(theta), 0.0, math.cos(theta)])
        u = gen.random((n_samples, 2))
        pick = gen.random(n_samples) < defensive
        w = sample_cosine_hemisphere(u)
        if has_sampler:
            ws, _ = model.sample(np.broadcast_to(wi, (n_samples, 3)), u)
            w = np.where(pick[:, None], w, ws)
        wib = np.broadcast_to(wi, w.shape)
        pdf = defensive * pdf_cosine_hemisphere(w)
        if has_sampler:
            pdf = pdf + (1.0 - defensive) * model.pdf(w, wib)
        up = (w[:, 2] > 0.0) & (pdf > 0.0)
        w_safe = np.where(up[:, None], w, np.array([0.0, 0.0, 1.0]))
        f = evaluate_pairs(model, wib, w_safe)
        est = np.where(up[:, None], f * (w_safe[:, 2] / np.where(up, pdf, 1.0))[:, None], 0.0)
        vals_a.append(est.mean(axis=0))
        vals_e.append(est.std(axis=0, ddof=1) / math.sqrt(n_samples))
    a = np.array(vals_a)
    e = np.array(vals_e)
    extra = model.specular_albedo(th.reshape(-1)) if isinstance(model, BRDF) else None
    if extra is not None:
        a = a + np.asarray(extra, dtype=np.float64).reshape(a.shape[0], -1)
    if getattr(model, "n_channels", None) is None and a.shape[1] == 1:
        return AlbedoResult(th.copy(), a[:, 0].reshape(th.shape), e[:, 0].reshape(th.shape))
    return AlbedoResult(th.copy(), a.reshape(th.shape + (-1,)), e.reshape(th.shape + (-1,)))


# --------------------------------------------------------------------------- ρ_hh and H_s
def hemispherical_albedo(model, *, n: int = 48, tol: float = 1e-7) -> tuple[np.ndarray,
                                                                           np.ndarray]:
    """Hemispherical–hemispherical albedo ρ_hh = (1/π) ∫ a(ω_i) cos θ_i dω_i.

    With μ = cos θ_i = u², ρ_hh = ∫₀¹ a(μ) 2μ dμ = ∫₀¹ 4 a(u²) u³ du, computed with
    n-point Gauss–Legendre in u (smooth even when a ∝ μ^−p near grazing), and the
    n/2-point rule for the error estimate.

    Returns
    -------
    (value, error) : ndarrays, scalars or (C,) for coloured models.
    """
    x, w = np.polynomial.legendre.leggauss(int(n))
    x2, w2 = np.polynomial.legendre.leggauss(int(n) // 2)
    us = np.concatenate([(x + 1) / 2, (x2 + 1) / 2])
    th = np.arccos(np.clip(us * us, 0.0, 1.0))
    th = np.minimum(th, math.pi / 2 - 1e-12)  # the node nearest grazing stays inside [0, π/2)
    r = albedo(model, th, tol=tol)
    a = np.asarray(r.albedo)
    wt = 4.0 * us ** 3
    wt = wt.reshape(wt.shape + (1,) * (a.ndim - 1))
    aw = a * wt
    v1 = np.tensordot(w / 2, aw[: len(x)], axes=(0, 0))
    v2 = np.tensordot(w2 / 2, aw[len(x):], axes=(0, 0))
    ew = np.asarray(r.error)[: len(x)] * wt[: len(x)]
    return v1, np.abs(v1 - v2) + np.tensordot(w / 2, ew, axes=(0, 0))


def H_s(theta_i, n: float, *, lobe: str = "phong", tol: float = 1e-8) -> AlbedoResult:
    """Lewis's specular integral H_s(S) = ∫ F_s(S, V) (N·V) dω_V (§4.1, Fig. 5).

    The albedo of Lewis's specular function alone, computed by the one H_s
    implementation, :func:`brdfkit.models.specular.specular_integral_with_error`
    (azimuth in closed form, tanh-sinh in the polar angle; ~1e-11 relative),
    not by the albedo engine. (The engine gives the same numbers for the
    registered models whose BRDF is F_s itself: ``lafortune`` with ρ_d = 0,
    ρ_s = 1, C_xy = −1, C_z = 1 is F_s^P, ``phong-blinn-reciprocal`` with
    k_d = 0, k_s = 1 is F_s^B; the tests compare the two.)

    Parameters
    ----------
    theta_i : float or array_like
        Incidence angle(s) of S, radians in [0, π/2).
    n : float
        Specular exponent n_s ≥ 0.
    lobe : {"phong", "blinn"}, keyword-only
        F_s^P = max(0, R·V)^n (eq. 5) or F_s^B = (N·H)^n (eq. 6).
    tol : float, keyword-only
        Absolute accuracy goal (> 0). The quadrature's own accuracy (~1e-11
        relative, H_s ≤ π) meets any goal above ~1e-10; ``error`` states what
        was reached.

    Returns
    -------
    AlbedoResult
        ``albedo`` holds H_s, ``error`` its absolute error estimate (the
        difference from the rule of twice the step plus rounding, a bound in
        practice). Lewis eq. (19): k_ρ = k_d π + k_s H_s/(N·S). At θ_i = 0
        with the Phong lobe, H_s = 2π/(n + 2) (eq. 16 with γ = n + 1).
    """
    # imported here: the rest of this module is the engine and does not need it
    from brdfkit.models.specular import specular_integral_with_error

    if lobe not in ("phong", "blinn"):
        raise ParameterError(f"lobe must be 'phong' or 'blinn'; got {lobe!r}")
    n = float(n)
    if not (n >= 0.0 and math.isfinite(n)):
        raise ParameterError(f"n must be a finite number >= 0; got {n!r}")
    th = _check_theta(theta_i)
    _check_tol(tol)
    value, error = specular_integral_with_error(th, n, lobe)
    return AlbedoResult(theta=th.copy(), albedo=value, error=error)
