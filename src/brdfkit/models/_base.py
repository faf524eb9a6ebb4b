"""
The model interface and its compiled evaluation driver
======================================================

Every reflectance model is a small object built from three pieces:

1. **Parameters** (:class:`Param`), declared once on the class with default,
   bounds, units and a description. The command line, the fitter and the
   explorer all read this declaration; there is no second list.
2. **A scalar kernel** ``kernel(ix, iy, iz, ox, oy, oz, p) -> float``: a
   Numba ``@njit`` function of the components of wi and wo (local frame,
   n = +z) and of ``p``, one channel's packed parameters (float64 1-D array).
   The kernel is where the paper's formula is written — once, over dot
   products, readable like the paper. It returns 0 below the horizon and a
   finite value at θ = 90°.
3. **Sampling** (:meth:`BRDF.sample`, :meth:`BRDF.pdf`), in NumPy. The base
   class provides the cosine-weighted fallback.

:meth:`BRDF.eval` validates the directions, broadcasts them, and runs the
kernel over all pairs and channels with :func:`eval_pairs`, a parallel
compiled loop (Numba ``prange`` over the 2 cores). The NumPy path would reach
~24 M evaluations/s for modified Phong; this one reaches ~100 M/s, which is
what lets brdfkit beat Mitsuba 3 end to end (see ``benchmarks/``).

Public objects
--------------
- :class:`Param`, :class:`Lobe` — a declared parameter, a lobe (defined in
  :mod:`brdfkit.models._param`, imported here).
- :class:`BRDF` — the base class of all models; it declares the model protocol.
- :class:`DerivedBRDF` — the one constructor path for models built from others.
- :class:`FresnelSplit` — what :meth:`BRDF.fresnel_split` returns: a model with a Fresnel
  factor as its white (F = 1) form and the factor's moments F₀, F_avg.
- :func:`eval_pairs`, :func:`eval_pairs_checked`, :func:`checked_driver` — the
  compiled loops over all pairs, defined in :mod:`brdfkit.models._drivers` and
  imported here (the loop :meth:`BRDF.eval` runs: :func:`~brdfkit.models._drivers.loop_driver`).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import ClassVar

import numpy as np

from brdfkit._array import as_directions, as_uniform
from brdfkit._dual import Formulas
from brdfkit._threads import numba_threads
from brdfkit.errors import BrdfkitError, ParameterError
from brdfkit.models._drivers import (  # noqa: F401  (re-exported: models import them here)
    SERIAL_BELOW,
    UNIT_TOL,
    VECTOR_OPTIONS,
    _unit_pair,
    cached_driver,
    checked_driver,
    eval_pairs,
    eval_pairs_checked,
    loop_driver,
)
from brdfkit.models._param import (  # noqa: F401  (re-exported: models import them here)
    Lobe,
    Param,
    _check_beta,
)
from brdfkit.models.sampling import COSINE

__all__ = ["Param", "Lobe", "BRDF", "DerivedBRDF", "FresnelSplit", "checked_driver",
           "eval_pairs", "eval_pairs_checked"]


@dataclass(frozen=True)
class FresnelSplit:
    """A model with a Fresnel factor, split as f = F · f_white (:meth:`BRDF.fresnel_split`).

    Attributes
    ----------
    white : BRDF
        The model with F = 1 (and any scale that multiplies F set to 1): the form whose
        albedo E(μ) the compensation operators tabulate (Kulla & Conty 2017, §
        "multiple scattering"; Turquin 2019, eq. 10 uses E of F = 1).
    f0 : ndarray (C,)
        F(1), the factor at normal incidence (Turquin's F₀).
    f_avg : ndarray (C,)
        2∫₀¹ F(μ) μ dμ, the cosine-weighted average (Kulla & Conty's F_avg).

    C is the model's channel count (1 for a grey model).
    """

    white: BRDF
    f0: np.ndarray
    f_avg: np.ndarray


class BRDF:
    """Base class of every reflectance model.

    Subclasses set the class attributes below, write ``kernel`` and, where a
    good sampler exists, override :meth:`sample` and :meth:`pdf`.

    Class attributes
    ----------------
    name : str
        Canonical registry name (``modified-phong``).
    aliases : tuple of str
        Other accepted names.
    params : tuple of Param
        The declared parameters.
    citation : str
        Paper and equation number.
    reciprocal : bool
        Whether the formula is symmetric in (wi, wo) for all parameters.
    has_sampler : bool
        True when :meth:`sample` follows the lobe (not the cosine fallback).
    width_param : str or None
        The parameter that a half-angle ``beta`` (radians) converts to.

    The model protocol
    ------------------
    Everything an engine (albedo, plausibility, pumping, sampling tests,
    renderers, fitting, the explorer) needs from a model is declared here, with
    a default; engines read only these and never name a model:

    - :attr:`isotropic` — f depends on the azimuths only through their
      difference (rotation invariance about the normal).
    - :attr:`mirror_symmetric` — f is moreover even in that difference
      (mirror symmetry about the plane of incidence), read with :attr:`isotropic`.
    - :attr:`kernel`, :attr:`packed`, :attr:`n_channels` — the compiled formula
      and its packed parameters (``kernel is None``: the model evaluates in
      :meth:`eval` itself, e.g. a pumped model with a user g).
    - :meth:`lobes` and :meth:`sharpest_lobe` — where the energy concentrates
      (the one reading of :meth:`lobes` every engine uses).
    - :attr:`albedo_kinks`, :meth:`albedo_kinks_nv`, :attr:`albedo_kink_mus` —
      kinks the albedo engine and the pumping tables make break points.
    - :attr:`has_delta`, :meth:`specular_albedo` — a specular delta term that
      is not in the kernel.
    - :attr:`reciprocal`, :attr:`has_sampler`, :meth:`sample`, :meth:`pdf`.
    - :meth:`formulas` — f_r, sampler and pdf as formulas Dr.Jit can trace
      (:class:`brdfkit._dual.Formulas`), or None (the default).
    - :meth:`fresnel_split` — the white (F = 1) form and F₀, F_avg of a model with a
      Fresnel factor, or None (the default: the model is its own white form).
    - :meth:`provenance` — what a verdict on the model is a verdict on, when that is a
      representation of data (a surrogate, a table), or None (the default: a formula).

    Models built from other models (pumped, measured, fitted, wrapped) derive
    from :class:`DerivedBRDF`, which passes through the same set-up.
    """

    name: ClassVar[str] = ""
    aliases: ClassVar[tuple[str, ...]] = ()
    params: ClassVar[tuple[Param, ...]] = ()
    citation: ClassVar[str] = ""
    summary: ClassVar[str] = ""
    reciprocal: ClassVar[bool] = True
    has_sampler: ClassVar[bool] = False
    width_param: ClassVar[str | None] = None
    #: Parameter sets exercised by the registry-wide tests (χ², physics
    #: properties, albedo cross-checks): a typical one first, then extreme ones
    #: (sharp lobes, grazing-sensitive settings, coloured parameters).
    examples: ClassVar[tuple[dict, ...]] = ({},)
    #: The compiled scalar kernel ``kernel(ix, iy, iz, ox, oy, oz, p) -> float`` (module
    #: docstring); None for a model that evaluates in NumPy (it overrides :meth:`eval`).
    kernel: Callable | None = None
    #: Whether f(ω_i, ω_o) depends on the azimuths only through φ_i − φ_o (rotation
    #: invariance about the normal). Pumping and compensation need it (the albedo is then a
    #: function of θ_i alone); analyses then evaluate at φ_i = 0.
    isotropic: ClassVar[bool] = True
    #: Whether f(ω_i, ω_o) is moreover even in φ_i − φ_o: unchanged when both directions are
    #: mirrored in the plane of incidence. Only then does the albedo engine integrate half
    #: the azimuths and double, and the reciprocity check try one side of the plane. A
    #: rotation-invariant model need not be even: a net fitted to measured data (NBRDF), a
    #: noisy measured table, a chiral formula. Every registered model that claims it is
    #: checked numerically by the registry-wide tests.
    mirror_symmetric: ClassVar[bool] = True
    #: Kinks of ω_o ↦ f(ω_i, ω_o) on curves known in closed form, made panel edges by the
    #: albedo engine in every frame: ``"nv=nl"`` (a max(N·L, N·V) in the formula, e.g.
    #: Neumann eq. 22) and ``"vgroove"`` (the branches of the V-groove shadowing
    #: G = min(1, 2(N·H)(N·V)/(V·H), 2(N·H)(N·L)/(L·H)) cross). Unlisted kinks are left to
    #: the engine's refinement, which then costs more nodes.
    albedo_kinks: ClassVar[frozenset[str]] = frozenset()
    #: cos θ_i where the directional albedo a(θ_i) itself has a kink (for tables of it,
    #: e.g. the pumping tables); () when a is smooth.
    albedo_kink_mus: tuple[float, ...] = ()
    #: Whether the model has a specular delta term that is not in :attr:`kernel` (its
    #: energy is :meth:`specular_albedo`).
    has_delta: ClassVar[bool] = False
    #: Parameter coordinates (labels as ``"C_z[0]"``) that a fit holds at their given value:
    #: a gauge freedom, the model unchanged when they move with others (e.g. Lafortune's
    #: first lobe: (C_xy, C_z) → t·(C_xy, C_z) with ρ_s → ρ_s / tⁿ). Fitted, they make the
    #: loss exactly flat along a curve and the optimiser crawl along it to its budget.
    fit_gauge: ClassVar[tuple[str, ...]] = ()
    #: Bounded shape parameters whose bounds are sub-models (e.g. Nielsen's α: 0 Phong-like,
    #: 1 Blinn-like): a fit also starts its search near each bound, so that it does not
    #: settle in one end's basin when the other end fits better.
    fit_bound_starts: ClassVar[tuple[str, ...]] = ()
    #: The model a fit of this derived model starts from, or None (a model fitted on its
    #: own). A fit of a model with a ``fit_base`` and no parameters it can solve in
    #: closed form (a pumped model: g depends on them) fits the base first — faster, its
    #: linear parameters in closed form — and starts its joint stage from the base's
    #: optimum; a half-width's first guess of the width uses the base's
    #: ``width_from_beta`` (the lobe keeps its shape). How it is evaluated meanwhile is the
    #: operator's (``brdfkit.pumping.surrogate``: a fast stand-in). Pumped models: their
    #: unpumped root.
    fit_base: BRDF | None = None
    #: Compiled loop specialised to ``kernel`` (:func:`checked_driver`), or None for the
    #: checked loop generated for ``kernel`` (:func:`loop_driver`; a composite or table
    #: kernel, e.g. pumped or measured, sets one).
    _driver: Callable | None = None

    # ------------------------------------------------------------------ set-up
    def __init__(self, **values):
        declared = {p.name: p for p in self.params}
        beta = values.pop("beta", None)
        unknown = sorted(set(values) - set(declared))
        if unknown:
            raise ParameterError(
                f"{self.name}: unknown parameter {unknown[0]!r}; valid parameters: "
                + ", ".join(declared) + (", beta" if self.width_param else "")
            )
        if beta is not None:
            if self.width_param is None:
                raise ParameterError(
                    f"{self.name}: has no lobe width, so 'beta' is not a parameter; valid "
                    "parameters: " + ", ".join(declared)
                )
            if self.width_param in values:
                raise ParameterError(
                    f"{self.name}: give either 'beta' or {self.width_param!r}, not both"
                )
            values[self.width_param] = self.width_from_beta(_check_beta(self.name, beta))
        self._setup(values)

    def _setup(self, values: dict) -> None:
        """The set-up every model passes through, registered or derived: validate each
        declared parameter (defaults for the missing ones), check per-lobe and per-channel
        lengths, the subclass's cross-parameter checks, then pack the kernel's rows."""
        self._values: dict = {}
        for p in self.params:
            v = values.get(p.name, p.default)
            self._values[p.name] = p.validate(v, self.name)
        self._check_lobes()
        self.n_channels = self._count_channels()
        self._validate()
        self._packed = self._pack()

    @classmethod
    def width_from_beta(cls, beta: float) -> float:
        """Width parameter for half-angle *beta* (radians); see :mod:`brdfkit.halfangle`."""
        raise NotImplementedError

    def _validate(self) -> None:
        """Cross-parameter checks of a subclass (raise :class:`ParameterError`)."""

    def _check_lobes(self) -> None:
        sizes = {p.name: np.size(self._values[p.name]) for p in self.params
                 if p.kind == "lobes" and np.ndim(self._values[p.name]) == 1}
        if len(set(sizes.values())) > 1:
            raise ParameterError(
                f"{self.name}: per-lobe parameters must have the same length; got "
                + ", ".join(f"{k}={v}" for k, v in sizes.items())
            )

    def _count_channels(self) -> int | None:
        sizes = {p.name: np.size(self._values[p.name]) for p in self.params
                 if p.kind == "colour" and np.ndim(self._values[p.name]) == 1}
        if not sizes:
            return None
        if len(set(sizes.values())) > 1:
            raise ParameterError(
                f"{self.name}: per-channel parameters must have the same number of channels; "
                "got " + ", ".join(f"{k}={v}" for k, v in sizes.items())
            )
        return next(iter(sizes.values()))

    def n_lobes(self) -> int:
        """Number of lobes given by ``lobes`` parameters (1 when all are scalar)."""
        sizes = [np.size(self._values[p.name]) for p in self.params if p.kind == "lobes"]
        return max(sizes, default=1)

    def channel_values(self, c: int) -> dict:
        """Parameter values of channel *c* (colour parameters indexed, others as given)."""
        out = {}
        for p in self.params:
            v = self._values[p.name]
            if v is None:
                v = None
            elif p.kind == "colour" and np.ndim(v) == 1:
                v = float(v[c])
            elif p.kind == "lobes":
                v = np.broadcast_to(np.atleast_1d(v), (self.n_lobes(),)).astype(np.float64)
            out[p.name] = v
        return out

    def _pack_channel(self, v: dict) -> list[float]:
        """One channel's kernel argument ``p``; default: declared order, choices as index,
        bools as 1.0/0.0."""
        row = []
        for p in self.params:
            if v[p.name] is None:
                row.append(0.0)  # "not given": kernels test for 0 (see Param.optional)
            elif p.kind == "bool":
                row.append(1.0 if v[p.name] else 0.0)
            elif p.kind == "choice":
                row.append(float(p.choices.index(v[p.name])))
            elif p.kind == "lobes":
                row.extend(np.asarray(v[p.name], dtype=np.float64).tolist())
            else:
                row.append(float(v[p.name]))
        return row

    def _pack(self) -> np.ndarray:
        rows = [self._pack_channel(self.channel_values(c)) for c in range(self.n_channels or 1)]
        return np.ascontiguousarray(np.array(rows, dtype=np.float64))

    def _driver_data(self) -> np.ndarray:
        """What :meth:`eval` passes to :attr:`_driver` in place of the packed rows (default:
        :attr:`packed`; a table model passes its table in the layout its driver reads)."""
        return self._packed

    def lobes(self) -> list[Lobe]:
        """The lobes of this parameterisation (see :class:`Lobe`); default: one diffuse."""
        return [Lobe("diffuse", math.pi / 2)]

    def sharpest_lobe(self) -> Lobe:
        """The lobe that sets the resolution of every numerical engine.

        The one reading of :meth:`lobes` (albedo quadrature frame, χ² binning,
        table grids): the width is the smallest width of all lobes (π/2 at most;
        a non-finite or non-positive width counts as π/2); the kind is that
        lobe's, except that a ``mirror`` or ``half`` lobe, where the model has
        one, wins over a sharper ``normal``/``diffuse`` one (the directional
        lobe's frame places its peak and horizon cut exactly; a narrow lobe
        about the normal is still resolved there by the width). No lobes:
        ``Lobe("diffuse", π/2)``.
        """
        lobes = list(self.lobes())
        if not lobes:
            return Lobe("diffuse", math.pi / 2)
        best = min(lobes, key=lambda lb: lb.width)
        width = float(best.width)
        if not math.isfinite(width) or width <= 0.0:
            width = math.pi / 2
        kind = best.kind
        if kind in ("normal", "diffuse"):
            kind = next((lb.kind for lb in lobes if lb.kind in ("mirror", "half")), kind)
        return Lobe(kind, min(width, math.pi / 2))

    def albedo_kinks_nv(self, theta) -> np.ndarray | None:
        """Levels k of N·V where ω_o ↦ f(ω_i, ω_o) has a kink, per incidence angle.

        For θ_i in *theta* (radians, 1-D), shape ``(T, K)``: up to 12 levels k
        per angle (NaN: none) of circles N·V = k that the albedo engine makes
        panel edges (e.g. where a pumped model's g switches branch). Default:
        None (no such kinks).
        """
        return None

    def albedo_half_axes(self) -> tuple[float, float, float] | None:
        """(a_x, a_y, q) of a half-vector lobe d(tan²θ_h (cos²ψ/a_x² + sin²ψ/a_y²)), d = e^{−x}
        (q = 0) or (1 + x)^{−2} (q = 1): where the albedo engine grades the azimuth
        (:func:`brdfkit.analysis.quadrature._axis_breaks`; panel edges only). Default: None."""
        return None

    def specular_albedo(self, theta_i) -> np.ndarray | None:
        """Albedo of the specular delta term not in :attr:`kernel` at θ_i (radians).

        Shape ``theta_i.shape`` (+ ``(C,)`` when coloured). The albedo engine
        adds it to the integral of the kernel. Default (``has_delta`` false):
        None.
        """
        return None

    # --------------------------------------------------------------- accessors
    @property
    def values(self) -> dict:
        """The parameter values (a copy; arrays for per-channel values)."""
        return {k: (v.copy() if isinstance(v, np.ndarray) else v) for k, v in self._values.items()}

    @property
    def packed(self) -> np.ndarray:
        """Packed kernel parameters, shape (C, K) — read-only view."""
        view = self._packed.view()
        view.flags.writeable = False
        return view

    def with_params(self, **changes) -> BRDF:
        """A new model of the same kind with some parameters changed."""
        merged = self.values
        if "beta" in changes and self.width_param:
            merged.pop(self.width_param, None)
        merged.update(changes)
        return type(self)(**merged)

    def to_dict(self) -> dict:
        """``{"model": name, "params": {...}}`` with lists for per-channel values."""
        return {
            "model": self.name,
            "params": {k: (v.tolist() if isinstance(v, np.ndarray) else v)
                       for k, v in self._values.items()},
        }

    def __repr__(self) -> str:
        args = ", ".join(f"{k}={(v.tolist() if isinstance(v, np.ndarray) else v)!r}"
                         for k, v in self._values.items())
        return f"brdfkit.model({self.name!r}, {args})"

    # -------------------------------------------------------------- evaluation
    def eval(self, wi, wo) -> np.ndarray:
        """BRDF value f_r(wi, wo) in 1/sr, without the cosine factor.

        Parameters
        ----------
        wi, wo : array_like, shape (..., 3)
            Unit directions toward the light and the viewer (local frame,
            normal +z). Leading axes broadcast against each other.

        Returns
        -------
        ndarray, shape (...) or (..., C)
            0 below the horizon. A trailing channel axis when any colour
            parameter was given per channel.
        """
        # finiteness and unit length are tested in the compiled pass: one read of the data
        wi_in, wo_in = wi, wo
        wi = as_directions(wi, "wi", check_finite=False)
        wo = as_directions(wo, "wo", check_finite=False)
        try:
            shape = np.broadcast_shapes(wi.shape[:-1], wo.shape[:-1])
        except ValueError:
            raise BrdfkitError(
                f"wi and wo must broadcast against each other; got shapes {wi.shape} and "
                f"{wo.shape}"
            ) from None
        # (N, 3) C-contiguous: a view when the input already is, else one copy
        if wi.shape[:-1] != shape:
            wi = np.broadcast_to(wi, (*shape, 3))
        if wo.shape[:-1] != shape:
            wo = np.broadcast_to(wo, (*shape, 3))
        wi2 = np.ascontiguousarray(wi).reshape(-1, 3)
        wo2 = np.ascontiguousarray(wo).reshape(-1, 3)
        out = np.empty((wi2.shape[0], self._packed.shape[0]))
        # the model's own loop, else the checked loop generated for its kernel (cached on
        # disk: models/_drivers.py); small calls on this thread alone (SERIAL_BELOW)
        if self._driver is not None:
            driver, data = self._driver, self._driver_data()
        else:
            driver, data = loop_driver(self.kernel), self._packed
        with numba_threads(1 if wi2.shape[0] < SERIAL_BELOW else None):
            n_bad = driver(wi2, wo2, data, out)
        if n_bad:
            as_directions(wi_in, "wi")  # raises the usual BrdfkitError for NaN/inf
            as_directions(wo_in, "wo")
            for name, w in (("wi", wi2), ("wo", wo2)):
                norm2 = np.einsum("ij,ij->i", w, w)
                bad = np.flatnonzero(~(np.abs(norm2 - 1.0) <= UNIT_TOL))
                if bad.size:
                    raise BrdfkitError(
                        f"{name} must hold unit vectors (squared norm within {UNIT_TOL:g} of 1); "
                        f"got norm {math.sqrt(norm2[bad[0]]):.9g} at flat index {bad[0]} "
                        f"({bad.size} of {norm2.size}): normalise your vectors"
                    )
            raise BrdfkitError("wi or wo is not a finite unit vector")  # unreachable
        if self.n_channels is None:
            return out[:, 0].reshape(shape)
        return out.reshape(*shape, self.n_channels)

    __call__ = eval

    # ---------------------------------------------------------------- sampling
    def sample(self, wo, u) -> tuple[np.ndarray, np.ndarray]:
        """Draw wi given wo from uniform numbers *u* ∈ [0, 1]², shape (..., 2).

        Returns ``(wi, pdf)`` with the solid-angle density of wi. The base
        class samples cos θ_i/π (the fallback for models with no better
        sampler); subclasses follow their lobes. Directions with pdf 0 must be
        discarded by the caller.
        """
        wo = as_directions(wo, "wo")
        u = as_uniform(u)
        wi = COSINE.sample(wo, u)
        wi = np.broadcast_to(wi, np.broadcast_shapes(wi.shape, wo.shape)).copy()
        return wi, self.pdf(wi, wo)

    def fresnel_split(self) -> FresnelSplit | None:
        """The white (F = 1) form of a model with a Fresnel factor, and F₀ and F_avg.

        Returns a :class:`FresnelSplit` when f = F · f_white with a factor F that the
        model's parameters set (a Fresnel term, a scale multiplying it); the energy
        compensation operators (:mod:`brdfkit.compensation`) tabulate the albedo of
        ``white`` and weight the restored energy with F₀ (Turquin) or F_avg (Kulla–Conty).
        Default: None — the model is its own white form, F₀ = F_avg = 1.
        """
        return None

    def provenance(self) -> str | None:
        """Where the model's values come from when a verdict on it is a verdict on that
        representation rather than on a formula: a measured material's surrogate (a fitted
        net need not be reciprocal though the material is), a tabulated file. The
        plausibility check adds it to its notes. Default: None (a formula: its verdicts
        are the formula's)."""
        return None

    def formulas(self) -> Formulas | None:
        """eval, sample and pdf as formulas of :mod:`brdfkit._dual` (the Mitsuba bridge traces
        them), or None: the bridge then calls :meth:`eval`/:meth:`sample`/:meth:`pdf`."""
        return None

    def pdf(self, wi, wo) -> np.ndarray:
        """Solid-angle density of :meth:`sample` for wi given wo."""
        wi = as_directions(wi, "wi")
        wo = as_directions(wo, "wo")
        p = COSINE.pdf(wi, wo)
        return np.where(wo[..., 2] > 0.0, p, 0.0) * np.ones(np.broadcast_shapes(
            wi.shape, wo.shape)[:-1])

    # ------------------------------------------------------------ description
    @classmethod
    def describe(cls) -> dict:
        """JSON-ready description of the model class (``brdfkit models --json``)."""
        return {
            "name": cls.name,
            "aliases": list(cls.aliases),
            "summary": cls.summary,
            "citation": cls.citation,
            "reciprocal": cls.reciprocal,
            "has_sampler": cls.has_sampler,
            "beta": cls.width_param,
            "params": [p.to_dict() for p in cls.params],
        }


class DerivedBRDF(BRDF):
    """A model built from another one: pumped, measured, fitted or wrapped.

    The one constructor path for derived models: what a registered model class
    declares as class attributes (name, parameters, citation, claims) a derived
    model receives as arguments, per instance, and then passes through the same
    set-up as every model (:meth:`BRDF._setup`: parameter validation, channel
    count, packing). So a derived model is a model by construction: evaluate,
    sample, analyse, pump, fit, render. Subclasses build what their kernel needs
    (tables, lookups) *before* calling ``super().__init__`` (which packs), and
    override :meth:`with_params`, :meth:`to_dict` and :meth:`__repr__`.

    Parameters (keyword-only)
    -------------------------
    name, citation, summary : str
        As the class attributes of :class:`BRDF`.
    params : sequence of Param
        The parameters this model exposes (e.g. a pumped model: its root's).
    values : dict
        Their values (validated again against *params*).
    reciprocal, has_sampler, isotropic, mirror_symmetric, has_delta : bool
        The model's claims (see :class:`BRDF`).
    width_param : str or None
        The parameter a half-angle ``beta`` converts to.
    kernel : compiled kernel or None
        None: the subclass overrides :meth:`eval`.
    packed : array_like (C, K), optional
        The kernel's packed rows when they are not those of :meth:`BRDF._pack`
        for *params* (e.g. wrapping another model's kernel: ``other.packed``).
    """

    def __init__(self, *, name: str, params, values: dict, citation: str = "",
                 summary: str = "", reciprocal: bool, has_sampler: bool = False,
                 isotropic: bool = True, mirror_symmetric: bool = True,
                 has_delta: bool = False, width_param: str | None = None,
                 kernel: Callable | None = None, packed=None):
        self.name = str(name)
        self.params = tuple(params)
        self.citation = citation
        self.summary = summary
        self.reciprocal = bool(reciprocal)
        self.has_sampler = bool(has_sampler)
        self.isotropic = bool(isotropic)
        self.mirror_symmetric = bool(mirror_symmetric)
        self.has_delta = bool(has_delta)
        self.width_param = width_param
        self.kernel = kernel
        self._given_packed = (None if packed is None else np.ascontiguousarray(
            np.array(packed, dtype=np.float64, ndmin=2)))
        self._setup(dict(values))

    def _pack(self) -> np.ndarray:
        if self._given_packed is not None:
            return self._given_packed
        return super()._pack()

    def describe(self) -> dict:  # an instance method here: the declarations are per instance
        """JSON-ready description of this model (as :meth:`BRDF.describe`)."""
        return {
            "name": self.name,
            "aliases": [],
            "summary": self.summary,
            "citation": self.citation,
            "reciprocal": self.reciprocal,
            "has_sampler": self.has_sampler,
            "beta": self.width_param,
            "params": [p.to_dict() for p in self.params],
        }
