"""
A model from a user's file: its one description and the model built from it
============================================================================

Whatever file a user model comes from (a Python file, :mod:`brdfkit.user.python_file`;
a BRDF Explorer ``.brdf`` file, :mod:`brdfkit.user.brdf_file`), the loader describes it
once, as a :class:`ModelDefinition`, and :class:`FormulaBRDF` builds the model from it:
a :class:`~brdfkit.models.DerivedBRDF`, so it is evaluated, analysed, sampled, pumped,
fitted and rendered like every model, without any engine knowing where it came from.

What the model measures of itself, from its own values (each once per instance, on
first use, so that building one — a fit builds one per evaluation — stays cheap):

- **lobes** (:meth:`FormulaBRDF.lobes`, read by the albedo engine, the χ² binning and the
  tabulated sampler): at ω_o = N, the angle δ of ω_i from the normal where f − f_min
  falls to half its peak (f_min its floor over δ, e.g. a diffuse term), the peak at
  δ → 0; then at θ_o = 60° the same half-width out of the plane of incidence about the
  mirror direction: a lobe about the mirror direction keeps its width there (a function
  of R·V: ``mirror``, width δ½), a lobe of the half vector halves it (θ_h ≈ δ/(2 cos θ_d),
  θ_d = 60°: ``half``, width δ½/2, the θ_h half-width). No such peak (flat, or peaked
  elsewhere): one ``diffuse`` lobe, π/2. ~1 800 evaluations.
- **reciprocity**, when the file claims nothing (``reciprocal`` None): the relative
  asymmetry over the plausibility check's structured pair set
  (:func:`brdfkit.analysis.plausibility.reciprocity`) ≤ :data:`RECIPROCITY_TOL`, so that
  pumping takes a reciprocal file model and refuses a non-reciprocal one.

:func:`measure_isotropy` is the numerical isotropy test a loader may use.

Public objects
--------------
- :class:`ModelDefinition` — the one description of a user model.
- :class:`SamplerFormulas` — a user's own sampler and pdf, as formulas.
- :class:`FormulaBRDF` — the model of a definition with parameter values.
- :func:`interpreted_driver` — a kernel's NumPy version as a pair loop (no compilation).
- :func:`measure_isotropy` — whether a model is isotropic, numerically.
- :data:`RECIPROCITY_TOL`, :data:`ISOTROPY_TOL`.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field, replace

import numpy as np

from brdfkit._array import as_directions, as_uniform
from brdfkit._dual import Formulas, numpy_version
from brdfkit.data.sampler import TabulatedSampler
from brdfkit.errors import ParameterError
from brdfkit.models import DerivedBRDF, Lobe
from brdfkit.models._drivers import UNIT_TOL, loop_driver
from brdfkit.models.proxy_sampler import proxy_formulas
from brdfkit.user._loops import sampler_loops

__all__ = ["ModelDefinition", "SamplerFormulas", "FormulaBRDF", "measure_isotropy",
           "interpreted_driver", "RECIPROCITY_TOL", "ISOTROPY_TOL"]

#: Largest relative asymmetry |f(L,V) − f(V,L)| / max(|f(L,V)|, |f(V,L)|) of a model
#: measured reciprocal: rounding of a symmetric formula written in another order is ~1e-15.
RECIPROCITY_TOL = 1e-9
#: Largest relative change of f under a rotation about the normal or a mirror of both
#: directions of a model measured isotropic (rounding, as above).
ISOTROPY_TOL = 1e-9


@dataclass(frozen=True)
class SamplerFormulas:
    """A user model's own importance sampler, as formulas of :mod:`brdfkit._dual`.

    ============  ================================================================
    field         meaning
    ============  ================================================================
    sample        ``sample(ox, oy, oz, u0, u1, *args) -> (ix, iy, iz)``: a @formula
                  drawing ω_i (unit, local frame) given ω_o from u0, u1 ∈ [0, 1)
    pdf           ``pdf(ix, iy, iz, ox, oy, oz, *args) -> p``: a @formula, its
                  solid-angle density (0 where ``sample`` never goes)
    args          ``args(values) -> tuple of float``: the sampler's arguments from
                  the model's validated parameter values (a dict NAME → value;
                  colour parameters as given, a float or a per-channel array); the
                  same for every channel
    ============  ================================================================
    """

    sample: Callable
    pdf: Callable
    args: Callable[[dict], tuple]


@dataclass(frozen=True)
class ModelDefinition:
    """The one description of a user model, whatever file it came from.

    A loader (``.py``: :mod:`brdfkit.user.python_file`; ``.brdf``:
    :mod:`brdfkit.user.brdf_file`) builds it; :class:`FormulaBRDF` ``(definition,
    **values)`` builds the model. Frozen: a definition is shared by every model built
    from it (and cached per file content by its loader).

    Fields
    ------
    name : str
        Display name, the model's ``name``: ``"my_model.py:phong"`` (a Python file's
        model: file base name ``:`` declared name), ``"disney.brdf"`` (the file's base
        name). Used in every message (``ParameterError`` names it).
    source : str
        Absolute path of the file the model was read from (shown by ``describe()``
        and ``brdfkit models``; an explorer watches it).
    target : str
        The spec string that rebuilds the model through :data:`brdfkit.spec.KINDS`:
        the absolute path (``/abs/disney.brdf``, ``/abs/my.py``) or
        ``"/abs/my.py:NAME"`` when the file declares several models. It is what
        ``FormulaBRDF.to_dict()["model"]`` gives, so ``ModelSpec.of(m).build()``
        rebuilds *m*.
    params : tuple of :class:`~brdfkit.models.Param`
        The declared parameters, in declaration order (kinds ``scalar``, ``colour``,
        ``bool``, ``choice``; names exactly as the file writes them). Values are
        validated against these by the model's set-up (``Param.validate``).
    kernel : formula
        ``kernel(ix, iy, iz, ox, oy, oz, p) -> float``: a ``@formula``
        (:func:`brdfkit._dual.formula`) of the local-frame components (N = +z,
        X = +x, Y = +y; ω_i = (ix, iy, iz) toward the light, ω_o toward the viewer)
        and of ``p``, ONE channel's packed row (a row of ``pack(values)``; indexed
        with constant indices, never iterated). It MUST be 0 below the horizon
        (``iz <= 0`` or ``oz <= 0``): the loader wraps the file's formula in
        ``select(iz > 0 & oz > 0, f, 0)``. A NaN it computes elsewhere is kept
        (the engines report it). It must have an importable module-level name
        (``kernel.py_func.__module__`` / ``__qualname__``, e.g. a module loaded with
        :func:`brdfkit.models._drivers._load`), so that its compiled pair loop is
        cached on disk; and it must keep the :mod:`brdfkit._dual` contract, so that
        ``drjit_version(kernel)`` traces it for Mitsuba.
    pack : callable or None
        ``pack(values) -> ndarray float64 (C, K)``: the validated values dict (NAME →
        float, per-channel float array, bool, or choice string, as ``Param.validate``
        returns them) → the kernel's packed rows, one row per channel (C = 1 for a
        grey model). None: the packing of every model (:meth:`BRDF._pack`: one column
        per parameter in declared order, row c holding channel c of every colour
        parameter — a scalar colour value repeated — bools 1.0/0.0, a choice its index).
    n_channels : int or None
        None: the model is grey unless a colour parameter is given per channel, and
        then has that many channels (as built-in models: counted from the values).
        An int C: the model always has C channels (e.g. 3 for a ``.brdf`` with a
        ``color`` parameter or a non-grey result), and ``pack`` always gives C rows.
    isotropic : bool
        Whether f depends on the azimuths only through φ_i − φ_o and is even in it
        (the albedo engine then integrates half the azimuths; pumping needs it).
    isotropy_reason : str
        One line saying how isotropy was decided (e.g. "the formula reads neither X
        nor Y", "declared by the file", "the formula reads iy").
    reciprocal : bool or None
        The file's claim f(L, V) = f(V, L): True / False, or None = not claimed
        (the model then measures it per instance, numerically).
    energy_conserving : bool or None
        The file's claim that the albedo is ≤ 1 for every θ_i: True / False / None
        (not claimed). Shown by ``describe()``; ``brdfkit check`` computes it.
    sampler : :class:`SamplerFormulas` or None
        The user's importance sampler and pdf; None: the model is sampled from its
        own values (the tabulated half-vector sampler of :mod:`brdfkit.data.sampler`
        in NumPy, and a cosine + GGX proxy as formulas for Mitsuba).
    citation, summary : str
        Where the formula comes from; one line saying what the model is.
    notes : tuple of str
        One-line remarks the loader makes about the file (e.g. "isFunc section
        ignored: …"), shown by ``describe()`` and ``brdfkit models``.
    interpreted : bool
        True: the models built from it evaluate the kernel's NumPy version
        (:func:`brdfkit._dual.numpy_version`, no compilation; ``kernel`` None on the
        model, so every engine takes its generic ``model.eval`` path) — what the
        explorer draws at once after an edit while Numba compiles the kernel
        (``dataclasses.replace(d, interpreted=True)``). False (the default, what the
        loaders give): compiled, as every model.
    """

    name: str
    source: str
    target: str
    params: tuple
    kernel: Callable
    pack: Callable[[dict], object] | None
    n_channels: int | None = None
    isotropic: bool = True
    isotropy_reason: str = ""
    reciprocal: bool | None = None
    energy_conserving: bool | None = None
    sampler: SamplerFormulas | None = None
    citation: str = ""
    summary: str = ""
    notes: tuple = field(default_factory=tuple)
    #: ``variant(values) -> ModelDefinition`` or None: the definition for these values when
    #: some parameters are compile-time constants of the kernel (a ``.brdf`` file's bools:
    #: each combination has its own kernel); FormulaBRDF builds from it.
    variant: Callable[[dict], ModelDefinition] | None = None
    interpreted: bool = False


# --------------------------------------------------------------------------- NumPy
def interpreted_driver(kernel) -> Callable:
    """``driver(wi, wo, P, out) -> n_bad`` as :func:`~brdfkit.models._drivers.loop_driver`
    gives, running the NumPy version of the formula *kernel* (:func:`numpy_version`) over
    all pairs at once: no compilation, the same values (NumPy's IEEE arithmetic, ``select``
    both sides evaluated as in the compiled loop; libm's exp/log/pow may differ from
    LLVM's in the last bit). All channels in one pass: a column of the packed rows that is
    the same in every row is one ``np.float64`` (so a division by 0 is ±inf or NaN, never
    ``ZeroDivisionError``, and a Python ``if`` on a flag works as compiled), a column that
    differs a (C, 1) array, so what does not depend on the channel (the geometry) is
    computed once. Pairs that are not finite unit vectors (|‖w‖² − 1| > UNIT_TOL) are
    counted and nothing is evaluated (the caller raises). Raises ``TypeError`` when the
    formula has no NumPy version."""
    f = numpy_version(kernel)

    def driver(wi, wo, P, out) -> int:
        norms = (np.einsum("ij,ij->i", wi, wi), np.einsum("ij,ij->i", wo, wo))
        n_bad = int(np.count_nonzero(~((np.abs(norms[0] - 1.0) <= UNIT_TOL)
                                       & (np.abs(norms[1] - 1.0) <= UNIT_TOL))))
        if n_bad:
            return n_bad
        args = tuple(np.ascontiguousarray(w[:, k]) for w in (wi, wo) for k in range(3))
        row = tuple(np.float64(col[0]) if np.all(col == col[0]) else col.reshape(-1, 1)
                    for col in np.asarray(P, dtype=np.float64).T)
        with np.errstate(all="ignore"):  # as the compiled loop: IEEE results, no warning
            f_r = f(*args, row)
        out[:] = np.broadcast_to(np.asarray(f_r, dtype=np.float64),
                                 (P.shape[0], out.shape[0])).T
        return 0

    return driver


# --------------------------------------------------------------------------- measurements
def _random_pairs(n: int, seed: int) -> tuple[np.ndarray, np.ndarray]:
    """*n* pairs of directions uniform on the upper hemisphere (z ≥ 0.02: off the horizon,
    where a formula's cut-off would make a rotation test fail by its rounding)."""
    rng = np.random.default_rng(seed)
    out = []
    for _ in range(2):
        z = rng.uniform(0.02, 1.0, n)
        phi = rng.uniform(0.0, 2.0 * math.pi, n)
        s = np.sqrt(1.0 - z * z)
        out.append(np.stack([s * np.cos(phi), s * np.sin(phi), z], axis=-1))
    return out[0], out[1]


def _relative_change(a: np.ndarray, b: np.ndarray) -> float:
    """max |a − b| / max(|a|, |b|) over the entries where both are finite (floored at 1e-12
    of the largest value: rounding noise of values ~0); NaN when no entry is."""
    a = np.asarray(a, dtype=np.float64).reshape(a.shape[0], -1)
    b = np.asarray(b, dtype=np.float64).reshape(a.shape)
    both = np.all(np.isfinite(a) & np.isfinite(b), axis=-1)
    if not np.any(both):
        return math.nan
    a, b = a[both], b[both]
    scale = max(float(np.max(np.abs(a))), float(np.max(np.abs(b))), 1e-300)
    den = np.maximum(np.maximum(np.abs(a), np.abs(b)), 1e-12 * scale)
    return float(np.max(np.abs(a - b) / den))


def measure_isotropy(model, *, n: int = 256, seed: int = 21) -> bool:
    """Whether *model* is isotropic at its values: f unchanged (≤ :data:`ISOTROPY_TOL`
    relative) when both directions of *n* random pairs turn about the normal by a random
    angle, and when both are mirrored y → −y (the plane of incidence's symmetry)."""
    wi, wo = _random_pairs(n, seed)
    ang = np.random.default_rng(seed + 1).uniform(0.0, 2.0 * math.pi, n)
    c, s = np.cos(ang), np.sin(ang)

    def turn(w):
        return np.stack([c * w[:, 0] - s * w[:, 1], s * w[:, 0] + c * w[:, 1], w[:, 2]], -1)

    mirror = np.array([1.0, -1.0, 1.0])
    f = model.eval(wi, wo)
    worst = max(_relative_change(f, model.eval(turn(wi), turn(wo))),
                _relative_change(f, model.eval(wi * mirror, wo * mirror)))
    return bool(worst <= ISOTROPY_TOL)  # NaN (no finite value): not isotropic


#: The δ grid of the lobe estimate: geometric from 1e-5 rad (a Phong n = 10⁹ lobe is
#: ~4e-5 wide) to just below π/2 (the horizon, where the kernel is cut to 0), 600 points
#: (a ratio of 1.4 % between neighbours, then linear interpolation).
_DELTA = np.geomspace(1e-5, 0.5 * math.pi * 0.999, 600)
#: Ratio of the out-of-plane half-width at θ_o = 60° to the one at the normal above which
#: the lobe is about the mirror direction (1 for R·V lobes, 1/2 for N·H ones).
_MIRROR_RATIO = 0.75


def _half_width(f: np.ndarray) -> float | None:
    """δ where f − min f falls to half of max f − min f (values at :data:`_DELTA`, the mean
    over channels), the peak at the smallest δ; None: no such lobe."""
    f = np.where(np.isfinite(f), f, np.nan)
    if not np.any(np.isfinite(f)):
        return None
    top, floor = float(np.nanmax(f)), float(np.nanmin(f))
    # no lobe: flat to rounding (1e-6 of the peak), or the peak not at the mirror/half
    # direction (f there below 90 % of the peak: e.g. a retro-reflective or grazing peak)
    if not top > 0.0 or top - floor <= 1e-6 * top or not f[0] >= 0.9 * top:
        return None
    g = np.nan_to_num(f - floor, nan=0.0)
    below = np.flatnonzero(g <= 0.5 * (top - floor))
    if below.size == 0 or below[0] == 0:
        return None
    k = int(below[0])
    g0, g1 = g[k - 1], g[k]
    t = (g0 - 0.5 * (top - floor)) / (g0 - g1) if g0 != g1 else 0.0
    return float(_DELTA[k - 1] + t * (_DELTA[k] - _DELTA[k - 1]))


def _mean_f(model, wi, wo) -> np.ndarray:
    f = np.asarray(model.eval(wi, np.broadcast_to(wo, wi.shape)), dtype=np.float64)
    return f.reshape(wi.shape[0], -1).mean(axis=1)


def estimate_lobes(model) -> list[Lobe]:
    """The lobes of *model* from its own values (module docstring)."""
    s, c = np.sin(_DELTA), np.cos(_DELTA)
    zero = np.zeros_like(s)
    normal = np.array([0.0, 0.0, 1.0])
    scans = [np.stack([s, zero, c], -1)] + ([] if model.isotropic else
                                             [np.stack([zero, s, c], -1)])
    widths = [_half_width(_mean_f(model, wi, normal)) for wi in scans]
    if any(w is None for w in widths):
        return [Lobe("diffuse", 0.5 * math.pi)]
    w0 = min(widths)
    t = math.radians(60.0)
    wo = np.array([math.sin(t), 0.0, math.cos(t)])
    mirror = np.array([-wo[0], 0.0, wo[2]])
    wi = c[:, None] * mirror + s[:, None] * np.array([0.0, 1.0, 0.0])
    w60 = _half_width(_mean_f(model, wi, wo))
    if w60 is not None and w60 >= _MIRROR_RATIO * w0:
        return [Lobe("mirror", w0)]
    return [Lobe("half", 0.5 * w0)]  # θ_h = δ/2 at the normal


# --------------------------------------------------------------------------- the model
class FormulaBRDF(TabulatedSampler, DerivedBRDF):
    """The model of a :class:`ModelDefinition` with parameter values.

    ``FormulaBRDF(definition, **values)``: *values* by the definition's parameter
    names (defaults for the missing ones), validated as every model's. Evaluated by
    the definition's kernel through the vectorised pair loop (the kernel is
    branch-free and total: a formula); its lobes and, when not claimed, its
    reciprocity are measured from its own values (module docstring). Sampled by the
    definition's own sampler when it has one, else from its values (the tabulated
    half-vector sampler of :mod:`brdfkit.data.sampler`, χ²-tested). ``to_dict()`` is
    ``{"model": definition.target, "params": ...}``: ``ModelSpec.of(m).build()``
    rebuilds it from the file. An *interpreted* definition (``definition.interpreted``)
    gives a model evaluated by :func:`interpreted_driver` with ``kernel`` None (the same
    values, not compiled; its user sampler, if any, is still compiled on first use).
    """

    def __init__(self, definition: ModelDefinition, /, **values):
        if not isinstance(definition, ModelDefinition):
            raise ParameterError(f"FormulaBRDF: expected a ModelDefinition; got "
                                 f"{type(definition).__name__}")
        declared = [p.name for p in definition.params]
        unknown = sorted(set(values) - set(declared))
        if unknown:
            raise ParameterError(f"{definition.name}: unknown parameter {unknown[0]!r}; valid "
                                 "parameters: " + (", ".join(declared) or "none"))
        if definition.variant is not None:  # compile-time parameters: their own kernel
            interpreted = definition.interpreted
            definition = definition.variant(values)
            if interpreted and not definition.interpreted:
                definition = replace(definition, interpreted=True)
        self._definition = definition
        self._measured: dict = {}
        super().__init__(name=definition.name, params=definition.params, values=values,
                         citation=definition.citation, summary=definition.summary,
                         reciprocal=bool(definition.reciprocal), has_sampler=True,
                         isotropic=definition.isotropic,
                         kernel=None if definition.interpreted else definition.kernel)
        # branch-free and total (a formula): the loop LLVM vectorises, cached on disk; or,
        # interpreted, its NumPy version (kernel None: the engines call eval)
        self._driver = (interpreted_driver(definition.kernel) if definition.interpreted
                        else loop_driver(definition.kernel, loop="vector"))

    @property
    def definition(self) -> ModelDefinition:
        """The description this model was built from."""
        return self._definition

    # ------------------------------------------------------------ set-up hooks
    def _count_channels(self) -> int | None:
        fixed = self._definition.n_channels
        given = super()._count_channels()
        if fixed is None:
            return given
        if given is not None and given != fixed:
            raise ParameterError(f"{self.name}: per-channel parameters must have {fixed} "
                                 f"channels (the model's); got {given}")
        return int(fixed)

    def _pack(self) -> np.ndarray:
        if self._definition.pack is None:
            return super()._pack()  # the packing of every model
        rows = np.ascontiguousarray(np.array(self._definition.pack(self._values),
                                             dtype=np.float64, ndmin=2))
        if rows.shape[0] != (self.n_channels or 1):
            raise ParameterError(f"{self.name}: the definition packed {rows.shape[0]} rows for "
                                 f"{self.n_channels or 1} channels")
        return rows

    # ------------------------------------------------------------ measured claims
    @property
    def reciprocal(self) -> bool:
        """The file's claim, else measured (:data:`RECIPROCITY_TOL`), once."""
        claim = self._definition.reciprocal
        if claim is not None:
            return bool(claim)
        if "reciprocal" not in self._measured:
            from brdfkit.analysis.plausibility import reciprocity
            self._measured["reciprocal"] = bool(reciprocity(self) <= RECIPROCITY_TOL)
        return self._measured["reciprocal"]

    @reciprocal.setter
    def reciprocal(self, value) -> None:
        pass  # DerivedBRDF's set-up assigns the claim; it is the definition's (read above)

    def lobes(self) -> list[Lobe]:
        """Estimated from this model's values (module docstring), once."""
        if "lobes" not in self._measured:
            self._measured["lobes"] = estimate_lobes(self)
        return list(self._measured["lobes"])

    # ------------------------------------------------------------ sampling
    def _sampler_args(self) -> np.ndarray:
        args = self._definition.sampler.args(self.values)
        return np.ascontiguousarray(np.array([float(a) for a in args], dtype=np.float64))

    def sample(self, wo, u):
        """Draw wi given wo from *u* ∈ [0, 1]² (..., 2): the definition's sampler, else the
        tabulated one; returns ``(wi, pdf)``."""
        if self._definition.sampler is None:
            return super().sample(wo, u)
        wo = as_directions(wo, "wo")
        u = as_uniform(u)
        shape = np.broadcast_shapes(wo.shape[:-1], u.shape[:-1])
        w = np.ascontiguousarray(np.broadcast_to(wo, shape + (3,)).reshape(-1, 3))
        uu = np.ascontiguousarray(np.broadcast_to(u, shape + (2,)).reshape(-1, 2))
        a = self._sampler_args()
        draw, _ = sampler_loops(self._definition.sampler, a.size)
        wi, p = np.empty_like(w), np.empty(w.shape[0])
        draw(w, uu, a, wi, p)
        p = np.where(w[:, 2] > 0.0, p, 0.0)
        return wi.reshape(shape + (3,)), p.reshape(shape)

    def pdf(self, wi, wo):
        """Solid-angle density of :meth:`sample`; 0 when wo is below the horizon."""
        if self._definition.sampler is None:
            return super().pdf(wi, wo)
        wi = as_directions(wi, "wi")
        wo = as_directions(wo, "wo")
        shape = np.broadcast_shapes(wi.shape[:-1], wo.shape[:-1])
        a_ = np.ascontiguousarray(np.broadcast_to(wi, shape + (3,)).reshape(-1, 3))
        b_ = np.ascontiguousarray(np.broadcast_to(wo, shape + (3,)).reshape(-1, 3))
        a = self._sampler_args()
        _, density = sampler_loops(self._definition.sampler, a.size)
        p = np.empty(a_.shape[0])
        density(a_, b_, a, p)
        return np.where(b_[:, 2] > 0.0, p, 0.0).reshape(shape)

    def formulas(self) -> Formulas:
        """The kernel, and the user's sampler and pdf, or else a cosine + GGX proxy sampler
        fitted to this model's lobe (:func:`brdfkit.models.proxy_sampler.proxy_formulas`):
        the Mitsuba bridge traces them."""
        d = self._definition
        if d.sampler is not None:
            return Formulas(eval=d.kernel, sample=d.sampler.sample, pdf=d.sampler.pdf,
                            args=tuple(float(a) for a in d.sampler.args(self.values)))
        return proxy_formulas(self)

    # ------------------------------------------------------------ rebuild, describe
    def with_params(self, **changes) -> FormulaBRDF:
        return FormulaBRDF(self._definition, **{**self.values, **changes})

    def to_dict(self) -> dict:
        d = super().to_dict()
        d["model"] = self._definition.target
        return d

    def __repr__(self) -> str:
        args = "".join(f", {k}={(v.tolist() if isinstance(v, np.ndarray) else v)!r}"
                       for k, v in self._values.items())
        return f"brdfkit.model({self._definition.target!r}{args})"

    def describe(self) -> dict:
        """JSON-ready description (``brdfkit models FILE``): the model's, plus its file,
        isotropy and its reason, the file's claims (None: not claimed) and notes."""
        d = self._definition
        return {**super().describe(), "source": d.source, "target": d.target,
                "isotropic": bool(d.isotropic), "isotropy_reason": d.isotropy_reason,
                "claims": {"reciprocal": d.reciprocal,
                           "energy_conserving": d.energy_conserving},
                "own_sampler": d.sampler is not None, "notes": list(d.notes)}
