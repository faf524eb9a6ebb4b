"""
EON: the energy-preserving Oren–Nayar model and its clipped-LTC sampler
=======================================================================

EON (Portsmouth, Kutz, Hill 2025; OpenPBR's diffuse) is FON
(:mod:`brdfkit.models.rough_diffuse`) plus a multiple-scattering lobe in the
Kulla–Conty form, with FON's albedo in closed form; the derivations (E_FON, the
rewriting of f_ms without 0/0 at r = 0) are in that module's docstring.

Public objects
--------------
- :class:`EON` — ``eon``.
- :func:`eon` — f_EON, a formula (:mod:`brdfkit._dual`).
- :func:`eon_sample`, :func:`eon_pdf` — the paper's sampler: a uniform
  hemisphere lobe (weight P_u(μ_o, r)) mixed with a *clipped* linearly
  transformed cosine (CLTC), formulas; :class:`EONStrategy` runs them on NumPy
  arrays (:class:`~brdfkit.models.sampling.Strategy`).

The CLTC sampler, derived (the paper's construction, written from its description)
-----------------------------------------------------------------------------------
In the frame X = (ω_o,x, ω_o,y, 0)/|·|, Y = N × X, N (ω_o in the XN plane), an LTC
maps a cosine-distributed w_h by M = [[a, 0, b], [0, c, 0], [d, 0, 1]] to
ω = M w_h/|M w_h|, with density D(ω) = D_h(w_h) |M w_h|³/det M, det M = c(a − b d).
ω is above the horizon iff d x_h + z_h ≥ 0; for d ≤ 0 the points of the unit disk
(x_h, y_h) that satisfy it are x_h ≤ v √(1 − y_h²), v = 1/√(1 + d²): half the disk
plus a half ellipse, area π s with s = (1 + v)/2 (for d > 0, which the fit gives
for θ_o < 0.8°, the mirror image x_h ≥ −v √(1 − y_h²)).
A uniform point (x, y) of the disk is mapped to it by x_h = ∓((1 − s)√(1 − y²) + s x)
(an affine map of each chord, Jacobian s), so w_h has density z_h/(π s) and no sample
is wasted below the horizon. The inverse: v⃗ = adj(M) ω = (c(x − b z), (a − b d) y,
c(a z − d x)) ∝ M⁻¹ω, and D(ω) = (det M/|v⃗|²)² max(v_z, 0)/(π s).
The coefficients a, b, c, d (rational functions of μ_o and r) and the uniform lobe's
weight P_u = r^0.1 p(μ_o) are the paper's fits, as its listing states them; the χ²
test checks sampler and pdf against each other (any fit would pass it), and the
weight f cos θ_i/pdf is what the fits improve over the cosine (measured in
``tests/test_rough_diffuse.py``).

References
----------
- [Portsmouth2025] J. Portsmouth, P. Kutz, S. Hill, *EON: A practical
  energy-preserving rough diffuse BRDF*, JCGT 14(1), 2025 (arXiv 2410.18026),
  §§3–5, Listing 1 (f_EON) and its importance-sampling listing (the CLTC sampler;
  sections and listings cited, not equation numbers: the paper is not on this
  machine). Constants checked against the
  authors' GLSL, repository ``portsmouth/OpenPBR-viewer``, file
  ``glsl/pathtracing/diffuse_brdf.glsl`` (``ltc_terms``, ``cltc_sample``,
  ``cltc_pdf``, ``sample_EON``, ``pdf_EON``; the LTC frame of
  ``glsl/pathtracing/main.glsl``'s ``orthonormal_basis_ltc``); nothing copied.
- [Heitz2016] E. Heitz, J. Dupuy, S. Hill, D. Neubelt, *Real-time polygonal-light
  shading with linearly transformed cosines*, SIGGRAPH 2016 (the LTC density).
"""

from __future__ import annotations

import math

import numba
import numpy as np

from brdfkit._dual import (
    Formulas,
    cos,
    formula,
    maximum,
    minimum,
    numpy_version,
    power,
    select,
    sin,
    sqrt,
)
from brdfkit.models._base import BRDF, VECTOR_OPTIONS, Param
from brdfkit.models._drivers import loop_driver
from brdfkit.models._params import packed_indices
from brdfkit.models._registry import register
from brdfkit.models.rough_diffuse import (
    C1_FON,
    C2_FON,
    FON_PARAMS,
    _RoughDiffuse,
    fon,
    g_approx,
    g_exact,
)
from brdfkit.models.sampling import Strategy, StrategySampled

__all__ = ["EON", "eon", "eon_sample", "eon_pdf", "EONStrategy"]

INV_PI = 1.0 / math.pi
TWO_PI = 2.0 * math.pi
INV_TWO_PI = 0.5 / math.pi
#: Floor of a mixture weight or a squared length used as a divisor: a normal float32
#: number (Mitsuba's single-precision variants), far below any weight that is not 0.
TINY = 1e-30

EON_PARAMS = FON_PARAMS + (
    Param("E_FON", "exact", kind="choice", choices=("exact", "approx"),
          doc="FON's albedo in the multiple-scattering lobe: exact closed form (a = 1 for "
              "rho = 1) or the paper's quartic in 1 - mu"),
)
P_RHO, P_R, P_E_FON = packed_indices(EON_PARAMS, "rho", "r", "E_FON")
EXACT, APPROX = 0, 1  # the packed value of the E_FON choice

# The paper's fits of the LTC matrix (rational in μ = cos θ_o and r) and of the uniform
# lobe's weight P_u = r^0.1 (PU0 + PU1 μ + PU2 μ² + PU3 μ³), as its listing states them.
A0, A1, A2, A3, A4 = 0.303392, -0.518982, 0.111709, -0.276266, 0.335918
B0, B1, B2, B3, B4 = -1.16407, 1.15859, 0.150815, -0.150105, -1.43545
C0, C1, C2 = 0.20013, -0.506373, 0.261777
D0, D1, D2, D3, D4 = 0.540852, -1.01625, 0.475392, -1.0743, 0.0725628
PU0, PU1, PU2, PU3 = 0.162925, -0.372058, 0.538233, -0.290822


# =========================================================================== f_EON
@formula
def eon(ix, iy, iz, ox, oy, oz, p, exact):
    """EON: f_FON + f_ms (EON §4, Listing 1), a formula; *exact* a compile-time flag.

    f_ms = (ρ_ms/π)(1 − E_FON(μ_i))(1 − E_FON(μ_o))/(1 − Ē_FON), written with
    1 − E = A r (c₁ − G/π) (:mod:`~brdfkit.models.rough_diffuse`), ρ_ms = ρ² Ē/(1 − ρ(1 − Ē)).
    """
    rho, r = p[P_RHO], p[P_R]
    live = (iz > 0.0) & (oz > 0.0)
    mu_i = maximum(iz, 0.0)  # clamp: the discarded lanes below the horizon stay finite
    mu_o = maximum(oz, 0.0)
    if exact:
        gi = g_exact(ix, iy, mu_i)
        go = g_exact(ox, oy, mu_o)
    else:
        gi = g_approx(mu_i)
        go = g_approx(mu_o)
    a = 1.0 / (1.0 + C1_FON * r)
    e_avg = a * (1.0 + C2_FON * r)
    rho_ms = rho * rho * e_avg / (1.0 - rho * (1.0 - e_avg))
    # clamp at 0: the quartic exceeds c₁ by up to 4.6e-4 beyond θ = 89.92° (E > 1), where
    # f_ms would turn negative (the authors' listing floors 1 − E at 1e-7 likewise)
    di = maximum(C1_FON - gi, 0.0)
    do = maximum(C1_FON - go, 0.0)
    f_ms = rho_ms * INV_PI * a * r * di * do / (C1_FON - C2_FON)
    return select(live, fon(ix, iy, iz, ox, oy, oz, p) + f_ms, 0.0)


@formula(**VECTOR_OPTIONS)
def _eon_exact(ix, iy, iz, ox, oy, oz, p):
    return eon(ix, iy, iz, ox, oy, oz, p, True)


@formula(**VECTOR_OPTIONS)
def _eon_approx(ix, iy, iz, ox, oy, oz, p):
    return eon(ix, iy, iz, ox, oy, oz, p, False)


@numba.njit(cache=True, **VECTOR_OPTIONS)
def _eon(ix, iy, iz, ox, oy, oz, p):
    """The model's kernel for callers with one kernel per model: dispatches on E_FON."""
    if p[P_E_FON] == APPROX:
        return _eon_approx(ix, iy, iz, ox, oy, oz, p)
    return _eon_exact(ix, iy, iz, ox, oy, oz, p)


# =========================================================================== the CLTC sampler
@formula
def _ltc(mu, r):
    """(a, b, c, d) of M and the clipped disk's area fraction s (module docstring)."""
    a = 1.0 + r * (A0 + (A1 + A2 * mu) * mu + (A3 + A4 * mu) * r)
    b = r * (B0 + B1 * mu + (B2 + B3 * mu) * r) / (mu * mu * mu + B4)  # B4 < −1: no 0
    c = 1.0 + (C0 + (C1 + C2 * mu) * mu) * r
    d = (D0 + (D1 + D2 * mu) * mu) * r / (D3 + mu * (D4 + mu))  # D3 + μ(D4 + μ) < 0
    s = 0.5 * (1.0 + 1.0 / sqrt(d * d + 1.0))
    return a, b, c, d, s


@formula
def _frame(ox, oy):
    """X = (ω_o,x, ω_o,y)/|·| (Y = (−X_y, X_x)); X = (1, 0) for ω_o at the normal."""
    l2 = ox * ox + oy * oy
    ok = l2 > TINY * TINY
    inv = 1.0 / sqrt(select(ok, l2, 1.0))  # 1: the discarded lane stays finite
    return select(ok, ox * inv, 1.0), select(ok, oy * inv, 0.0)


@formula
def _uniform_weight(mu, r):
    """P_u, the uniform lobe's share of the mixture (0 at r = 0: the sampler is the
    cosine there, a = c = 1, b = d = 0)."""
    return power(r, 0.1) * (PU0 + mu * (PU1 + (PU2 + PU3 * mu) * mu))


@formula
def cltc_pdf(ix, iy, iz, ox, oy, oz, r):
    """Solid-angle density of the clipped LTC at ω_i (module docstring); 0 below."""
    mu = minimum(maximum(oz, 0.0), 1.0)  # clamp: ω_o below the horizon stays finite
    a, b, c, d, s = _ltc(mu, r)
    xx, xy = _frame(ox, oy)
    lx = ix * xx + iy * xy
    ly = iy * xx - ix * xy
    det = c * (a - b * d)
    vx = c * (lx - b * iz)
    vy = (a - b * d) * ly
    vz = c * (a * iz - d * lx)
    q = det / maximum(vx * vx + vy * vy + vz * vz, TINY)  # floor: |v| > 0 for unit ω_i
    return select(iz >= 0.0, q * q * maximum(vz, 0.0) * INV_PI / s, 0.0)


@formula
def eon_pdf(ix, iy, iz, ox, oy, oz, r):
    """P_u/(2π) + (1 − P_u) D_CLTC on the upper hemisphere, 0 below it or for ω_o below."""
    mu = minimum(maximum(oz, 0.0), 1.0)
    p_u = _uniform_weight(mu, r)
    p = p_u * INV_TWO_PI + (1.0 - p_u) * cltc_pdf(ix, iy, iz, ox, oy, oz, r)
    return select((oz > 0.0) & (iz >= 0.0), p, 0.0)


@formula
def eon_sample(ox, oy, oz, u0, u1, r):
    """ω_i from (u₀, u₁): the uniform hemisphere when u₀ < P_u, else the clipped LTC, u₀
    rescaled into the chosen component's interval (both evaluated)."""
    mu = minimum(maximum(oz, 0.0), 1.0)
    p_u = _uniform_weight(mu, r)
    pick_u = u0 < p_u
    uu = minimum(u0 / maximum(p_u, TINY), 1.0)  # clamp: rounding of the rescaled u₀
    uc = minimum(maximum((u0 - p_u) / maximum(1.0 - p_u, TINY), 0.0), 1.0)
    phi = TWO_PI * u1
    cp = cos(phi)
    sp = sin(phi)
    # uniform on the hemisphere: cos θ_i = u
    st = sqrt(maximum(1.0 - uu * uu, 0.0))  # clamp: rounding at u = 1
    # the clipped LTC: a uniform disk point mapped onto the clipped region, lifted, M w_h
    a, b, c, d, s = _ltc(mu, r)
    rad = sqrt(uc)
    y = rad * sp
    # the kept side of the disk: x_h ≤ v√(1 − y²) for d ≤ 0, x_h ≥ −v√(1 − y²) for d > 0
    # (the fit's d is positive, ≤ 3.5e-3 r, for μ_o > 0.99991: θ_o < 0.8°)
    side = select(d > 0.0, 1.0, -1.0)
    x = side * ((1.0 - s) * sqrt(maximum(1.0 - y * y, 0.0)) + s * rad * cp)
    zh = sqrt(maximum(1.0 - x * x - y * y, 0.0))  # clamp: rounding at the rim
    wx = a * x + b * zh
    wy = c * y
    wz = maximum(d * x + zh, 0.0)  # ≥ 0 by construction; the clamp removes rounding
    inv = 1.0 / sqrt(maximum(wx * wx + wy * wy + wz * wz, TINY))
    wx = wx * inv
    wy = wy * inv
    wz = wz * inv
    xx, xy = _frame(ox, oy)
    lx = xx * wx - xy * wy  # from the LTC frame (X, Y, N) to the local frame
    ly = xy * wx + xx * wy
    return (select(pick_u, st * cp, lx), select(pick_u, st * sp, ly),
            select(pick_u, uu, wz))


class EONStrategy(Strategy):
    """:func:`eon_sample`/:func:`eon_pdf` on NumPy arrays (a
    :class:`~brdfkit.models.sampling.Strategy`), for roughness *r* ∈ [0, 1]."""

    def __init__(self, r: float):
        self.r = float(r)

    def sample(self, wo, u):
        x, y, z = numpy_version(eon_sample)(wo[..., 0], wo[..., 1], wo[..., 2], u[..., 0],
                                            u[..., 1], self.r)
        return np.stack(np.broadcast_arrays(x, y, z), axis=-1)

    def pdf(self, wi, wo):
        return numpy_version(eon_pdf)(wi[..., 0], wi[..., 1], wi[..., 2], wo[..., 0],
                                      wo[..., 1], wo[..., 2], self.r)

    def __repr__(self) -> str:
        return f"EONStrategy(r={self.r:g})"


@register
class EON(StrategySampled, _RoughDiffuse, BRDF):
    """EON (Portsmouth, Kutz, Hill 2025): FON plus its energy compensation.

    f = f_FON + (ρ_ms/π)(1 − E_FON(μ_i))(1 − E_FON(μ_o))/(1 − Ē_FON),
    ρ_ms = ρ² Ē_FON/(1 − ρ(1 − Ē_FON)) (EON §4, Listing 1; OpenPBR's diffuse).

    =====  =======  ============  ===============================================
    name   default  bounds        meaning
    =====  =======  ============  ===============================================
    rho    0.8      [0, 1]        albedo (per channel)
    r      0.5      [0, 1]        roughness; 0 is Lambert
    E_FON  exact    exact/approx  FON's albedo in f_ms: the closed form (a = 1 for
                                  ρ = 1 to the engine's accuracy) or the paper's
                                  quartic (cheaper; |1 − a| ≤ 5.3e-4)
    =====  =======  ============  ===============================================

    Reciprocal. Energy-preserving: for ρ = 1 the albedo is 1 at every angle with
    ``E_FON="exact"`` (measured in the tests); for ρ < 1 its albedo is
    ρ E_FON + ρ_ms (1 − E_FON), the paper's multiple-scattering estimate. Sampled by
    the paper's uniform + clipped-LTC mixture (module docstring).
    """

    albedo_engine_tol = 1e-9  # FON's azimuth-90° switch (rough_diffuse._RoughDiffuse)

    name = "eon"
    aliases = ("energy-preserving-oren-nayar", "openpbr-diffuse")
    summary = "EON energy-preserving Oren-Nayar: FON + (1-E(mu_i))(1-E(mu_o)) lobe"
    params = EON_PARAMS
    citation = ("Portsmouth, Kutz, Hill 2025 (JCGT 14(1)) §§3-4, Listing 1: f_FON + f_ms, "
                "E_FON exact or approx")
    reciprocal = True
    kernel = _eon
    examples = (
        {},
        {"r": 1.0, "rho": 1.0},
        {"r": 0.3, "rho": [0.2, 0.5, 0.9], "E_FON": "approx"},
    )

    def _validate(self):
        self._formula = _eon_approx if self._values["E_FON"] == "approx" else _eon_exact
        self._driver = loop_driver(self._formula, loop="vector")

    def _strategy(self, wo):
        return EONStrategy(float(self._values["r"]))

    def formulas(self) -> Formulas:
        """This instance's kernel and the uniform + clipped-LTC sampler."""
        return Formulas(eval=self._formula, sample=eon_sample, pdf=eon_pdf,
                        args=(float(self._values["r"]),))
