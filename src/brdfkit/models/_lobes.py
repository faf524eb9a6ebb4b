"""
Shared pieces of the Phong-family modules
=========================================

The parameter declarations, the kernel helper and the lobe hints that
:mod:`~brdfkit.models.phong`, :mod:`~brdfkit.models.blinn`,
:mod:`~brdfkit.models.lafortune` and :mod:`~brdfkit.models.grazing` share,
and their common base class.

Public objects (re-exported by :mod:`brdfkit.models.phong`)
-----------------------------------------------------------
- :func:`lobe_pow` — max(0, x)ⁿ with 0⁰ = 1, binary exponentiation for integral n.
- :func:`lobe_power`, :func:`lobe_mode`, :func:`rv_dot`, :func:`nh_dot` — the same
  and the dot products of :mod:`brdfkit._kern` as formulas (:mod:`brdfkit._dual`):
  branch-free, so that the ``"vector"`` loop vectorises them and Mitsuba traces them.
- :data:`COS_DIVISOR_FLOOR` — floor of a cosine that divides.
- :class:`CosineLobeBRDF` — base of the cosⁿ-lobe models: strategy-sampled
  (:mod:`brdfkit.models.sampling`), ``beta`` converts by cosⁿβ = 1/2.

References
----------
- [Lewis1993] R. R. Lewis, *Making Shaders More Physically Plausible*, 1993:
  §3.1 (the half-angle β of a cosⁿ lobe).
"""

from __future__ import annotations

import math

import numba
import numpy as np

from brdfkit._dual import Formulas, floor, formula, maximum, power, select, sqrt
from brdfkit._kern import SMALL_LENGTH
from brdfkit.halfangle import beta_from_exponent, exponent_from_beta
from brdfkit.models._base import BRDF, Lobe, Param
from brdfkit.models._drivers import loop_driver
from brdfkit.models._params import DIFFUSE_PART
from brdfkit.models.sampling import (
    COSINE,
    CosPowerAxis,
    HalfVector,
    Mixture,
    PowerHalf,
    StrategySampled,
    blinn_lobe,
    lobes_pdf,
    lobes_sample,
    normalised_weights,
    phong_lobe,
)
from brdfkit.models.specular import blinn_normal_albedo

__all__ = ["COS_DIVISOR_FLOOR", "CosineLobeBRDF", "DiffuseLobeBRDF", "KdKsLobeBRDF",
           "KdKsBlinnBRDF", "UP",
           "lobe_pow", "lobe_power", "lobe_mode",
           "rv_dot", "nh_dot", "LOBE_AUTO", "LOBE_INTEGRAL", "LOBE_REAL"]

RHO_D = DIFFUSE_PART  # ρ_d of the diffuse part beside a lobe (models/_params.py)
RHO_S = Param("rho_s", 0.5, 0.0, 1.0, "",
              "specular reflectance (albedo of the normalised lobe at normal incidence)",
              kind="colour")
N_EXP = Param("n", 20.0, 0.0, 1e6, "",
              "specular exponent (lobe sharpness); ~1-10 rough, 100-1000 glossy, >1e4 mirror")
K_D = Param("k_d", 0.1, 0.0, 1.0, "1/sr",
            "diffuse BRDF constant (albedo k_d*pi; <= 1/pi conserves energy; Lewis's "
            "figures use k_d = 1 - k_s)", kind="colour")
K_S = Param("k_s", 1.0, 0.0, 1e6, "1/sr",
            "specular coefficient (unnormalised; (n+2)/2pi gives unit normal-incidence "
            "albedo for the R.V lobe)", kind="colour")


# Floor of a cosine that divides (1/(N·L) in phong and blinn, 1/max(N·L, N·V) in
# neumann-phong). The true value overflows float64 when the cosine is subnormal; with the
# floor f ≤ k_s·1e300 ≤ 1e306 (k_s ≤ 1e6) and ≤ c_n·1e300 ≤ 1e307 (c_n ≤ 1e7): finite for
# every accepted parameter. Cost: f is too small by the factor cos/1e-300 only for cosines
# below 1e-300 (θ within 1e-300 rad of 90°), where float64 cannot represent it anyway.
COS_DIVISOR_FLOOR = 1e-300


# --------------------------------------------------------------------------- kernel helper
@numba.njit(cache=True, inline="always")
def lobe_pow(x: float, n: float) -> float:
    """max(0, x)ⁿ with 0⁰ = 1 (as :func:`brdfkit._kern.pos_pow`), faster for integral n.

    Integral exponents below 1024 (the usual Phong exponents) use binary
    exponentiation — ≤ 20 multiplications, ~4x faster than ``pow`` and within
    ~n·1e-16 relative of it; other exponents call ``pow``. The branch depends
    on the parameters only, so it is perfectly predicted inside a batch.
    """
    if x <= 0.0:
        return 1.0 if n == 0.0 else 0.0
    if n < 1024.0 and n == math.floor(n):
        k = int(n)
        r = 1.0
        b = x
        while k:
            if k & 1:
                r *= b
            b *= b
            k >>= 1
        return r
    return x**n


# ------------------------------------------------------------------ the same as formulas
#: lobe_power's compile-time mode: AUTO decides per value (both ways evaluated: the class
#: kernels, any n), INTEGRAL multiplies only (n integral below BINARY_LIMIT: vectorises),
#: REAL calls pow only (any other n); an instance's loop takes its mode (lobe_mode)
LOBE_AUTO, LOBE_INTEGRAL, LOBE_REAL = 0, 1, 2
#: lobe_pow multiplies for integral n below 2¹⁰ (≤ 20 products): ten bits, unrolled
BINARY_LIMIT = 1024.0
_TWO_600 = 2.0 ** 600  # exact rescaling of a short L + V (nh_dot), as microfacet.half_sum
_TWO_M600 = 2.0 ** -600
SMALL_LENGTH_SQ = SMALL_LENGTH * SMALL_LENGTH  # |L + V|² below which nh_dot rescales


def lobe_mode(n: float) -> int:
    """The :func:`lobe_power` mode for exponent *n*: LOBE_INTEGRAL or LOBE_REAL."""
    n = float(n)
    return LOBE_INTEGRAL if n < BINARY_LIMIT and n == math.floor(n) else LOBE_REAL


@formula
def _square_step(r, b, q):
    """One bit of :func:`lobe_pow`'s binary exponentiation: r·b if q is odd, b², ⌊q/2⌋.
    r·1.0 where the bit is 0 is exact, so the products are lobe_pow's, bit for bit."""
    h = floor(q * 0.5)
    return r * select(q - 2.0 * h > 0.5, b, 1.0), b * b, h


@formula
def _binary_power(x, n):
    """xⁿ for integral 0 ≤ n < 2¹⁰ by ten unrolled squaring steps (:func:`_square_step`)."""
    r, b, q = _square_step(1.0, x, n)
    r, b, q = _square_step(r, b, q)
    r, b, q = _square_step(r, b, q)
    r, b, q = _square_step(r, b, q)
    r, b, q = _square_step(r, b, q)
    r, b, q = _square_step(r, b, q)
    r, b, q = _square_step(r, b, q)
    r, b, q = _square_step(r, b, q)
    r, b, q = _square_step(r, b, q)
    r, b, q = _square_step(r, b, q)
    return r


@formula
def lobe_power(x, n, mode):
    """max(0, x)ⁿ with 0⁰ = 1: :func:`lobe_pow` as a formula, the same values bit for bit.

    *mode* (a compile-time constant): LOBE_INTEGRAL multiplies (:func:`_binary_power`;
    only for the n :func:`lobe_mode` gives it), LOBE_REAL is ``x ** n``, LOBE_AUTO
    selects between the two per n (both evaluated; a discarded NaN is harmless).
    """
    xp = maximum(x, 0.0)  # clamp: a negative base is the lobe's 0 (selected below)
    if mode == LOBE_INTEGRAL:
        r = _binary_power(xp, n)
    elif mode == LOBE_REAL:
        r = power(xp, n)
    else:
        r = select((n < BINARY_LIMIT) & (n == floor(n)), _binary_power(xp, n), power(xp, n))
    return select(x > 0.0, r, select(n == 0.0, 1.0, 0.0))


@formula
def rv_dot(ix, iy, iz, ox, oy, oz):
    """R·V = 2(N·L)(N·V) − L·V (:func:`brdfkit._kern.r_dot_v`, the same operations)."""
    return 2.0 * iz * oz - (ix * ox + iy * oy + iz * oz)


@formula
def nh_dot(ix, iy, iz, ox, oy, oz):
    """(N·H, |L + V|) without underflow, branch-free (:func:`brdfkit._kern.n_dot_h`).

    Where |L + V|² < SMALL_LENGTH² (1e-280: both directions within ~1e-140 of the
    horizon, nearly opposite) the sum is multiplied by 2⁶⁰⁰ first (exact: a power of
    two; its squares are then normal, ≤ (4e40)²): elsewhere the factor is 1 and the
    values are n_dot_h's bit for bit. L + V = 0 gives N·H = 0 (n_dot_h's value) and length 0.
    """
    sz = iz + oz
    sx = ix + ox
    sy = iy + oy
    small = sx * sx + sy * sy + sz * sz < SMALL_LENGTH_SQ
    r = select(small, _TWO_600, 1.0)
    zx = sx * r
    zy = sy * r
    zz = sz * r
    length = sqrt(zx * zx + zy * zy + zz * zz)
    ok = length > 0.0
    hz = zz / select(ok, length, 1.0)  # 1.0: L + V = 0, N·H 0 below
    return select(ok, hz, 0.0), length * select(small, _TWO_M600, 1.0)


def lobe_hint(kind: str, n: float) -> Lobe:
    """Lobe hint of a cosⁿ lobe: half-angle β with cosⁿβ = 1/2 (n = 0: constant, diffuse)."""
    if n <= 0.0:
        return Lobe("diffuse", math.pi / 2)
    return Lobe(kind, float(beta_from_exponent(n)))


def channel_mean(x) -> float:
    """The mean over channels of a (per-channel) parameter value: what mixture weights use."""
    return float(np.mean(x))


_SLOTS = ("cosine", "phong", "blinn")  # the components of lobes_sample, in its order
UP = np.array([0.0, 0.0, 1.0])  # a wo for _strategy (the models' weights do not depend on it)


def lobe_sampler_args(mixture: Mixture, layout: tuple) -> tuple:
    """(w_c, w_p, w_b, n_p, n_b) of :func:`~brdfkit.models.sampling.lobes_sample` for
    *mixture*, whose components are, in order, those *layout* names ("cosine", "phong": the
    cosⁿ lobe about the mirror of ω_o, "blinn": the N·H lobe; a subsequence of that order,
    so that the cumulative weights, and with them the pick from u₀, are the mixture's).
    A lobe of exponent 0 is the cosine (phong_lobe, blinn_lobe): its exponent is 0."""
    if list(layout) != [s for s in _SLOTS if s in layout] or len(layout) != len(
            mixture.components):
        raise ValueError(f"layout {layout!r} is not a subsequence of {_SLOTS} matching "
                         f"{mixture!r}")
    w = dict.fromkeys(_SLOTS, 0.0)
    n = {"phong": 0.0, "blinn": 0.0}
    for slot, comp, weight in zip(layout, mixture.components, mixture.weights, strict=True):
        w[slot] = float(weight)
        if isinstance(comp, CosPowerAxis) and comp.axis is None and slot == "phong":
            n[slot] = comp.n
        elif (isinstance(comp, HalfVector) and isinstance(comp.distribution, PowerHalf)
              and comp.fold and slot == "blinn"):
            n[slot] = comp.distribution.n
        elif comp is not COSINE:
            raise ValueError(f"component {comp!r} is not the {slot} slot of lobes_sample")
    return w["cosine"], w["phong"], w["blinn"], n["phong"], n["blinn"]


class CosineLobeBRDF(StrategySampled, BRDF):
    """Base of the cosⁿ-lobe models: sampled by ``_strategy(wo)`` (see
    :class:`~brdfkit.models.sampling.StrategySampled`); the width parameter is the
    exponent, converted from a half-angle ``beta`` by cosⁿβ = 1/2.

    A model whose f_r is a formula sets :attr:`lobe_kernels` and :attr:`lobe_layout`:
    :meth:`eval` then runs the ``"vector"`` loop of the kernel for its exponent
    (:func:`lobe_mode`), and :meth:`formulas` gives that kernel with
    :func:`~brdfkit.models.sampling.lobes_sample`/``lobes_pdf`` for its strategy.
    """

    #: (kernel for any exponent, kernel for integral exponents below 2¹⁰), both formulas of
    #: (ix, iy, iz, ox, oy, oz, p) (:func:`lobe_power`'s LOBE_AUTO and LOBE_INTEGRAL), or None
    lobe_kernels: tuple | None = None
    #: the slots of ``_strategy``'s components in :func:`lobe_sampler_args`
    lobe_layout: tuple = ()

    def _validate(self):
        if self.lobe_kernels is not None:
            self._driver = loop_driver(self._lobe_kernel(), loop="vector")

    def _lobe_kernel(self):
        any_n, integral = self.lobe_kernels
        mode = lobe_mode(self._values[self.width_param])
        return integral if mode == LOBE_INTEGRAL else any_n

    def formulas(self) -> Formulas | None:
        """The kernel for this exponent, the sampler :func:`lobes_sample` and its pdf."""
        if self.lobe_kernels is None:
            return None
        return Formulas(eval=self._lobe_kernel(), sample=lobes_sample, pdf=lobes_pdf,
                        args=lobe_sampler_args(self._strategy(UP), self.lobe_layout))

    @classmethod
    def width_from_beta(cls, beta: float) -> float:
        """Exponent with cosⁿβ = 1/2 (Lewis §3.1): ``n``, or ``s`` in ``nielsen``."""
        return float(exponent_from_beta(beta))


class DiffuseLobeBRDF(CosineLobeBRDF):
    """Base of the models of a diffuse part and one cosⁿ lobe: their lobes, a diffuse one
    where :attr:`diffuse_param` is > 0 somewhere and the lobe of kind :attr:`lobe_kind`
    whose exponent is the width parameter (:func:`lobe_hint`)."""

    #: the diffuse part's parameter ("k_d", "rho_d")
    diffuse_param = "k_d"
    #: "mirror" (about the mirror of ω_o, phong_lobe) or "half" (N·H, blinn_lobe)
    lobe_kind = "half"

    def lobes(self):
        out = [Lobe("diffuse", math.pi / 2)] if np.any(self._values[self.diffuse_param]) else []
        return out + [lobe_hint(self.lobe_kind, self._values[self.width_param])]


class KdKsLobeBRDF(DiffuseLobeBRDF):
    """Base of the k_d + k_s·lobe models (``phong``: the cosⁿ lobe about the mirror of ω_o;
    ``blinn``, ``phong-blinn-reciprocal``: the (N·H)ⁿ lobe, :class:`KdKsBlinnBRDF`): their
    lobes (a diffuse one where k_d > 0 and the lobe of kind :attr:`lobe_kind`) and their
    sampler, the cosine and the lobe mixed in proportion to their normal-incidence albedos
    πk_d and k_s ∫lobe cos θ_o dω_o (2π/(n+1) for the mirror lobe, whose division by N·L in
    Lewis eq. 8 cancels the cosine; :func:`blinn_normal_albedo` for the N·H lobe)."""

    def _strategy(self, wo):
        v = self._values
        n = v["n"]
        mirror = self.lobe_kind == "mirror"
        k_s = channel_mean(v["k_s"])
        w = normalised_weights([math.pi * channel_mean(v["k_d"]),
                                k_s * 2.0 * math.pi / (n + 1.0) if mirror
                                else k_s * blinn_normal_albedo(n)])
        return Mixture([COSINE, phong_lobe(n) if mirror else blinn_lobe(n)], w)


class KdKsBlinnBRDF(KdKsLobeBRDF):
    """Base of the k_d + k_s (N·H)ⁿ models (``blinn``, ``phong-blinn-reciprocal``)."""

    lobe_kind = "half"
