"""
Panels, nodes and reduction of the albedo quadrature (the compiled core)
=========================================================================

The node generator and the error reduction behind
:func:`brdfkit.analysis.albedo` (the method is described in the docstring of
:mod:`brdfkit.analysis.albedo_engine`): break points of the polar axis t
(:func:`_t_breaks`) and of the azimuth (:func:`_phi_breaks`) in the mirror,
half-vector and normal frames, Gauss–Kronrod 7/15 nodes after a smoothstep
change of variable, and the QUADPACK-type error per panel (:func:`_reduce`).
Numba-compiled; no model is known here: declared kinks arrive as bit flags
(:data:`KINK_NVNL`, :data:`KINK_VGROOVE`) and per-angle levels of N·V.

References
----------
- R. Piessens et al., QUADPACK (1983): Gauss–Kronrod 7–15 and its error heuristic.
"""

from __future__ import annotations

import math

import numba
import numpy as np

NORMAL, MIRROR, HALF = 0, 1, 2
#: Bits of the ``kinks`` flags passed to the node generators, from the model's declared
#: :attr:`~brdfkit.models.BRDF.albedo_kinks`: the curve N·V = N·L (a max(N·L, N·V) in the
#: formula) and the three curves where the branches of the V-groove G cross.
KINK_NVNL, KINK_VGROOVE = 1, 2
_KINK_BITS = {"nv=nl": KINK_NVNL, "vgroove": KINK_VGROOVE}
_MODE = {"diffuse": NORMAL, "normal": NORMAL, "mirror": MIRROR, "half": HALF}
MAX_LEVEL = 5
GRADE = 2.0  # geometric grading of the t panels: w, 2w, 4w, 8w, then x4
#: An elongated half-vector lobe (:func:`_axis_breaks`): azimuth break points at each crest
#: ψ₀ and at ψ₀ ± 3w (e^{−9} ≈ 1e-4 of the crest for e^{−x}: the crest in two panels, its
#: tails in the next ones; ±w, ±2w, ±4w were tried: 1.6x the nodes, the same level-0
#: convergence). AXIS_BREAKS: the most azimuth break points this adds per half (2 crests).
AXIS_GRADES = (3.0,)
AXIS_BREAKS = 2 * (1 + 2 * len(AXIS_GRADES))

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
def _t_breaks(mode, theta, width, out, kv, kinks, az):
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
        n += 1
    if mode == HALF and kinks & KINK_VGROOVE:
        cand[n] = e  # V-groove kink 2(N·H)(N·L) = L·H reaches φ = 0
        cand[n + 1] = theta  # V-groove kink N·V = N·L reaches φ = 0
        cand[n + 2] = 0.25 * math.pi  # the three V-groove kink curves cross (2cos²t = 1)
        n += 3
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
    if mode == HALF and az[1] > 0.0 and az[2] > 0.0 and az[1] != az[2]:
        # an elongated lobe (_axis_breaks): where a crest (azimuth u₀ in a half, fixed in t)
        # meets the horizon azimuth φ_max(t), cot 2t = −tan θ cos u₀, the strip's integral
        # drops steeply (the crest leaves the visible range): a break of t
        psi0 = 0.5 * math.pi if az[2] > az[1] else 0.0
        for crest in range(2):
            for sign in (1.0, -1.0):
                u0 = sign * (psi0 + crest * math.pi - az[0])
                u0 = u0 - 2.0 * math.pi * math.floor((u0 + math.pi) / (2.0 * math.pi))
                if 0.0 < u0 < math.pi and n < 60:
                    cand[n] = 0.5 * math.atan2(1.0, -math.tan(theta) * math.cos(u0))
                    n += 1
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
def _axis_breaks(t, sign, az, out, k, phimax):
    """Append to out[k:] the azimuth break points (node frame, this half: φ = sign·u, u in
    (0, φ_max)) that grade an elongated half-vector lobe about its crests; returns the new k.

    ``az`` = (φ_i, a_x, a_y, q): the model's lobe D(h) ∝ d(tan²t E(ψ)), E(ψ) = cos²ψ/a_x²
    + sin²ψ/a_y² (ψ the azimuth of h in the tangent frame, ψ = φ + φ_i in the node frame;
    :meth:`~brdfkit.models.BRDF.albedo_half_axes`) with d = e^{−x} (q = 0: Beckmann-like)
    or (1 + x)^{−2} (q = 1: GGX-like). At fixed t it is largest on the long axis ψ₀ (E's
    minimum 1/a_max²) and falls off in δ = ψ − ψ₀ like d(tan²t (1/a_max² + δ² Δ)),
    Δ = |1/a_x² − 1/a_y²|: a crest of width w = √((cot²t + q/a_max²)/Δ) (the δ where the
    argument of d grows by 1, or for q = 1 by 1 plus its crest value). a_x = NaN: none.
    """
    ax = az[1]
    ay = az[2]
    if not (ax > 0.0 and ay > 0.0) or ax == ay or t <= 0.0:
        return k
    tt = math.tan(t)
    amax = max(ax, ay)
    delta = abs(1.0 / (ax * ax) - 1.0 / (ay * ay))
    w = math.sqrt((1.0 / (tt * tt) + az[3] / (amax * amax)) / delta)
    psi0 = 0.5 * math.pi if ay > ax else 0.0  # the long axis
    for crest in range(2):
        # the crest's azimuth in this half's u = sign·φ, wrapped into (−π, π]
        u0 = sign * (psi0 + crest * math.pi - az[0])
        u0 = u0 - 2.0 * math.pi * math.floor((u0 + math.pi) / (2.0 * math.pi))
        for j in range(-len(AXIS_GRADES), len(AXIS_GRADES) + 1):
            g = 0.0 if j == 0 else (AXIS_GRADES[abs(j) - 1] if j > 0 else -AXIS_GRADES[-j - 1])
            ph = u0 + g * w
            if 1e-12 < ph < phimax - 1e-12 and k < out.shape[0] - 1:
                out[k] = ph
                k += 1
    return k


@numba.njit(cache=True)
def _phi_breaks(mode, t, s, c, level, out, kinks, kv, sign, az):
    """Break points 0 = b₀ < … < b_k = φ_max of the azimuth at polar angle t; returns k + 1.

    φ_max is where ω_o meets the horizon (closed form). In half-vector mode,
    for a model declaring the ``vgroove`` kink, the azimuths where the branches
    of the V-groove G cross are added:
    2(N·H)(N·L) = L·H, 2(N·H)(N·V) = V·H, and N·V = N·L, each of the form
    cos φ = (d* − c cos t)/(s sin t) for the value d* of ω_i·h on that curve.
    The curves N·V = k for the levels k in ``kv`` (model-declared kinks, see
    :func:`albedo`) are added in the mirror and half frames:
    mirror: N·V = c cos t + s sin t cos φ, so cos φ = (k − c cos t)/(s sin t);
    half: N·V = 2(ω_i·h) cos t − c, so ω_i·h = (k + c)/(2 cos t).
    In half-vector mode the crests of an elongated lobe (``az``, :func:`_axis_breaks`)
    of the half ``sign`` (+1: φ ≥ 0; −1: φ ≤ 0, returned as −φ) are graded.
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
    if mode == MIRROR and (level >= 1 or kinks & KINK_NVNL) and s * st > 1e-300 \
            and phimax > 0.0:
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
    if mode == HALF and kinks & KINK_VGROOVE and s * st > 1e-300 and phimax > 0.0:
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
    if mode == HALF and phimax > 0.0:
        k = _axis_breaks(t, sign, az, out, k, phimax)
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
def _t_node(a, b, x):
    """The polar angle of a node, a + (b − a)x: one strict (non-fastmath) function for
    :func:`_count_nodes` and :func:`_gen_nodes`, whose azimuth break points at that t
    must agree to the last bit (a fused multiply-add in one of them moved a break across a
    1e-12 threshold: one interval more written than counted)."""
    return a + (b - a) * x


@numba.njit(cache=True)
def _count_nodes(mode, theta, width, level, sym, X, kinks, kv, az):
    """Exact number of nodes :func:`_gen_nodes` writes, and the number of error pieces."""
    tb = np.empty(64)
    pb = np.empty(16 + kv.shape[0] + AXIS_BREAKS)
    nt = _t_breaks(mode, theta, width, tb, kv, kinks, az)
    sub = 1 << level
    n_int = (5 if mode == HALF else 2) + kv.shape[0] + (AXIS_BREAKS if az[1] > 0.0 else 0)
    halves = 1 if sym else 2
    s = math.sin(theta)
    c = math.cos(theta)
    n = 0
    for ip in range(nt - 1):
        for q in range(sub):
            a = tb[ip] + (tb[ip + 1] - tb[ip]) * q / sub
            b = tb[ip] + (tb[ip + 1] - tb[ip]) * (q + 1) / sub
            for it in range(15):
                for h in range(halves):
                    k = _phi_breaks(mode, _t_node(a, b, X[it]), s, c, level, pb, kinks, kv,
                                    1.0 - 2.0 * h, az)
                    n += min(k - 1, n_int) * sub * 15
    return n, (nt - 1) * sub * halves


@numba.njit(cache=True, error_model="numpy", fastmath={"nsz", "arcp", "contract"})
def _gen_nodes(mode, theta, width, level, sym, X, WK, WG, wo, wk, wg, piece, kinks, kv, az):
    """Fill the nodes of one incidence angle; returns the number written.

    wo (N, 3), wk / wg (N,) Kronrod / Gauss weights including the measure and
    cos θ_o, piece (N,) the 2-D panel each node belongs to.
    """
    s = math.sin(theta)
    c = math.cos(theta)
    tb = np.empty(64)
    nt = _t_breaks(mode, theta, width, tb, kv, kinks, az)
    sub = 1 << level
    n_int = (5 if mode == HALF else 2) + kv.shape[0] + (AXIS_BREAKS if az[1] > 0.0 else 0)
    halves = 1 if sym else 2
    fac = 2.0 if sym else 1.0
    pb = np.empty(16 + kv.shape[0] + AXIS_BREAKS)
    n = 0
    tp = 0
    for ip in range(nt - 1):
        for q in range(sub):
            a = tb[ip] + (tb[ip + 1] - tb[ip]) * q / sub
            b = tb[ip] + (tb[ip + 1] - tb[ip]) * (q + 1) / sub
            for it in range(15):
                t = _t_node(a, b, X[it])
                wtk = WK[it] * (b - a)
                wtg = WG[it] * (b - a)
                st = math.sin(t)
                ct = math.cos(t)
                for h in range(halves):
                    sign = 1.0 if h == 0 else -1.0
                    k = _phi_breaks(mode, t, s, c, level, pb, kinks, kv, sign, az)
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
                            if n + 15 > wo.shape[0]:
                                # never past the counted slots (a break point that differs
                                # from _count_nodes' by rounding bounds a ~zero-width interval)
                                continue
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
                kinks, kvs, azs):
    """Nodes of every angle i at its level, written at offsets[i] (parallel over angles)."""
    for i in numba.prange(thetas.shape[0]):
        o = offsets[i]
        m = offsets[i + 1] - o
        n = _gen_nodes(mode, thetas[i], width, levels[i], sym, X, WK, WG, wo[o:o + m],
                       wk[o:o + m], wg[o:o + m], piece[o:o + m], kinks, kvs[i], azs[i])
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
