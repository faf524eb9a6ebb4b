"""
Lewis's specular integral H_s
=============================

H_s(S) = ∫_Ω F_s(S, V) (N·V) dω_V for Phong's F_s^P = max(0, R·V)ⁿ (Lewis
eq. 5) and Blinn's F_s^B = (N·H)ⁿ (eq. 6): the albedo of the specular
function, which sets the albedo of Lewis's shaders (eq. 19,
k_ρ = k_d π + k_s H_s/(N·S)) and normalises the energy-conserving one
(eq. 22). This is the one implementation: :func:`brdfkit.analysis.H_s`
returns it as an :class:`~brdfkit.analysis.AlbedoResult`, and
``phong-energy-conserving`` tabulates it.

Method: in the frame of the lobe (about R for Phong, over the half vector H
for Blinn) the azimuthal integral over the part of each ring above the
horizon has a closed form; the remaining polar integral is in closed form
where the whole ring is above the horizon and by a tanh-sinh rule where the
horizon cuts it (relative accuracy ~1e-11 for n ≤ 1e6).
:func:`specular_integral_with_error` also returns an error estimate: the
difference from the rule of twice the step (tanh-sinh converges double
exponentially, so this difference bounds the error of the finer rule) plus
a bound on rounding.

Public objects
--------------
- :func:`specular_integral` — H_s(θ_i) for the Phong or Blinn lobe.
- :func:`specular_integral_with_error` — the same, with an absolute error estimate.
- :func:`blinn_normal_albedo` — H_s of the Blinn lobe at normal incidence,
  ∫ (N·H)ⁿ cos θ_o dω_o with L = N, in closed form.

References
----------
- [Lewis1993] R. R. Lewis, *Making Shaders More Physically Plausible*, 1993:
  eqs. (5), (6), (16), (17), (19), (22), Fig. 5.
- [Takahasi1974] H. Takahasi, M. Mori, *Double exponential formulas for
  numerical integration*, Publ. RIMS 9, 1974 (the tanh-sinh rule).
- [Akenine-Möller2008] T. Akenine-Möller, E. Haines, N. Hoffman,
  *Real-Time Rendering*, 3rd ed. (the (n+8)/8π factor of Nielsen eq. 2).
"""

from __future__ import annotations

import math

import numpy as np

from brdfkit.errors import ParameterError

__all__ = ["specular_integral", "specular_integral_with_error", "blinn_normal_albedo"]

#: Rounding allowance of the error estimate, in units of the float64 epsilon times the sum
#: of the magnitudes of the terms; the power n adds n of them (see :func:`_error`).
_ROUNDING = 128.0 * np.finfo(np.float64).eps
_EPS = float(np.finfo(np.float64).eps)

def blinn_normal_albedo(n):
    """∫ (N·H)ⁿ cos θ_o dω_o at normal incidence (L = N), in closed form.

    With L = N, H bisects N and V, so θ_o = 2θ_h, cos θ_o = 2h² − 1 (h = cos θ_h)
    and sin θ_o dθ_o = −4h dh; the integral over θ_o ∈ [0, π/2] becomes

        8π ∫_{1/√2}^1 h^{n+1} (2h² − 1) dh
          = 8π [2(1 − 2^{−(n+4)/2})/(n+4) − (1 − 2^{−(n+2)/2})/(n+2)].

    n = 0 gives π (the cosine integral, Lewis eq. 16); for large n it tends to
    8π/n. Nielsen eq. (2)'s factor (n+8)/8π (Akenine-Möller et al.) is an
    approximation of its reciprocal, too large by up to 7.5 % (n ≈ 8.76).
    """
    n = np.asarray(n, dtype=np.float64)
    a = -np.expm1(-0.5 * (n + 4.0) * math.log(2.0)) / (n + 4.0)
    b = -np.expm1(-0.5 * (n + 2.0) * math.log(2.0)) / (n + 2.0)
    return 8.0 * math.pi * (2.0 * a - b)


# --------------------------------------------------------------------------- H_s(S)
def _tanh_sinh(h: float = 1.0 / 32.0, t_max: float = 3.6):
    """Tanh-sinh nodes on [0, 1] as distances from both ends, and weights.

    Double-exponential quadrature converges exponentially even with algebraic
    endpoint singularities (the kinks where the horizon starts to cut a lobe
    behave like d^{3/2}); distances from each end are returned separately so
    that integrands can be evaluated without cancellation near the ends.
    """
    t = np.arange(-t_max, t_max + 0.5 * h, h)
    s = 0.5 * np.pi * np.sinh(t)
    left = 1.0 / (1.0 + np.exp(-2.0 * s))
    right = 1.0 / (1.0 + np.exp(2.0 * s))
    w = 0.5 * h * (0.5 * np.pi) * np.cosh(t) / np.cosh(s) ** 2
    return left, right, w


_TS_LEFT, _TS_RIGHT, _TS_W = _tanh_sinh()
#: The lobe factor is truncated where it has fallen below e^{-60} of its value at
#: the kink (negligible against any relative accuracy in double precision).
_DECAY = 60.0


def _hs_phong(theta: np.ndarray, n: float) -> tuple[np.ndarray, np.ndarray]:
    """H_s for F_s = max(0, R·V)ⁿ, in the frame of R (α from R, φ about R), and its error.

    With c = cos θ_i, s = sin θ_i: V_z = cos α c + sin α s cos φ. For α below
    α_k = π/2 − θ_i the whole ring is above the horizon and the φ-integral is
    2π cos α c (closed form in α); above it, ∫(a + b cos φ)₊ dφ =
    2(a φ₀ + √(b² − a²)) with φ₀ = atan2(√(b² − a²), −a), b² − a² = sin²α − c².
    """
    th = theta[:, None]
    c, s = np.cos(th), np.sin(th)
    a_k = 0.5 * np.pi - th
    with np.errstate(divide="ignore"):
        log_s = np.log(s)
    # ∫_0^{α_k} cos^{n+1}α sin α dα · 2π c = 2π c (1 − sin^{n+2}θ)/(n+2)
    closed = 2.0 * np.pi * c * -np.expm1((n + 2.0) * log_s) / (n + 2.0)
    a_max = np.maximum(np.arccos(np.minimum(1.0, s * math.exp(-_DECAY / n))), a_k)
    length = a_max - a_k
    d = length * _TS_LEFT  # α − α_k
    e = (0.5 * np.pi - a_max) + length * _TS_RIGHT  # π/2 − α
    cos_a = np.sin(e)
    sin_a = np.sin(a_k + d)
    a = cos_a * c
    # sin α − sin α_k = 2 cos(α_k + d/2) sin(d/2), without cancellation
    r = np.sqrt(np.maximum(0.0, 2.0 * np.cos(a_k + 0.5 * d) * np.sin(0.5 * d) * (sin_a + c)))
    g = 2.0 * (a * np.arctan2(r, -a) + r)
    with np.errstate(divide="ignore"):
        lobe = np.exp(n * np.log(cos_a))
    terms = _TS_W * lobe * g * sin_a
    part = length[:, 0] * np.sum(terms, axis=-1)
    # d closed / d log s: what the rounding of log s (~ε absolute) moves it by
    with np.errstate(under="ignore"):
        slope = 2.0 * np.pi * c * np.exp((n + 2.0) * log_s)
    return closed[:, 0] + part, _error(closed[:, 0], slope[:, 0], length[:, 0], terms, part, n)


def _hs_blinn(theta: np.ndarray, n: float) -> tuple[np.ndarray, np.ndarray]:
    """H_s for F_s = (N·H)ⁿ, integrated over H (θ_h = γ, azimuth φ about N), and its error.

    dω_V = 4 (S·H) dω_H and V_z = 2(S·H) cos γ − c. With x = S·H = A + B cos φ
    (A = c cos γ, B = s sin γ) the φ-integrand is 4x(2x cos γ − c)₊: the whole
    ring counts for γ ≤ γ₁ = (π/2 − θ_i)/2, none of it for γ ≥ γ₂ =
    (π/2 + θ_i)/2, and |φ| < φ₁ = arccos t in between, with
    1 + t = sin 2(γ − γ₁)/(2 cos γ B) and 1 − t = sin 2(γ₂ − γ)/(2 cos γ B).
    """
    th = theta[:, None]
    c, s = np.cos(th), np.sin(th)
    g1 = 0.5 * (0.5 * np.pi - th)
    g2 = 0.5 * (0.5 * np.pi + th)
    h1 = np.cos(g1)
    log_h1 = np.log(h1)
    # γ ≤ γ₁: 2π-ring integral 16π c² h³ + 8π s² h(1 − h²) − 8π c² h, times hⁿ, h from h₁ to 1
    full = ((16.0 * np.pi * c * c - 8.0 * np.pi * s * s) * -np.expm1((n + 4.0) * log_h1)
            / (n + 4.0)
            + (8.0 * np.pi * s * s - 8.0 * np.pi * c * c) * -np.expm1((n + 2.0) * log_h1)
            / (n + 2.0))
    g_max = np.minimum(g2, np.arccos(np.minimum(1.0, h1 * math.exp(-_DECAY / n))))
    g_max = np.maximum(g_max, g1)
    length = g_max - g1
    d1 = length * _TS_LEFT
    d2 = (g2 - g_max) + length * _TS_RIGHT
    g = g1 + d1
    h, sg = np.cos(g), np.sin(g)
    A = c * h
    B = np.maximum(s * sg, 1e-300)  # clamp: B = 0 only on an empty interval (θ_i = 0)
    den = 2.0 * h * B
    opt = np.maximum(np.sin(2.0 * d1) / den, 0.0)  # 1 + t (clamp: rounding at γ₁)
    omt = np.maximum(np.sin(2.0 * d2) / den, 0.0)  # 1 − t (clamp: rounding at γ₂)
    phi1 = 2.0 * np.arctan2(np.sqrt(omt), np.sqrt(opt))
    sin1 = np.sqrt(omt * opt)
    cos1 = 0.5 * (opt - omt)
    ring = (8.0 * h * (2.0 * A * A * phi1 + 4.0 * A * B * sin1 + B * B * (phi1 + sin1 * cos1))
            - 4.0 * c * (2.0 * A * phi1 + 2.0 * B * sin1))
    with np.errstate(divide="ignore"):
        lobe = np.exp(n * np.log(h))
    terms = _TS_W * lobe * ring * sg
    part = length[:, 0] * np.sum(terms, axis=-1)
    # d full / d log h₁: what the rounding of log h₁ (~ε absolute) moves it by
    with np.errstate(under="ignore"):
        slope = ((16.0 * np.pi * c * c - 8.0 * np.pi * s * s) * np.exp((n + 4.0) * log_h1)
                 + (8.0 * np.pi * s * s - 8.0 * np.pi * c * c) * np.exp((n + 2.0) * log_h1))
    return full[:, 0] + part, _error(full[:, 0], slope[:, 0], length[:, 0], terms, part, n)


def _error(closed: np.ndarray, slope: np.ndarray, length: np.ndarray, terms: np.ndarray,
           part: np.ndarray, n: float) -> np.ndarray:
    """|I_h − I_2h| (the rule on every other node, weights doubled) plus rounding.

    Tanh-sinh converges double exponentially (error(h) ≈ error(2h)²), so the
    difference from the coarser rule bounds the error of the finer one.
    Rounding: every value carries a few ulps (:data:`_ROUNDING`), and a power
    xⁿ = exp(n log x) of a cosine x near 1 turns the absolute rounding of x
    (~ε) into an error n·ε relative to the lobe at each node, and into
    ε·|*slope*| in the closed-form part (*slope*: its derivative with respect
    to the logarithm it raises to the power). Checked against 25-digit
    references up to n = 1e6 (``tests/test_models_phong.py``).
    """
    coarse = length * np.sum(2.0 * terms[:, ::2], axis=-1)
    nodes = length * np.sum(np.abs(terms), axis=-1)
    return (np.abs(part - coarse) + _ROUNDING * (np.abs(closed) + nodes) + n * _EPS * nodes
            + 8.0 * _EPS * np.abs(slope))


def specular_integral(theta_i, n: float, lobe: str = "phong") -> np.ndarray:
    """Lewis's H_s(S) = ∫_Ω F_s(S, V) (N·V) dω_V for F_s = max(0, R·V)ⁿ or (N·H)ⁿ.

    Parameters
    ----------
    theta_i : array_like
        Incident polar angle(s) in radians, in [0, π/2].
    n : float
        Exponent ≥ 0. n = 0 means F_s ≡ 1 (0⁰ = 1, Lewis §7), so H_s = π.
    lobe : {"phong", "blinn"}
        Lewis eq. (5) (R·V) or eq. (6) (N·H).

    Returns
    -------
    ndarray
        H_s(θ_i) (sr). Computed in the lobe frame with the azimuthal integral
        in closed form and a tanh-sinh rule over the polar angle where the
        horizon cuts the lobe; relative accuracy ~1e-11 for n ≤ 1e6
        (:func:`specular_integral_with_error` also estimates the error).
        Checks: H_s(0) = 2π/(n+2) (Phong, Lewis eq. 16); H_s(π/2) =
        B((n+1)/2, 3/2) (Phong), 8π/((n+2)(n+4)) (Blinn); Blinn at n = 0 is π
        at every θ_i.
    """
    return specular_integral_with_error(theta_i, n, lobe)[0]


def specular_integral_with_error(theta_i, n: float,
                                 lobe: str = "phong") -> tuple[np.ndarray, np.ndarray]:
    """:func:`specular_integral` and an absolute error estimate, both of shape ``theta_i``.

    The estimate is the difference from the tanh-sinh rule of twice the step
    plus a rounding allowance (module docstring): a bound in practice, ~1e-12
    relative for most (θ_i, n); 0-width intervals (whole lobe above the
    horizon) are closed forms with rounding error only.
    """
    th = np.asarray(theta_i, dtype=np.float64)
    if np.any(~((th >= 0.0) & (th <= 0.5 * np.pi))):
        raise ParameterError(f"theta_i must lie in [0, pi/2] rad; got {theta_i!r}")
    if not (math.isfinite(n) and n >= 0.0):
        raise ParameterError(f"n must be a finite number >= 0; got {n!r}")
    if lobe not in ("phong", "blinn"):
        raise ParameterError(f"lobe must be one of phong, blinn; got {lobe!r}")
    flat = th.reshape(-1)
    if n == 0.0:
        return np.full(th.shape, np.pi), np.full(th.shape, _ROUNDING * np.pi)
    fn = _hs_phong if lobe == "phong" else _hs_blinn
    parts = [fn(flat[i:i + 512], float(n)) for i in range(0, flat.size, 512)]
    if not parts:
        return np.empty(th.shape), np.empty(th.shape)
    out = np.concatenate([v for v, _ in parts])
    err = np.concatenate([e for _, e in parts])
    return out.reshape(th.shape), err.reshape(th.shape)
