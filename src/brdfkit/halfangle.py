"""
Half-angle conversions
======================

Lewis (1993) characterises every lobe by its half-angle β: the angle at which
the lobe "drops to half its peak" (Lewis §3.1, after Blinn 1977). Each
function here converts β (radians) to a model's width parameter and back,
**derived** from that definition rather than copied from the paper:

=====================  ===================================  ==========================
lobe (peak at 0)       definition at β                      printed in Lewis 1993
=====================  ===================================  ==========================
cosⁿα (Phong/Blinn,    cosⁿβ = 1/2                          c₁ = −ln2/ln cos β — right
D₁ with n = c₁)
D₂ = e^{−(c₂α)²}       e^{−(c₂β)²} = 1/2                    c₂ = √ln2/β — right
D₃ (Trowbridge–Reitz)  [c₃²/(cos²β(c₃²−1)+1)]² = 1/2        c₃ = √((cos²β−1)/(cos²β−√2)) — right
D₄ (Beckmann)          D₄(β)/D₄(0) = e^{−tan²β/m²}/cos⁴β    m = tanβ/√(ln2 − 4 ln cos β) — right
                       = 1/2                                 (but see the caveat below)
Neumann–Neumann        S = N, V tilted by β:                s = −ln2/(1 + cos β) — **wrong**
                       e^{−s(1/cos β − 1)} = 1/2            (negative); derived:
                                                            s = ln2 · cos β/(1 − cos β)
Minnaert               S = N, V tilted by β:                k = 1 − ln2/ln cos β — right
                       cos^{k−1}β = 1/2
Ward's exp(−tan²δ/m²)  e^{−tan²β/m²} = 1/2                  (not in the papers)
                                                            m = tan β/√ln2
=====================  ===================================  ==========================

Lewis §3.3 prints s = −ln 2/(1 + cos β) for the Neumann–Neumann lacquer
model. With S = N the model is f_r = b_N exp{−s(1/cos θ_v − 1)}; setting it
to b_N/2 at θ_v = β gives s (1/cos β − 1) = ln 2, i.e.
s = ln 2 · cos β/(1 − cos β) > 0. The printed value is negative for every β,
and a negative s would make the lobe *grow* away from the normal.

Caveat for D₄: Lewis's m(β) is the exact solution of D₄(β) = D₄(0)/2, but
D₄ peaks at α = 0 only when m ≤ 1/√2 (write t = tan²α: ln D₄ = −t/m² +
2 ln(1+t) + const has slope 2 − 1/m² at t = 0). For β ≳ 55° the formula gives
m > 1/√2, where D₄(0) is no longer the peak; the conversion still satisfies
the ratio definition.

Public objects
--------------
- :func:`exponent_from_beta`, :func:`beta_from_exponent` — Phong/Blinn n and
  Lewis's c₁.
- :func:`gaussian_c_from_beta`, :func:`beta_from_gaussian_c` — Lewis's c₂.
- :func:`trowbridge_reitz_c_from_beta`, :func:`beta_from_trowbridge_reitz_c` —
  Lewis's c₃ (also GGX's α, which is the same lobe).
- :func:`beckmann_m_from_beta`, :func:`beta_from_beckmann_m` — Lewis's D₄.
- :func:`neumann_s_from_beta`, :func:`beta_from_neumann_s` — Neumann–Neumann s.
- :func:`minnaert_k_from_beta`, :func:`beta_from_minnaert_k` — Minnaert k.
- :func:`ward_m_from_beta`, :func:`beta_from_ward_m` — Ward's m.

References
----------
- [Lewis1993] §3.1 (β for Phong/Blinn), §3.2 (c₁, c₂, c₃, m), §3.3 (s),
  §3.4 (k).
- J. F. Blinn, *Models of Light Reflection for Computer Synthesized
  Pictures*, SIGGRAPH 1977 (the half-angle definition).
"""

from __future__ import annotations

import numpy as np

from brdfkit.errors import ParameterError

__all__ = [
    "exponent_from_beta",
    "beta_from_exponent",
    "gaussian_c_from_beta",
    "beta_from_gaussian_c",
    "trowbridge_reitz_c_from_beta",
    "beta_from_trowbridge_reitz_c",
    "beckmann_m_from_beta",
    "beta_from_beckmann_m",
    "neumann_s_from_beta",
    "beta_from_neumann_s",
    "minnaert_k_from_beta",
    "beta_from_minnaert_k",
    "ward_m_from_beta",
    "beta_from_ward_m",
]

LN2 = float(np.log(2.0))
SQRT2 = float(np.sqrt(2.0))


def _check_beta(beta) -> np.ndarray:
    b = np.asarray(beta, dtype=np.float64)
    if np.any(~((b > 0.0) & (b < np.pi / 2))):
        raise ParameterError(
            f"beta (half-angle) must lie in (0, pi/2) radians; got {beta!r}"
        )
    return b


def _check_range(name: str, value, lower: float, upper: float, text: str) -> np.ndarray:
    a = np.asarray(value, dtype=np.float64)
    if np.any(~((a > lower) & (a < upper))):
        raise ParameterError(f"{name} must lie in {text} to have a half-angle; got {value!r}")
    return a


def _ret(x: np.ndarray):
    return float(x) if np.ndim(x) == 0 else x


# ----------------------------------------------------------------- Phong, Blinn, D1
def exponent_from_beta(beta):
    """Phong/Blinn exponent (and Lewis's c₁) with cosⁿβ = 1/2: n = −ln 2 / ln cos β.

    Lewis §3.1 and §3.2 print this formula; it is right.
    """
    b = _check_beta(beta)
    return _ret(-LN2 / np.log(np.cos(b)))


def beta_from_exponent(n):
    """Inverse of :func:`exponent_from_beta`: β = arccos(2^(−1/n)), n > 0."""
    n = _check_range("n", n, 0.0, np.inf, "(0, inf)")
    return _ret(np.arccos(2.0 ** (-1.0 / n)))


# ----------------------------------------------------------------- D2 (Gaussian)
def gaussian_c_from_beta(beta):
    """Lewis's c₂ of D₂ = b e^{−(c₂α)²}: e^{−(c₂β)²} = 1/2 gives c₂ = √ln2/β (as printed)."""
    b = _check_beta(beta)
    return _ret(np.sqrt(LN2) / b)


def beta_from_gaussian_c(c):
    """Inverse of :func:`gaussian_c_from_beta`: β = √ln2/c₂; needs c₂ > 2√ln2/π ≈ 0.530."""
    c = _check_range("c (Gaussian c2)", c, 2.0 * np.sqrt(LN2) / np.pi, np.inf,
                     f"({2.0 * np.sqrt(LN2) / np.pi:.6g}, inf)")
    return _ret(np.sqrt(LN2) / c)


# ----------------------------------------------------------------- D3 (Trowbridge-Reitz)
def trowbridge_reitz_c_from_beta(beta):
    """Lewis's c₃ of D₃ = b [c₃²/(cos²α(c₃²−1)+1)]².

    D₃(0) = b, so D₃(β) = b/2 means c₃²/(cos²β(c₃²−1)+1) = 1/√2, hence
    c₃² (√2 − cos²β) = 1 − cos²β and c₃ = √((cos²β − 1)/(cos²β − √2)) — the
    printed formula is right. The same lobe is GGX's with α = c₃.
    """
    b = _check_beta(beta)
    c2 = np.cos(b) ** 2
    return _ret(np.sqrt((c2 - 1.0) / (c2 - SQRT2)))


def beta_from_trowbridge_reitz_c(c):
    """Inverse of :func:`trowbridge_reitz_c_from_beta`.

    cos²β = (1 − √2 c₃²)/(1 − c₃²); a half-angle exists for 0 < c₃ < 2^{−1/4}.
    """
    c = _check_range("c (Trowbridge-Reitz c3)", c, 0.0, 2.0**-0.25, f"(0, {2.0**-0.25:.6g})")
    c2 = c * c
    return _ret(np.arccos(np.sqrt((1.0 - SQRT2 * c2) / (1.0 - c2))))


# ----------------------------------------------------------------- D4 (Beckmann)
def beckmann_m_from_beta(beta):
    """Beckmann m of Lewis's D₄ = e^{−tan²α/m²}/(4m² cos⁴α).

    D₄(β)/D₄(0) = e^{−tan²β/m²}/cos⁴β = 1/2 gives tan²β/m² = ln2 − 4 ln cos β,
    so m = tan β/√(ln 2 − 4 ln cos β): the printed formula is right. (D₄(0)
    is the peak only for m ≤ 1/√2; see the module docstring.)
    """
    b = _check_beta(beta)
    return _ret(np.tan(b) / np.sqrt(LN2 - 4.0 * np.log(np.cos(b))))


def beta_from_beckmann_m(m):
    """Inverse of :func:`beckmann_m_from_beta`, m > 0.

    With t = tan²β the definition reads φ(t) = t − m²(ln 2 + 2 ln(1 + t)) = 0;
    φ(0) < 0 and φ is convex, so the positive root is unique and m(β) is
    increasing. It is found by bisection on β ∈ (0, π/2) (200 halvings: exact
    to rounding).
    """
    m = _check_range("m", m, 0.0, np.inf, "(0, inf)")
    m2 = np.broadcast_to(m * m, np.shape(m))
    lo = np.zeros(np.shape(m))
    hi = np.full(np.shape(m), np.pi / 2)
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        t = np.tan(mid) ** 2
        phi = t - m2 * (LN2 + 2.0 * np.log1p(t))
        lo = np.where(phi < 0.0, mid, lo)
        hi = np.where(phi < 0.0, hi, mid)
    return _ret(0.5 * (lo + hi))


# ----------------------------------------------------------------- Neumann-Neumann
def neumann_s_from_beta(beta):
    """Neumann–Neumann s for half-angle β (Lewis §3.3 definition, derived).

    With S = N, f_r = b_N exp{−s(1/cos θ_v − 1)}; f_r(β) = b_N/2 gives
    s = ln 2 · cos β/(1 − cos β). **Lewis prints s = −ln 2/(1 + cos β)**,
    which is negative for every β and therefore wrong.
    """
    b = _check_beta(beta)
    c = np.cos(b)
    return _ret(LN2 * c / (1.0 - c))


def beta_from_neumann_s(s):
    """Inverse of :func:`neumann_s_from_beta`: cos β = s/(s + ln 2), s > 0."""
    s = _check_range("s", s, 0.0, np.inf, "(0, inf)")
    return _ret(np.arccos(s / (s + LN2)))


# ----------------------------------------------------------------- Minnaert
def minnaert_k_from_beta(beta):
    """Minnaert k for half-angle β (Lewis §3.4, same definition as §3.3).

    With S = N, f_r = b_M cos^{k−1}θ_v; cos^{k−1}β = 1/2 gives
    k = 1 − ln 2/ln cos β — the printed formula is right (k > 1: only then
    does the lobe peak at the normal).
    """
    b = _check_beta(beta)
    return _ret(1.0 - LN2 / np.log(np.cos(b)))


def beta_from_minnaert_k(k):
    """Inverse of :func:`minnaert_k_from_beta`: β = arccos(2^{−1/(k−1)}), k > 1."""
    k = _check_range("k (Minnaert)", k, 1.0, np.inf, "(1, inf)")
    return _ret(np.arccos(2.0 ** (-1.0 / (k - 1.0))))


# ----------------------------------------------------------------- Ward
def ward_m_from_beta(beta):
    """Ward's m for the N·H lobe exp(−tan²δ/m²) (Neumann eq. 8): m = tan β/√ln2."""
    b = _check_beta(beta)
    return _ret(np.tan(b) / np.sqrt(LN2))


def beta_from_ward_m(m):
    """Inverse of :func:`ward_m_from_beta`: β = arctan(m √ln2), m > 0."""
    m = _check_range("m", m, 0.0, np.inf, "(0, inf)")
    return _ret(np.arctan(m * np.sqrt(LN2)))
