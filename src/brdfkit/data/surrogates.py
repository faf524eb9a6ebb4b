"""
Compact surrogates of measured materials, evaluated by compiled kernels
=======================================================================

No raw MERL file ships with brdfkit; the built-in materials are compact fits
made by others directly from the real measurements (MERL: Matusik et al. 2003;
RGL-EPFL: Dupuy & Jakob 2018; Nielsen et al. 2015). Each fit is evaluated here
by a Numba kernel ``kernel(ix, iy, iz, ox, oy, oz, p) -> float`` (one RGB
channel per packed row ``p``; 0 below the horizon; finite above it) and wrapped
as a :class:`SurrogateBRDF`, a :class:`~brdfkit.models.DerivedBRDF` with no
free parameters. Results are "MERL as seen through the surrogate", never raw
measurements; the surrogates disagree by up to ~2x on specular peaks
(``SOURCES.md``: two-layer-silver at θ_i = θ_o = 10°: NBRDF 20.9, NPF/π 36.8,
ABC 26.1).

Representations (formulas as evaluated here; ω_i, ω_o local, n = +z)
----------------------------------------------------------------------
- **NBRDF** [Sztrajman2021]: a 6-21-21-3 MLP with ReLU on
  x = [sin θ_h, 0, cos θ_h, d_x, d_y, d_z] (the half vector with φ_h rotated to
  0, and Rusinkiewicz's difference vector d = rot_y(−θ_h) rot_z(−φ_h) ω_i);
  f_r = exp(y) − 1 per channel. The net can return y slightly below 0; f_r is
  then clamped to 0 (a BRDF is non-negative; the training loss, on
  log(1 + f cos θ_i), does not forbid it).
- **NPF** [Bagher2016]: f_r = (ρ_d + ρ_s D(θ_h) F(θ_d) G₁(θ_i)/cos θ_i
  G₁(θ_o)/cos θ_o)/π with 1-D tables of 90 entries, indexed as the viewer that
  ships the data does (``npf.glsl``): D at ⌊√(θ_h/(π/2))·90⌋, F at
  ⌊θ_d/(π/2)·90⌋, G₁ linear in the index coordinate θ/(π/2)·90 between bins
  1–89 (bin 0 ignored; see :func:`_npf_g1`). The 1/π is not in the viewer; it
  makes f_r 1/sr (``SOURCES.md``, checked against NBRDF and ABC).
- **ABC** [Low2012]: f_r = (k_D + F(cos θ_d; η) D G/(cos θ_i cos θ_o))/π,
  D = A/(1 + B(1 − cos θ_h))^C, G = min(1, 2 cos θ_h cos θ_i/cos θ_d,
  2 cos θ_h cos θ_o/cos θ_d) (the V-groove term), F the unpolarised
  dielectric Fresnel reflectance (:mod:`brdfkit.fresnel`).
- **SGD** [Bagher2012]: f_r = (ρ_d + ρ_s F(cos θ_d) D(θ_h) G₁(θ_i) G₁(θ_o)
  /(cos θ_i cos θ_o))/π with the shifted-gamma distribution
  D = K exp(−a)/(π a^p cos⁴θ_h), a = α + tan²θ_h/α, the fitted shadowing
  G₁(θ) = clamp(1 + Λ(1 − exp(c·max(0, θ − θ₀)^k)), 0, 1) and the fitted
  Fresnel F(u) = F₀ − u F₁ + (1 − u)⁵(1 − F₀), u = cos θ_d. Re-derived from
  the paper's formulas as tabulated by Dupuy's public-domain ``dj_brdf.h``
  (``sgd__ndf``, ``sgd__g1``, ``fresnel::sgd``) — no code copied.

Public objects
--------------
- :class:`SurrogateBRDF` — a built-in material as a brdfkit model (defined in
  :mod:`brdfkit.data.surrogate_model`, with :data:`CITATIONS`, :data:`LICENCES`).
- :func:`nbrdf_material`, :func:`npf_material`, :func:`abc_material`,
  :func:`sgd_material` — build one from its fitted numbers.
- Kernels: :func:`nbrdf_kernel`, :func:`npf_kernel`, :func:`abc_kernel`,
  :func:`sgd_kernel` (each run by its generated checked loop, cached on disk);
  :func:`nbrdf_driver` (NBRDF: all channels from one net evaluation, in blocks).

References
----------
- [Matusik2003] W. Matusik, H. Pfister, M. Brand, L. McMillan, *A Data-Driven
  Reflectance Model*, ACM TOG 22(3), 2003 (MERL database, CC-BY-SA-4.0).
- [Sztrajman2021] A. Sztrajman, G. Rainer, T. Ritschel, T. Weyrich, *Neural
  BRDF Representation and Importance Sampling*, CGF 40(6), 2021 (weights:
  github.com/asztr/Neural-BRDF, MIT © 2022 asztr).
- [Bagher2016] M. M. Bagher, J. Snyder, D. Nowrouzezahrai, *A Non-Parametric
  Factor Microfacet Model for Isotropic BRDFs*, ACM TOG 35(5), 2016.
- [Low2012] J. Löw, J. Kronander, A. Ynnerman, J. Unger, *BRDF Models for
  Accurate and Efficient Rendering of Glossy Surfaces*, ACM TOG 31(1), 2012.
- [Bagher2012] M. M. Bagher, C. Soler, N. Holzschuch, *Accurate Fitting of
  Measured Reflectances Using a Shifted Gamma Micro-facet Distribution*,
  CGF 31(4), 2012.
- [Dupuy2018] J. Dupuy, W. Jakob, *An Adaptive Parameterization for Efficient
  Material Acquisition and Rendering*, ACM TOG 37(6), 2018 (RGL-EPFL).
- [Nielsen2015data] J. B. Nielsen, H. W. Jensen, R. Ramamoorthi, *On Optimal,
  Minimal BRDF Sampling for Reflectance Acquisition*, ACM TOG 34(6), 2015.
- J. Dupuy, ``dj_brdf.h`` (public domain), github.com/jdupuy/dj_brdf and
  jdupuy/opengl-framework ``demo-merl`` (NPF data and viewer, SGD and ABC
  parameter tables).
"""

from __future__ import annotations

import math

import numba
import numpy as np

from brdfkit._kern import INV_PI, half
from brdfkit.data.surrogate_model import (  # noqa: F401 - SOURCES re-exported (catalog)
    CITATIONS,
    LICENCES,
    REPRESENTATIONS,
    SOURCES,
    SurrogateBRDF,
)
from brdfkit.errors import ParameterError
from brdfkit.fresnel import _fresnel_dielectric
from brdfkit.models._base import _unit_pair

__all__ = ["SurrogateBRDF", "nbrdf_material", "npf_material", "abc_material", "sgd_material",
           "nbrdf_kernel", "nbrdf_driver", "npf_kernel", "abc_kernel", "sgd_kernel",
           "CITATIONS", "LICENCES", "REPRESENTATIONS"]

_jit = numba.njit(cache=True, inline="always")
HALF_PI = 0.5 * math.pi


# --------------------------------------------------------------------------- geometry
@_jit
def _half_diff_vectors(ix, iy, iz, ox, oy, oz):
    """(sin θ_h, cos θ_h, d_x, d_y, d_z): the half vector rotated to φ_h = 0 and
    Rusinkiewicz's difference vector d = rot_y(−θ_h) rot_z(−φ_h) ω_i, without
    trigonometric functions (cos φ_h = h_x/sin θ_h, sin φ_h = h_y/sin θ_h)."""
    hx, hy, hz, _ = half(ix, iy, iz, ox, oy, oz)
    s = math.sqrt(hx * hx + hy * hy)  # sin θ_h ≥ 0
    if s > 0.0:
        cp = hx / s
        sp = hy / s
    else:  # h = n: φ_h = atan2(0, 0) = 0, as the reference reader
        cp = 1.0
        sp = 0.0
    tx = ix * cp + iy * sp  # rot_z(−φ_h) ω_i
    ty = iy * cp - ix * sp
    dx = tx * hz - iz * s  # rot_y(−θ_h)
    dz = iz * hz + tx * s
    return s, hz, dx, ty, dz


# --------------------------------------------------------------------------- NBRDF
#: Packed NBRDF row: [channel, W1 (6x21, row-major), b1 (21), W2 (21x21), b2 (21),
#: W3 (21x3), b3 (3)] — the whole net in every channel's row, plus the channel index.
_NH = 21
_W1 = 1
_B1 = _W1 + 6 * _NH
_W2 = _B1 + _NH
_B2 = _W2 + _NH * _NH
_W3 = _B2 + _NH
_B3 = _W3 + 3 * _NH
NBRDF_ROW = _B3 + 3  # 676 numbers


@_jit
def _nbrdf_features(ix, iy, iz, ox, oy, oz):
    return _half_diff_vectors(ix, iy, iz, ox, oy, oz)


@_jit
def _relu(x):
    return x if x > 0.0 else 0.0


@_jit
def _nbrdf_f(y):
    # f_r = exp(y) − 1 (expm1: exact near 0); clamped at 0 where the net dips below it
    f = math.expm1(y)
    return f if f > 0.0 else 0.0


@numba.njit(cache=True)
def nbrdf_kernel(ix, iy, iz, ox, oy, oz, p):  # pragma: no cover - compiled
    """NBRDF, channel ``int(p[0])`` (the whole net is evaluated per channel)."""
    if iz <= 0.0 or oz <= 0.0:
        return 0.0
    x0, x2, x3, x4, x5 = _nbrdf_features(ix, iy, iz, ox, oy, oz)  # x1 = h_y = 0
    a1 = np.empty(_NH)
    for j in range(_NH):
        a1[j] = _relu(p[_B1 + j] + x0 * p[_W1 + j] + x2 * p[_W1 + 2 * _NH + j]
                      + x3 * p[_W1 + 3 * _NH + j] + x4 * p[_W1 + 4 * _NH + j]
                      + x5 * p[_W1 + 5 * _NH + j])
    c = int(p[0])
    y = p[_B3 + c]
    for k in range(_NH):
        s = p[_B2 + k]
        for j in range(_NH):
            s += a1[j] * p[_W2 + _NH * j + k]
        y += _relu(s) * p[_W3 + 3 * k + c]
    return _nbrdf_f(y)


#: Pairs per block of :func:`nbrdf_driver` (inner loops of this length vectorise).
_BLOCK = 64


@numba.njit(cache=True, parallel=True, fastmath={"reassoc", "contract", "nsz", "arcp"})
def nbrdf_driver(wi, wo, P, out):  # pragma: no cover - compiled
    """All three channels of NBRDF from one network evaluation per pair.

    The ``_driver`` of NBRDF materials (:meth:`~brdfkit.models.BRDF.eval`):
    pairs go through the net in blocks of 64, each layer a small matrix product
    whose inner loop runs over the pairs of a block (SIMD) — measured 2.5x the
    pairs/s of the same net evaluated pair by pair, and ~7x evaluating it once
    per channel through the kernel. Floating-point reassociation is allowed
    (results differ from :func:`nbrdf_kernel` by ~1e-13 relative). Returns the
    number of pairs with a NaN/inf component (their rows are NaN), as
    :func:`~brdfkit.models.eval_pairs_checked`.
    """
    n = wi.shape[0]
    p = P[0]
    nblocks = (n + _BLOCK - 1) // _BLOCK
    n_bad = 0
    for b in numba.prange(nblocks):
        j0 = b * _BLOCK
        m = min(n, j0 + _BLOCK) - j0
        X = np.zeros((5, _BLOCK))
        A = np.empty((_NH, _BLOCK))
        acc = np.empty(_BLOCK)
        Y = np.empty((3, _BLOCK))
        state = np.zeros(_BLOCK, dtype=np.int8)  # 0: evaluate, 1: below horizon, 2: NaN/inf
        for t in range(m):
            j = j0 + t
            ix, iy, iz = wi[j, 0], wi[j, 1], wi[j, 2]
            ox, oy, oz = wo[j, 0], wo[j, 1], wo[j, 2]
            if not _unit_pair(ix, iy, iz, ox, oy, oz):
                state[t] = 2
            elif iz <= 0.0 or oz <= 0.0:
                state[t] = 1
            else:
                X[0, t], X[1, t], X[2, t], X[3, t], X[4, t] = _nbrdf_features(
                    ix, iy, iz, ox, oy, oz)
        for q in range(_NH):
            w0, w2 = p[_W1 + q], p[_W1 + 2 * _NH + q]
            w3, w4, w5 = p[_W1 + 3 * _NH + q], p[_W1 + 4 * _NH + q], p[_W1 + 5 * _NH + q]
            bq = p[_B1 + q]
            for t in range(_BLOCK):
                A[q, t] = _relu(bq + X[0, t] * w0 + X[1, t] * w2 + X[2, t] * w3
                                + X[3, t] * w4 + X[4, t] * w5)
        for c in range(3):
            for t in range(_BLOCK):
                Y[c, t] = p[_B3 + c]
        for k in range(_NH):
            bk = p[_B2 + k]
            for t in range(_BLOCK):
                acc[t] = bk
            for q in range(_NH):
                w = p[_W2 + _NH * q + k]
                for t in range(_BLOCK):
                    acc[t] += A[q, t] * w
            u0, u1, u2 = p[_W3 + 3 * k], p[_W3 + 3 * k + 1], p[_W3 + 3 * k + 2]
            for t in range(_BLOCK):
                a = _relu(acc[t])
                Y[0, t] += a * u0
                Y[1, t] += a * u1
                Y[2, t] += a * u2
        for t in range(m):
            j = j0 + t
            if state[t] == 0:
                for c in range(3):
                    out[j, c] = _nbrdf_f(Y[c, t])
            elif state[t] == 1:
                for c in range(3):
                    out[j, c] = 0.0
            else:
                for c in range(3):
                    out[j, c] = math.nan
                n_bad += 1
    return n_bad


def nbrdf_packed(W1, b1, W2, b2, W3, b3) -> np.ndarray:
    """Packed rows (3, 676) of one NBRDF net (float32 weights widened to float64)."""
    shapes = {"W1": (6, _NH), "b1": (_NH,), "W2": (_NH, _NH), "b2": (_NH,), "W3": (_NH, 3),
              "b3": (3,)}
    arrays = {"W1": W1, "b1": b1, "W2": W2, "b2": b2, "W3": W3, "b3": b3}
    parts = []
    for key, shape in shapes.items():
        a = np.asarray(arrays[key], dtype=np.float64)
        if a.shape != shape:
            raise ParameterError(f"NBRDF weights: {key} must have shape {shape}; got {a.shape}")
        if not np.all(np.isfinite(a)):
            raise ParameterError(f"NBRDF weights: {key} has NaN or infinite entries")
        parts.append(a.ravel())
    row = np.concatenate([[0.0], *parts])
    rows = np.repeat(row[None, :], 3, axis=0)
    rows[:, 0] = (0.0, 1.0, 2.0)
    return rows


# --------------------------------------------------------------------------- NPF
#: Packed NPF row (one channel): [ρ_d, ρ_s, D[90], G₁[90], F[90]] — the file's columns.
_ND, _NG, _NF = 2, 92, 182
NPF_ROW = 272


@_jit
def _npf_g1(p, theta):
    """G₁(θ), as the viewer interpolates it (``lookupInterpolatedG1`` in ``npf.glsl``).

    With u = θ/(π/2)·90 (index coordinate) and f₀ = ⌊u − ½⌋ + ½ (the bin centre
    below u): t₀ = max(1, ⌊f₀⌋), t₁ = max(2, ⌊f₀⌋ + 1) (bin 0 is ignored), weights
    w₀ = 1 − (u − f₀), w₁ = u − f₀; past the last centre (t₁ > 89) G₁ = w₀·G₁[89],
    which fades to ½G₁[89] at 90°. Kept as the data's authors evaluate it (their
    fit was made for this rule), including its jump at u = 1.5.
    """
    u = theta / HALF_PI * 90.0
    f0 = math.floor(u - 0.5) + 0.5
    t0 = max(1, int(math.floor(f0)))
    t1 = max(2, int(math.floor(f0)) + 1)
    w0 = 1.0 - (u - f0)
    if t1 > 89:
        return p[_NG + t0] * w0
    return p[_NG + t0] * w0 + p[_NG + t1] * (1.0 - w0)


@numba.njit(cache=True)
def npf_kernel(ix, iy, iz, ox, oy, oz, p):  # pragma: no cover - compiled
    """NPF/π [Bagher2016]; ``p`` one channel's row of the data file (:data:`NPF_ROW`)."""
    if iz <= 0.0 or oz <= 0.0:
        return 0.0
    hx, hy, hz, _ = half(ix, iy, iz, ox, oy, oz)
    # cosines of unit vectors, clamped to [0, 1] against rounding before acos (as the viewer)
    theta_h = math.acos(min(max(hz, 0.0), 1.0))
    theta_d = math.acos(min(max(ix * hx + iy * hy + iz * hz, 0.0), 1.0))
    i_d = int(min(max(math.sqrt(theta_h / HALF_PI * 90.0 * 90.0), 0.0), 89.0))
    i_f = int(min(max(theta_d / HALF_PI * 90.0, 0.0), 89.0))
    g_i = _npf_g1(p, math.acos(min(iz, 1.0)))
    g_o = _npf_g1(p, math.acos(min(oz, 1.0)))
    # cos θ_i = iz, cos θ_o = oz > 0 here: G₁/cos θ grows as 1/cos θ at grazing (finite)
    spec = p[1] * p[_ND + i_d] * p[_NF + i_f] * (g_i / iz) * (g_o / oz)
    return (p[0] + spec) * INV_PI


def npf_packed(row) -> np.ndarray:
    """Packed rows (3, 272) from one material's row of the NPF file, shape (512, 3)."""
    a = np.asarray(row, dtype=np.float64)
    if a.shape != (512, 3):
        raise ParameterError(f"NPF row must have shape (512, 3); got {a.shape}")
    rows = np.ascontiguousarray(a[:NPF_ROW].T)
    if not np.all(np.isfinite(rows)) or np.any(rows < 0.0):
        raise ParameterError("NPF row: expected finite, non-negative factors")
    return rows


# --------------------------------------------------------------------------- ABC
#: Packed ABC row (one channel): [k_D, A, B, C, η].
ABC_ROW = 5


@numba.njit(cache=True)
def abc_kernel(ix, iy, iz, ox, oy, oz, p):  # pragma: no cover - compiled
    """ABC [Low2012] with V-groove G and dielectric Fresnel; ``p`` = [k_D, A, B, C, η]."""
    if iz <= 0.0 or oz <= 0.0:
        return 0.0
    hx, hy, hz, _ = half(ix, iy, iz, ox, oy, oz)
    cos_d = ix * hx + iy * hy + iz * hz  # = ω_o·h > 0 above the horizon
    D = p[1] / (1.0 + p[2] * (1.0 - hz)) ** p[3]
    G = min(1.0, 2.0 * hz * iz / cos_d, 2.0 * hz * oz / cos_d)
    F = _fresnel_dielectric(cos_d, p[4])
    return (p[0] + F * D * G / (iz * oz)) * INV_PI


# --------------------------------------------------------------------------- SGD
#: Packed SGD row (one channel): [ρ_d, ρ_s, α, p, F₀, F₁, K, Λ, c, k, θ₀].
SGD_FIELDS = ("rhoD", "rhoS", "alpha", "p", "f0", "f1", "kap", "lambda", "c", "k", "theta0")
SGD_ROW = len(SGD_FIELDS)
#: exp() argument cap in G₁: exp(700) ≈ 1e304 is finite, so Λ·(1 − exp(·)) stays finite
#: (or 0 for Λ = 0) instead of inf·0 = NaN; G₁ is clamped to [0, 1] anyway.
_EXP_CAP = 700.0


@_jit
def _sgd_g1(cos_t, lam, c, k, theta0):
    """G₁(θ) = clamp(1 + Λ(1 − exp(c·max(0, θ − θ₀)^k)), 0, 1) [Bagher2012]."""
    t = max(0.0, math.acos(min(cos_t, 1.0)) - theta0)
    g = 1.0 + lam * (1.0 - math.exp(min(c * t**k, _EXP_CAP)))
    return min(1.0, max(0.0, g))


@_jit
def _sgd_ndf(cos_h, alpha, pw, kap):
    """D(θ_h) = K exp(−a)/(π a^p cos⁴θ_h), a = α + tan²θ_h/α [Bagher2012]."""
    c2 = cos_h * cos_h
    a = alpha + (1.0 - c2) / (c2 * alpha)
    e = math.exp(-a)
    if e == 0.0:  # a > ~745: D underflows to 0 (avoids 0/0 when cos θ_h → 0)
        return 0.0
    return kap * e * INV_PI / (a**pw * c2 * c2)


@numba.njit(cache=True)
def sgd_kernel(ix, iy, iz, ox, oy, oz, p):  # pragma: no cover - compiled
    """SGD [Bagher2012]; ``p`` = [ρ_d, ρ_s, α, p, F₀, F₁, K, Λ, c, k, θ₀]."""
    if iz <= 0.0 or oz <= 0.0:
        return 0.0
    hx, hy, hz, _ = half(ix, iy, iz, ox, oy, oz)
    u = min(max(ix * hx + iy * hy + iz * hz, 0.0), 1.0)  # cos θ_d, clamped against rounding
    m = 1.0 - u
    F = p[4] - u * p[5] + m * m * m * m * m * (1.0 - p[4])
    # the fitted F is not bounded below by construction; a BRDF is: clamp at 0 (no MERL fit
    # reaches it on [0, 1] — tests/test_data_surrogates.py checks all 100)
    F = max(F, 0.0)
    D = _sgd_ndf(hz, p[2], p[3], p[6])
    G = _sgd_g1(iz, p[7], p[8], p[9], p[10]) * _sgd_g1(oz, p[7], p[8], p[9], p[10])
    return (p[0] + p[1] * F * D * G / (iz * oz)) * INV_PI




# --------------------------------------------------------------------------- builders
def nbrdf_material(source: str, material: str, W1, b1, W2, b2, W3, b3) -> SurrogateBRDF:
    """An NBRDF material from its net's weights (shapes 6x21, 21, 21x21, 21, 21x3, 3)."""
    return SurrogateBRDF(source=source, material=material, representation="nbrdf",
                         kernel=nbrdf_kernel, packed=nbrdf_packed(W1, b1, W2, b2, W3, b3),
                         reciprocal=False, driver=nbrdf_driver)


def npf_material(material: str, row) -> SurrogateBRDF:
    """A MERL material's NPF fit from its row (512, 3) of ``merl100_npf_bagher2016.f32``."""
    packed = npf_packed(row)
    return SurrogateBRDF(source="merl", material=material, representation="npf",
                         kernel=npf_kernel, packed=packed, reciprocal=True,
                         rho_d=packed[:, 0].copy())


def abc_material(material: str, kD, A, B: float, C: float, ior: float) -> SurrogateBRDF:
    """A MERL material's ABC fit: k_D, A per channel; B, C, η shared."""
    kD = np.broadcast_to(np.asarray(kD, dtype=np.float64), (3,))
    A = np.broadcast_to(np.asarray(A, dtype=np.float64), (3,))
    packed = np.column_stack([kD, A, np.full(3, B), np.full(3, C), np.full(3, ior)])
    if not np.all(np.isfinite(packed)) or ior <= 0.0:
        raise ParameterError(f"ABC fit of {material!r}: expected finite parameters and ior > 0")
    return SurrogateBRDF(source="merl", material=material, representation="abc",
                         kernel=abc_kernel, packed=packed, reciprocal=True, rho_d=kD.copy(),
                         albedo_kinks=frozenset({"vgroove"}))


def sgd_material(material: str, fields: dict) -> SurrogateBRDF:
    """A MERL material's SGD fit; *fields* maps each of :data:`SGD_FIELDS` to 3 values."""
    missing = [f for f in SGD_FIELDS if f not in fields]
    if missing:
        raise ParameterError(f"SGD fit of {material!r}: missing field {missing[0]!r}")
    packed = np.column_stack([np.broadcast_to(np.asarray(fields[f], dtype=np.float64), (3,))
                              for f in SGD_FIELDS])
    if not np.all(np.isfinite(packed)):
        raise ParameterError(f"SGD fit of {material!r}: NaN or infinite parameters")
    return SurrogateBRDF(source="merl", material=material, representation="sgd",
                         kernel=sgd_kernel, packed=packed, reciprocal=True,
                         rho_d=packed[:, 0].copy(),
                         kink_theta0=packed[:, 10].copy())
