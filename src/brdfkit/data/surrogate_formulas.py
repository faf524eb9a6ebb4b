"""
The measured-material surrogates as formulas (traced by Mitsuba, compiled by Numba)
===================================================================================

:mod:`brdfkit.data.surrogates` evaluates the four representations of a built-in
material (NBRDF, NPF, ABC, SGD) with Numba kernels that branch and loop. This
module writes each f_r again as a *formula* (:mod:`brdfkit._dual`: branch-free,
no loops, the packed row read by index), the same arithmetic in the same order,
so that the Mitsuba bridge traces it into its kernel
(:mod:`brdfkit.render.mitsuba_traced`) and Numba compiles it:

- **ABC**, **SGD**: the kernels' formulas with ``select`` for their branches;
  the same values as the kernels to rounding (tests/test_formulas_measured.py).
- **NPF**: the 1-D factors read at their computed bins by
  :func:`~brdfkit.tables.row_at` (a gather in the trace); returned with
  ``Formulas(tables=2)``: the factors are the row's tables.
- **NBRDF**: the 6-21-21-3 MLP unrolled: a formula generated once per network
  shape (:func:`nbrdf_formula`), each weight read from the packed row by a
  constant index (one generated source for every material; the weights are
  Python floats in the trace, literals in the compiled kernel), written into
  the drivers' cache directory (:func:`brdfkit.models._drivers._load`) so that
  Numba caches its compilation on disk.

The guards of the kernels, kept: the half vector as :func:`brdfkit._kern.half`
computes it (an exact power-of-two rescaling where |ω_i + ω_o| is below
:data:`~brdfkit._kern.SMALL_LENGTH`, instead of the kernel's division by the
largest component: equal to rounding), the cosines clamped to [0, 1] before
``acos`` as in the kernels, and 0 at and below the horizon.

Samplers: these materials' own samplers are tabulated (:mod:`brdfkit.data.sampler`),
not formulas. Their traced sampler is the cosine + GGX proxy of
:mod:`brdfkit.models.proxy_sampler` fitted to the material's lobe (its pdf is the
density of its samples: Monte-Carlo estimates stay unbiased; only the variance
differs from the tabulated sampler's).

Public objects
--------------
- :func:`surrogate_formulas` — a :class:`~brdfkit.data.surrogate_model.SurrogateBRDF`'s
  formulas (``SurrogateBRDF.formulas``).
- :func:`abc_formula`, :func:`sgd_formula`, :func:`npf_formula` — the kernels as formulas.
- :func:`nbrdf_formula` — the generated NBRDF formula.
- :func:`half_unit` — a shared formula (the dielectric Fresnel is
  :mod:`brdfkit.fresnel`'s formula).
"""

from __future__ import annotations

import math

from brdfkit._cache import memo
from brdfkit._dual import (
    Formulas,
    acos,
    exp,
    floor,
    formula,
    maximum,
    minimum,
    power,
    select,
    sqrt,
)
from brdfkit._kern import SMALL_LENGTH
from brdfkit.fresnel import _fresnel_dielectric as fresnel_dielectric
from brdfkit.models.proxy_sampler import proxy_args, proxy_pdf, proxy_sample
from brdfkit.tables import row_at

__all__ = ["surrogate_formulas", "abc_formula", "sgd_formula", "npf_formula", "nbrdf_formula",
           "half_unit"]

INV_PI = 1.0 / math.pi
HALF_PI = 0.5 * math.pi
#: |s|² below which s = ω_i + ω_o is rescaled by 2^600 before normalising (the squares of
#: its components could underflow: :data:`brdfkit._kern.SMALL_LENGTH`); 1e-280 is 0 in
#: float32, where the guard is then constant-false (inert, never NaN-producing)
_SMALL_L2 = SMALL_LENGTH * SMALL_LENGTH
_TWO_600 = 2.0 ** 600  # exact (a power of two)
#: SGD: exp() argument cap in G₁ (surrogates._EXP_CAP): exp(700) is finite in float64
_EXP_CAP = 700.0


# --------------------------------------------------------------------------- shared
@formula
def half_unit(ix, iy, iz, ox, oy, oz):
    """(h_x, h_y, h_z): the unit half vector, as :func:`brdfkit._kern.half` (the same
    operations where |s|² ≥ 1e-280; below, s rescaled by 2^600, exact, first)."""
    sx, sy, sz = ix + ox, iy + oy, iz + oz
    r = select(sx * sx + sy * sy + sz * sz < _SMALL_L2, _TWO_600, 1.0)
    sx, sy, sz = sx * r, sy * r, sz * r
    length = sqrt(sx * sx + sy * sy + sz * sz)
    return sx / length, sy / length, sz / length


# --------------------------------------------------------------------------- ABC
@formula
def abc_formula(ix, iy, iz, ox, oy, oz, p):
    """ABC [Low2012] (:func:`brdfkit.data.surrogates.abc_kernel`), p = [k_D, A, B, C, η]."""
    live = (iz > 0.0) & (oz > 0.0)
    hx, hy, hz = half_unit(ix, iy, iz, ox, oy, oz)
    cos_d = ix * hx + iy * hy + iz * hz  # > 0 above the horizon
    D = p[1] / power(1.0 + p[2] * (1.0 - hz), p[3])
    G = minimum(minimum(1.0, 2.0 * hz * iz / cos_d), 2.0 * hz * oz / cos_d)
    F = fresnel_dielectric(cos_d, p[4])
    return select(live, (p[0] + F * D * G / (iz * oz)) * INV_PI, 0.0)


# --------------------------------------------------------------------------- SGD
@formula
def sgd_g1(cos_t, lam, c, k, theta0):
    """G₁(θ) = clamp(1 + Λ(1 − exp(c·max(0, θ − θ₀)^k)), 0, 1) (surrogates._sgd_g1)."""
    t = maximum(0.0, acos(minimum(cos_t, 1.0)) - theta0)
    e = exp(minimum(c * power(t, k), _EXP_CAP))
    # Λ = 0: G₁ = 1 (in float32 exp(700) is inf and 0·(1 − inf) would be NaN)
    g = 1.0 + select(lam == 0.0, 0.0, lam * (1.0 - e))
    return minimum(1.0, maximum(0.0, g))


@formula
def sgd_ndf(cos_h, alpha, pw, kap):
    """D(θ_h) = K exp(−a)/(π a^p cos⁴θ_h), a = α + tan²θ_h/α (surrogates._sgd_ndf); 0 where
    exp(−a) underflows (no 0/0 at cos θ_h → 0)."""
    c2 = cos_h * cos_h
    a = alpha + (1.0 - c2) / (c2 * alpha)
    e = exp(-a)
    return select(e == 0.0, 0.0, kap * e * INV_PI / (power(a, pw) * c2 * c2))


@formula
def sgd_formula(ix, iy, iz, ox, oy, oz, p):
    """SGD [Bagher2012] (:func:`brdfkit.data.surrogates.sgd_kernel`)."""
    live = (iz > 0.0) & (oz > 0.0)
    hx, hy, hz = half_unit(ix, iy, iz, ox, oy, oz)
    u = minimum(maximum(ix * hx + iy * hy + iz * hz, 0.0), 1.0)  # cos θ_d, clamped
    m = 1.0 - u
    F = p[4] - u * p[5] + m * m * m * m * m * (1.0 - p[4])
    F = maximum(F, 0.0)  # the fitted F is not bounded below by construction (sgd_kernel)
    D = sgd_ndf(hz, p[2], p[3], p[6])
    G = sgd_g1(iz, p[7], p[8], p[9], p[10]) * sgd_g1(oz, p[7], p[8], p[9], p[10])
    return select(live, (p[0] + p[1] * F * D * G / (iz * oz)) * INV_PI, 0.0)


# --------------------------------------------------------------------------- NPF
_ND, _NG, _NF = 2, 92, 182  # surrogates: [ρ_d, ρ_s, D[90], G₁[90], F[90]]
NPF_TABLE = _ND  # the factors: the row's tables from this column on


@formula
def npf_g1(p, theta):
    """G₁(θ) as the NPF viewer interpolates it (:func:`brdfkit.data.surrogates._npf_g1`)."""
    u = theta / HALF_PI * 90.0
    f0 = floor(u - 0.5) + 0.5
    t0 = maximum(1.0, floor(f0))
    t1 = maximum(2.0, floor(f0) + 1.0)
    w0 = 1.0 - (u - f0)
    g0 = row_at(p, _NG + t0) * w0
    # t1 ≤ 90: bin 90 is F[0], read and discarded past the last centre
    return select(t1 > 89.0, g0, g0 + row_at(p, _NG + t1) * (1.0 - w0))


@formula
def npf_formula(ix, iy, iz, ox, oy, oz, p):
    """NPF/π [Bagher2016] (:func:`brdfkit.data.surrogates.npf_kernel`): D and F at the
    nearest bin, G₁ interpolated, the factors read by :func:`row_at`."""
    live = (iz > 0.0) & (oz > 0.0)
    hx, hy, hz = half_unit(ix, iy, iz, ox, oy, oz)
    # cosines of unit vectors, clamped to [0, 1] against rounding before acos (as the kernel)
    theta_h = acos(minimum(maximum(hz, 0.0), 1.0))
    theta_d = acos(minimum(maximum(ix * hx + iy * hy + iz * hz, 0.0), 1.0))
    # the bins: ⌊·⌋ of the index coordinate, clamped to the table (the kernel's int())
    i_d = floor(minimum(maximum(sqrt(theta_h / HALF_PI * 90.0 * 90.0), 0.0), 89.0))
    i_f = floor(minimum(maximum(theta_d / HALF_PI * 90.0, 0.0), 89.0))
    g_i = npf_g1(p, acos(minimum(iz, 1.0)))
    g_o = npf_g1(p, acos(minimum(oz, 1.0)))
    spec = p[1] * row_at(p, _ND + i_d) * row_at(p, _NF + i_f) * (g_i / iz) * (g_o / oz)
    return select(live, (p[0] + spec) * INV_PI, 0.0)


# --------------------------------------------------------------------------- NBRDF
@formula
def nbrdf_features(ix, iy, iz, ox, oy, oz):
    """(sin θ_h, cos θ_h, d_x, d_y, d_z) (:func:`brdfkit.data.surrogates._half_diff_vectors`):
    the half vector rotated to φ_h = 0 and the difference vector, without trigonometry."""
    hx, hy, hz = half_unit(ix, iy, iz, ox, oy, oz)
    s = sqrt(hx * hx + hy * hy)  # sin θ_h ≥ 0
    pos = s > 0.0
    d = select(pos, s, 1.0)  # h = n: φ_h = 0 (cos 1, sin 0), as the reference reader
    cp = select(pos, hx / d, 1.0)
    sp = select(pos, hy / d, 0.0)
    tx = ix * cp + iy * sp  # rot_z(−φ_h) ω_i
    ty = iy * cp - ix * sp
    return s, hz, tx * hz - iz * s, ty, iz * hz + tx * s  # rot_y(−θ_h)


#: The generated NBRDF formula's source: the net of surrogates.nbrdf_kernel unrolled, the
#: sums in the kernel's order (so the same values), weights by constant index.
_NBRDF_HEADER = '''"""brdfkit: generated NBRDF formula ({nh} hidden units; surrogate_formulas)."""
from brdfkit._dual import expm1, formula, muladd, select
from brdfkit.data.surrogate_formulas import nbrdf_features


@formula(cache={cache}, inline="never")
def nbrdf_eval(ix, iy, iz, ox, oy, oz, p):
    live = (iz > 0.0) & (oz > 0.0)
    x0, x2, x3, x4, x5 = nbrdf_features(ix, iy, iz, ox, oy, oz)
'''


def _dot(bias: str, terms: list[tuple[str, str]]) -> str:
    """bias + Σ x·w in the kernel's order (left to right) as a chain of :func:`muladd`:
    the same value in Numba (unfused), one fused multiply-add per weight in the trace."""
    out = bias
    for x, w in terms:
        out = f"muladd({x}, {w}, {out})"
    return out


def _nbrdf_source(cache: bool) -> str:
    from brdfkit.data.surrogates import _B1, _B2, _B3, _NH, _W1, _W2, _W3

    lines = [_NBRDF_HEADER.format(nh=_NH, cache=cache)]
    for j in range(_NH):  # layer 1 (x1 = h_y = 0 is left out, as the kernel does)
        s = _dot(f"p[{_B1 + j}]", [(f"x{i}", f"p[{_W1 + i * _NH + j}]") for i in (0, 2, 3, 4, 5)])
        lines.append(f"    s = {s}\n    a{j} = select(s > 0.0, s, 0.0)\n")
    for k in range(_NH):  # layer 2
        s = _dot(f"p[{_B2 + k}]", [(f"a{j}", f"p[{_W2 + _NH * j + k}]") for j in range(_NH)])
        lines.append(f"    s = {s}\n    r{k} = select(s > 0.0, s, 0.0)\n")
    for c in range(3):  # the output layer, one sum per channel
        y = _dot(f"p[{_B3 + c}]", [(f"r{k}", f"p[{_W3 + 3 * k + c}]") for k in range(_NH)])
        lines.append(f"    y{c} = {y}\n")
    lines.append("    c = p[0]  # the row's channel\n"
                 "    f = expm1(select(c == 0.0, y0, select(c == 1.0, y1, y2)))\n"
                 "    # f_r = exp(y) − 1, clamped at 0 where the net dips below it (the kernel)\n"
                 "    return select(live, select(f > 0.0, f, 0.0), 0.0)\n")
    return "".join(lines)


@memo(maxsize=1)  # one network shape
def nbrdf_formula():
    """The NBRDF formula (module docstring), generated once and cached on disk with the
    drivers (compiled in memory when the cache directory cannot be written)."""
    from brdfkit.models._drivers import _load

    generated = _load(_nbrdf_source(cache=True))
    if generated is not None:
        return generated.nbrdf_eval
    namespace: dict = {"__name__": "brdfkit_generated_nbrdf"}
    exec(compile(_nbrdf_source(cache=False), "<brdfkit nbrdf formula>", "exec"), namespace)
    return namespace["nbrdf_eval"]


# --------------------------------------------------------------------------- formulas()
_ANALYTIC = {"abc": abc_formula, "sgd": sgd_formula}


def surrogate_formulas(model):
    """*model*'s (a SurrogateBRDF's) Formulas: its f_r as a formula (module docstring), the
    cosine + GGX proxy of its lobe as sampler and pdf."""
    rep = model.representation
    args = proxy_args(model)
    if rep == "npf":
        return Formulas(eval=npf_formula, sample=proxy_sample, pdf=proxy_pdf, args=args,
                        tables=NPF_TABLE)
    if rep == "nbrdf":
        # the unrolled net composed into the vectorising loop (compensate) compiled in
        # 160-210 s against 22 s for its kernel in the checked loop (loaded 2-core machine)
        return Formulas(eval=nbrdf_formula(), sample=proxy_sample, pdf=proxy_pdf, args=args,
                        vectorise=False)
    return Formulas(eval=_ANALYTIC[rep], sample=proxy_sample, pdf=proxy_pdf, args=args)
