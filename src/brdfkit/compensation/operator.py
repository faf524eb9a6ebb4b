"""
The compensation operator and the compensated model
===================================================

:func:`compensate` restores the energy a model's single-scattering lobe loses
(``docs/compensation.md``): Kulla & Conty 2017 add a lobe f_ms, Turquin 2019 scale
the lobe; :class:`CompensatedBRDF` is the result, a
:class:`~brdfkit.models.DerivedBRDF` built through the one constructor path of
derived models (its tables and lookups first, then the shared set-up).

Public objects
--------------
- :func:`compensate` — the operator; :func:`compensation_method` — the dispatcher.
- :class:`CompensatedBRDF`, :class:`CompensationWarning`, :class:`Method`.
- :data:`METHODS` — the registry of methods by name.
"""

from __future__ import annotations

import math
import warnings
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from brdfkit._array import as_directions, as_uniform
from brdfkit._dual import Formulas, numpy_version
from brdfkit.compensation.kernels import (
    WEIGHT_DEGREE,
    kc_weight,
    kulla_conty_formula,
    kulla_conty_kernel,
    kulla_conty_sampler,
    turquin_formula,
    turquin_kernel,
)
from brdfkit.compensation.table import compensation_table
from brdfkit.errors import ParameterError
from brdfkit.models._base import BRDF, DerivedBRDF, Lobe
from brdfkit.models.sampling import COSINE, Mixture, Strategy

__all__ = ["METHODS", "CompensatedBRDF", "CompensationWarning", "Method", "compensate",
           "compensation_method"]


#: Chebyshev nodes of the sampler weight's polynomial fit (kernels.WEIGHT_DEGREE + 1 would
#: interpolate; 4× as many smooth it over Ẽ's steep rim)
WEIGHT_NODES = 4 * (WEIGHT_DEGREE + 1)


class CompensationWarning(UserWarning):
    """The base's albedo exceeds 1 somewhere: E is clamped at 1 there (nothing restored)."""


@dataclass(frozen=True)
class Method:
    """One compensation method: ``key``, the paper (``citation``), whether it keeps a
    reciprocal base reciprocal, the kernel factory ``kernel(base_kernel, k)`` and the
    channel constant ``constant(model)`` the kernel reads at ``p[k]``."""

    key: str
    citation: str
    keeps_reciprocity: bool
    kernel: Callable
    constant: Callable


def _kc_constant(m: CompensatedBRDF) -> np.ndarray:
    # F_ms/(π(1 − E_avg)); a lossless white form (E_avg = 1 to rounding) has no f_ms
    loss = 1.0 - m.e_avg
    return np.where(loss > 1e-12, m.f_ms / (math.pi * np.maximum(loss, 1e-12)), 0.0)


def _turquin_constant(m: CompensatedBRDF) -> np.ndarray:
    return m.f0


#: The compensation methods by name (the dispatcher :func:`compensation_method` lists them).
METHODS: dict[str, Method] = {
    "kulla-conty": Method(
        "kulla-conty", "Kulla & Conty 2017, 'Revisiting physically based shading at "
        "Imageworks', energy compensation f_ms with F_ms for coloured Fresnel",
        True, kulla_conty_kernel, _kc_constant),
    "turquin": Method(
        "turquin", "Turquin 2019, 'Practical multiple scattering compensation for "
        "microfacet models', eq. (10): f (1 + F0 (1 - E)/E)", False, turquin_kernel,
        _turquin_constant),
}
_ALIASES = {"kc": "kulla-conty", "kulla_conty": "kulla-conty", "kullaconty": "kulla-conty"}


def compensation_method(name) -> Method:
    """The :class:`Method` named *name* (or an alias: ``kc``); the error lists the names."""
    key = str(name).strip().lower() if isinstance(name, str) else None
    key = _ALIASES.get(key, key)
    if key not in METHODS:
        raise ParameterError(f"compensate: method must be one of {', '.join(METHODS)}; "
                             f"got {name!r}")
    return METHODS[key]


class _BaseStrategy(Strategy):
    """A model's own sampler as a :class:`~brdfkit.models.sampling.Strategy` (a mixture
    component)."""

    def __init__(self, model: BRDF):
        self.model = model

    def sample(self, wo, u):
        return self.model.sample(wo, u)[0]

    def pdf(self, wi, wo):
        return self.model.pdf(wi, wo)


class CompensatedBRDF(DerivedBRDF):
    """A model with its single-scattering energy loss compensated (:func:`compensate`).

    Kulla–Conty: f = f_base + F_ms (1 − E(μ_o))(1 − E(μ_i))/(π (1 − E_avg));
    Turquin: f = f_base (1 + F₀ (1 − E(μ_i))/E(μ_i)) — E the albedo of the base's
    white form (``fresnel_split().white``, else the base itself), tabulated
    (:attr:`table`). The base's parameters pass through (:meth:`with_params`
    recompensates with new values).

    Attributes
    ----------
    base : BRDF
        The compensated model.
    method : str
        ``"kulla-conty"`` or ``"turquin"``.
    white : BRDF
        The base's white form, whose albedo E is tabulated.
    table : CompensationTable
        E(μ), its lookups and E_avg, with their accuracy (``table.message``).
    f0, f_avg, e_avg, f_ms : ndarray (C,)
        F₀ and F_avg of the split (1 without one), E_avg, and
        F_ms = F_avg² E_avg/(1 − F_avg (1 − E_avg)) per channel (C = rows of ``packed``).
    """

    @property
    def fit_base(self) -> BRDF:
        """A fit starts from the base's fit (``BRDF.fit_base``)."""
        return self.base

    def __init__(self, base: BRDF, method: str = "kulla-conty"):
        spec = compensation_method(method)
        self.base, self.method = base, spec.key
        split = base.fresnel_split()
        self.white = base if split is None else split.white
        n_rows = base.packed.shape[0]
        ones = np.ones(n_rows)
        self.f0 = ones if split is None else np.broadcast_to(split.f0, (n_rows,)).copy()
        self.f_avg = ones if split is None else np.broadcast_to(split.f_avg, (n_rows,)).copy()
        self.table = table = compensation_table(self.white)
        if table.n_channels not in (1, n_rows):
            raise ParameterError(
                f"compensate: the white form of {base.name} has {table.n_channels} channels, "
                f"the model {n_rows}")
        # warned only beyond the table's own accuracy: a lobe whose albedo reaches 1 by
        # rounding (modified-phong n = 1 at normal incidence) is clamped silently
        if table.clamped and (float(np.max(table.max_albedo)) > 1.0 + table.engine_tol
                              + float(np.max(table.interp_error))):
            warnings.warn(
                f"compensate: the albedo of {self.white.name} reaches "
                f"{float(np.max(table.max_albedo)):.6g} > 1 (it gains energy); E is clamped "
                "at 1 there, so nothing is restored where it already exceeds 1",
                CompensationWarning, stacklevel=3)
        self.e_avg = np.broadcast_to(table.e_avg, (n_rows,)).copy()
        fa = self.f_avg
        self.f_ms = fa * fa * self.e_avg / (1.0 - fa * (1.0 - self.e_avg))
        self.constant = spec.constant(self)
        kernel = driver = None
        if base.kernel is not None:
            # a base whose eval is a formula (branch-free and total: the _dual contract)
            # composes into the vectorising loop, like its own eval (microfacet's), unless
            # the formula says it is not for that loop (Formulas.vectorise: an unrolled net)
            formulas = base.formulas()
            vector = formulas is not None and formulas.eval is not None and formulas.vectorise
            kernel, driver = spec.kernel(formulas.eval if vector else base.kernel,
                                         base.packed.shape[1], vector=vector,
                                         uniform=table.uniform)
        own = ("its own white form: all energy missing from its albedo (absorption "
               "included) is treated as lost to unmodelled multiple scattering, so its "
               "white furnace goes to 1 in every channel" if split is None else
               "E of its white (F = 1) form, the restored energy weighted by "
               + ("F_ms" if spec.key == "kulla-conty" else "F0"))
        super().__init__(
            name=f"{base.name}+{spec.key}", params=base.params, values=base.values,
            citation=f"{base.citation}; compensated: {spec.citation}",
            summary=f"{base.name} with energy compensation ({spec.key}; {own})",
            reciprocal=base.reciprocal and spec.keeps_reciprocity,
            has_sampler=base.has_sampler, isotropic=True,
            mirror_symmetric=base.mirror_symmetric, has_delta=base.has_delta,
            width_param=base.width_param, kernel=kernel)
        self._driver = driver
        # the base's channels (a material declares them by its packed rows, not by colour
        # parameters, which the shared set-up counts)
        self.n_channels = base.n_channels
        self.albedo_kinks = base.albedo_kinks
        self.albedo_kink_mus = base.albedo_kink_mus

    def albedo_kinks_nv(self, theta):
        """The base's kink circles N·V = k (the compensation multiplies or adds functions of
        μ_i and μ_o only, so the base's kinks stay and no new circle appears)."""
        return self.base.albedo_kinks_nv(theta)

    # ---------------------------------------------------------------- packing
    def _pack(self) -> np.ndarray:
        """Per channel c: the base's row, the constant at p[K], the lookup of Ẽ at p[K+1:]
        (:mod:`brdfkit.compensation.kernels`), padded to the longest channel."""
        base = self.base.packed
        rows = [np.concatenate([base[c], [self.constant[c]],
                                self.table.lookups[c % self.table.n_channels].packed(0)])
                for c in range(base.shape[0])]
        width = max(r.size for r in rows)
        return np.ascontiguousarray(np.array(
            [np.concatenate([r, np.zeros(width - r.size)]) for r in rows], dtype=np.float64))

    # -------------------------------------------------------------- evaluation
    def _e(self, mu) -> np.ndarray:
        """Ẽ(μ) per row of ``packed``: shape ``mu.shape + (C,)``."""
        e = self.table(mu)  # clamped at 1, as the kernels read it
        return np.broadcast_to(e, (*e.shape[:-1], self.packed.shape[0]))

    def eval(self, wi, wo) -> np.ndarray:
        """The compensated f_r(wi, wo) in 1/sr (see :meth:`BRDF.eval`)."""
        if self.kernel is not None:
            return super().eval(wi, wo)
        wi = as_directions(wi, "wi")
        wo = as_directions(wo, "wo")
        f = np.asarray(self.base.eval(wi, wo), dtype=np.float64)
        grey = self.n_channels is None
        e_i, e_o = self._e(wi[..., 2]), self._e(wo[..., 2])
        if self.method == "kulla-conty":
            up = (wi[..., 2] > 0.0) & (wo[..., 2] > 0.0)
            ms = self.constant * (1.0 - e_i) * (1.0 - e_o) * up[..., None]
            return f + (ms[..., 0] if grey else ms)
        factor = 1.0 + self.f0 * (1.0 - e_i) / e_i
        return f * (factor[..., 0] if grey else factor)

    __call__ = eval

    def specular_albedo(self, theta_i):
        """The base's delta term: unchanged (Kulla–Conty), times the factor (Turquin)."""
        s = self.base.specular_albedo(theta_i)
        if s is None or self.method == "kulla-conty":
            return s
        th = np.asarray(theta_i, dtype=np.float64)
        e = self._e(np.cos(th))
        factor = 1.0 + self.f0 * (1.0 - e) / e
        return s * (factor[..., 0] if np.ndim(s) == th.ndim else factor)

    def formulas(self) -> Formulas | None:
        """With a base that gives formulas (and no tables of its own): eval composed with Ẽ
        read in the trace (:func:`~brdfkit.compensation.kernels.turquin_formula`,
        :func:`~brdfkit.compensation.kernels.kulla_conty_formula`); Turquin samples with the
        base's sampler, Kulla–Conty with its mixture of the cosine and the base's sampler
        (:func:`~brdfkit.compensation.kernels.kulla_conty_sampler`), as :meth:`sample`."""
        base = self.base.formulas()
        if self.kernel is None or base is None or base.tables is not None:
            return None
        k = self.base.packed.shape[1]
        if self.method == "turquin":
            return Formulas(eval=turquin_formula(base.eval, k, uniform=self.table.uniform),
                            sample=base.sample, pdf=base.pdf, args=base.args, tables=k + 1,
                            vectorise=base.vectorise)
        sample, pdf = kulla_conty_sampler(base.sample, base.pdf, len(base.args))
        return Formulas(eval=kulla_conty_formula(base.eval, k, uniform=self.table.uniform),
                        sample=sample, pdf=pdf, args=(*self._weight_args(), *base.args),
                        tables=k + 1, vectorise=base.vectorise)

    # ---------------------------------------------------------------- sampling
    def _weight_args(self) -> tuple:
        """(F̄_ms, F̄_avg, q₀ … q₆) of :func:`~brdfkit.compensation.kernels.kc_weight`: the
        channel means, and the least-squares polynomial in x = 2μ − 1 of the channel mean
        of Ẽ(μ) at WEIGHT_NODES Chebyshev points (the weight steers variance only: a
        formula sampler reads no table)."""
        x = np.cos(np.pi * (np.arange(WEIGHT_NODES) + 0.5) / WEIGHT_NODES)
        e = np.mean(self._e(0.5 * (x + 1.0)), axis=-1)
        q = np.polynomial.polynomial.polyfit(x, e, WEIGHT_DEGREE)
        return (float(np.mean(self.f_ms)), float(np.mean(self.f_avg)),
                *(float(c) for c in q))

    def _strategy(self, wo: np.ndarray) -> Strategy:
        """Kulla–Conty: the base's sampler mixed with cos θ_i/π for f_ms, weighted by
        f_ms's share of the albedo at ω_o, F̄_ms(1 − E)/(F̄_ms(1 − E) + F̄_avg E) (channel
        means; exact for F = 1, where the base's albedo is E; E the polynomial of
        :meth:`_weight_args`, as the traced sampler reads it)."""
        with np.errstate(all="ignore"):  # the discarded side of the weight's select
            w = numpy_version(kc_weight)(wo[..., 2], *self._weight_args())
        return Mixture([COSINE, _BaseStrategy(self.base)], np.stack([w, 1.0 - w], axis=-1))

    def sample(self, wo, u):
        """Draw wi given wo from *u* ∈ [0, 1]² (..., 2); returns ``(wi, pdf)``. Turquin:
        the base's sampler (the lobe reweighted by a factor of θ_i only)."""
        if self.method == "turquin":
            return self.base.sample(wo, u)
        wo = as_directions(wo, "wo")
        u = as_uniform(u)
        wi = self._strategy(wo).sample(wo, u)
        return wi, self.pdf(wi, wo)

    def pdf(self, wi, wo):
        """Solid-angle density of :meth:`sample`; 0 when wo is below the horizon."""
        if self.method == "turquin":
            return self.base.pdf(wi, wo)
        wi = as_directions(wi, "wi")
        wo = as_directions(wo, "wo")
        p = self._strategy(wo).pdf(wi, wo)
        return np.where(wo[..., 2] > 0.0, p, 0.0)

    def lobes(self):
        """The base's lobes; Kulla–Conty adds f_ms's diffuse one."""
        lobes = list(self.base.lobes())
        return lobes + [Lobe("diffuse", math.pi / 2)] if self.method == "kulla-conty" else lobes

    # --------------------------------------------------------------- accessors
    def with_params(self, **changes) -> BRDF:
        """The same compensation of the base with some parameters changed."""
        return compensate(self.base.with_params(**changes), self.method)

    def to_dict(self) -> dict:
        """The base's dict plus ``"compensate": {"method": METHOD}``."""
        d = self.base.to_dict()
        d["compensate"] = {"method": self.method}
        return d

    def describe(self) -> dict:
        """As :meth:`DerivedBRDF.describe`, plus ``"compensation"``: the method, F₀, F_avg,
        F_ms, E_avg and the table's accuracy."""
        d = super().describe()
        d["compensation"] = {"method": self.method, "white": self.white.to_dict(),
                             "f0": self.f0.tolist(), "f_avg": self.f_avg.tolist(),
                             "f_ms": self.f_ms.tolist(), "table": self.table.to_dict()}
        return d

    def __repr__(self) -> str:
        return f"brdfkit.compensate({self.base!r}, method={self.method!r})"


def compensate(model: BRDF, method: str = "kulla-conty") -> CompensatedBRDF:
    """Compensate the energy *model*'s lobe loses to unmodelled multiple scattering.

    Parameters
    ----------
    model : BRDF
        An isotropic model whose albedo the engine computes (registered, measured, a
        user's, pumped); not already compensated. A model with a Fresnel factor
        declares its white form (:meth:`BRDF.fresnel_split`).
    method : {"kulla-conty", "turquin"}
        ``"kulla-conty"`` (alias ``"kc"``): add f_ms (reciprocal when the base is);
        ``"turquin"``: scale by 1 + F₀(1 − E(μ_i))/E(μ_i) (not reciprocal; brdfkit's
        furnace, which holds ω_i fixed, reads 1).

    Returns
    -------
    CompensatedBRDF

    Raises
    ------
    ParameterError
        Not a model, an unknown method (the valid ones listed), an anisotropic base,
        or a base already compensated.

    Warns
    -----
    CompensationWarning
        The base's white albedo exceeds 1 somewhere (clamped at 1 there).

    Examples
    --------
    >>> import brdfkit
    >>> m = brdfkit.compensate(brdfkit.model("microfacet", distribution="ggx", alpha=0.5))
    """
    if not isinstance(model, BRDF):
        raise ParameterError(
            f"compensate: model must be a brdfkit model (BRDF); got {type(model).__name__}")
    spec = compensation_method(method)
    if not model.isotropic:
        raise ParameterError(
            f"compensate: {model.name} is anisotropic; E(mu) is tabulated as a function of "
            "the incidence angle only, which needs an isotropic base "
            "(docs/compensation.md, 'Anisotropic bases')")
    if "compensate" in model.to_dict():
        raise ParameterError(
            f"compensate: {model.name} is already compensated; compensate its base instead")
    return CompensatedBRDF(model, spec.key)
