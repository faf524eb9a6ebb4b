"""
A model from a user's file: its one description and the model built from it
============================================================================

Whatever file a user model comes from (a Python file, :mod:`brdfkit.user.python_file`;
a BRDF Explorer ``.brdf`` file, :mod:`brdfkit.user.brdf_file`), the loader describes it
once, as a :class:`ModelDefinition`, and :class:`FormulaBRDF` builds the model from it:
a :class:`~brdfkit.models.DerivedBRDF`, so it is evaluated, analysed, sampled, pumped,
fitted and rendered like every model, without any engine knowing where it came from.

Public objects
--------------
- :class:`ModelDefinition` — the one description of a user model.
- :class:`SamplerFormulas` — a user's own sampler and pdf, as formulas.
- :class:`FormulaBRDF` — the model of a definition with parameter values.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field

__all__ = ["ModelDefinition", "SamplerFormulas", "FormulaBRDF"]


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
    pack : callable
        ``pack(values) -> ndarray float64 (C, K)``: the validated values dict (NAME →
        float, per-channel float array, bool, or choice string, as ``Param.validate``
        returns them) → the kernel's packed rows, one row per channel (C = 1 for a
        grey model). Row c holds channel c of every colour parameter (a scalar colour
        value repeated) and every other parameter as is (bool → 1.0/0.0, a choice →
        its index).
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
    """

    name: str
    source: str
    target: str
    params: tuple
    kernel: Callable
    pack: Callable[[dict], object]
    n_channels: int | None = None
    isotropic: bool = True
    isotropy_reason: str = ""
    reciprocal: bool | None = None
    energy_conserving: bool | None = None
    sampler: SamplerFormulas | None = None
    citation: str = ""
    summary: str = ""
    notes: tuple = field(default_factory=tuple)
