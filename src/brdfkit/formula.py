"""
The formula language: what a model written in Python imports
============================================================

A user writes a model in a Python file of their own (no package edit, no
registration): its formula as a function decorated with :func:`formula`, its
parameters as :class:`Param`, and one :func:`define` that names them. brdfkit
loads the file when a spec names it (``brdfkit.model("my_model.py")``,
``brdfkit check my_model.py``; ``my_model.py:NAME`` when it defines several)::

    from brdfkit.formula import Param, define, formula, pos_pow

    PI = 3.141592653589793

    @formula
    def phong(ix, iy, iz, ox, oy, oz, rho_d, rho_s, n):
        c = 2.0 * iz * oz - (ix * ox + iy * oy + iz * oz)    # R·V
        return rho_d / PI + rho_s * (n + 2.0) / (2.0 * PI) * pos_pow(c, n)

    MODEL = define("phong", eval=phong, params=[
        Param("rho_d", 0.2, 0.0, 1.0, doc="diffuse albedo", kind="colour"),
        Param("rho_s", 0.5, 0.0, 1.0, doc="specular albedo", kind="colour"),
        Param("n", 20.0, 0.0, 1e4, doc="exponent")], reciprocal=True)

The eval formula takes the six components of ω_i = (ix, iy, iz) (toward the
light) and ω_o = (ox, oy, oz) (toward the viewer) in the local frame (normal
+z), then the parameters **by name** (one channel's value of a colour
parameter; a bool parameter as a bool; a choice as its index), and returns
f_r in 1/sr without the cosine. Below the horizon brdfkit makes it 0 whatever
the formula returns there; a NaN it makes above is reported by the engines.

A formula is compiled by Numba (brdfkit's engines) and traced by Dr.Jit
(Mitsuba renders); so it keeps the contract of :mod:`brdfkit._dual`: only
arithmetic, comparisons, ``&``/``|`` of comparisons, tuples and calls of the
primitives below or of other ``@formula`` functions; a branch on a value is a
:func:`select` (both sides are evaluated: keep both finite); no loops, no
``math.x`` attribute access, no ``if`` on a value. Constants of the file
(``PI`` above) may be read. The loader names the function that breaks it.

Optionally a sampler: ``sample(ox, oy, oz, u0, u1, <params>) -> (ix, iy, iz)``
and its solid-angle ``pdf(ix, iy, iz, ox, oy, oz, <params>)`` as formulas (the
parameters by name again, colour ones as their mean over the channels), or with
``sampler_args(values) -> tuple`` their arguments after the leading ones.
Without one, brdfkit samples the model from its own values.

Public objects
--------------
- :func:`formula` — the decorator; :func:`define` — declare a model.
- :class:`Param` — a parameter (default, bounds, unit, doc, kind: ``scalar``,
  ``colour``, ``bool``, ``choice``).
- :class:`Declaration` — what :func:`define` returns (the loader collects it).
- the primitives of :mod:`brdfkit._dual` (``select``, ``sqrt``, ``exp``,
  ``log``, ``log1p``, ``sin``, ``cos``, ``minimum``, ``maximum``,
  ``absolute``, ``exp_nonpos`` …: every name of its ``__all__``), and
  :func:`pos_pow` — max(0, x)ⁿ with 0⁰ = 1, the power of the built-in Phong
  lobes (binary powers for integral n < 1024, ``pow`` otherwise; ``dr.power``
  in Dr.Jit).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

from brdfkit import _dual
from brdfkit.errors import ParameterError
from brdfkit.models._lobes import lobe_pow as pos_pow
from brdfkit.models._param import Param

#: The primitives and the decorator, as :mod:`brdfkit._dual` exports them (new ones
#: appear here without an edit)
_DUAL = tuple(n for n in _dual.__all__ if n not in ("Formulas", "primitive", "drjit_version"))
globals().update({n: getattr(_dual, n) for n in _DUAL})

__all__ = [*_DUAL, "pos_pow", "Param", "Declaration", "define"]  # noqa: PLE0604


def _pos_pow_drjit(dr):
    def pos_pow_(x, n):
        up = x > 0.0
        return dr.select(up, dr.power(dr.select(up, x, 1.0), n),
                         dr.select(n == 0.0, 1.0, 0.0))  # 0⁰ = 1
    return pos_pow_


# pos_pow(x, n) = max(0, x)ⁿ with 0⁰ = 1: the built-in Phong lobes' power (binary powers
# for integral n < 1024, ~4x faster than pow), a primitive (Dr.Jit: dr.power)
_dual.primitive(pos_pow, _pos_pow_drjit)

#: The parameter kinds a user model may declare (per-lobe ones are the built-ins')
USER_KINDS = ("scalar", "colour", "bool", "choice")


@dataclass(frozen=True)
class Declaration:
    """A model a user's file declares (:func:`define`); its loader
    (:mod:`brdfkit.user.python_file`) turns it into a model definition."""

    name: str
    eval: Callable
    params: tuple
    reciprocal: bool | None = None
    energy_conserving: bool | None = None
    isotropic: bool | None = None
    sample: Callable | None = None
    pdf: Callable | None = None
    sampler_args: Callable | None = None
    citation: str = ""
    summary: str = ""


def _claim(name: str, what: str, value) -> bool | None:
    if value is not None and not isinstance(value, bool):
        raise ParameterError(f"define({name!r}): {what} must be True, False or None (not "
                             f"claimed); got {value!r}")
    return value


def define(name: str, *, eval: Callable, params=(), reciprocal: bool | None = None,
           energy_conserving: bool | None = None, isotropic: bool | None = None,
           sample: Callable | None = None, pdf: Callable | None = None,
           sampler_args: Callable | None = None, citation: str = "",
           summary: str = "") -> Declaration:
    """Declare a model of a user's file; keep the result at module level
    (``MODEL = define(...)``, or several in a list) for the loader to find.

    Parameters
    ----------
    name : str
        The model's name in its file (a Python identifier; ``my.py:NAME`` chooses it).
    eval : formula
        ``eval(ix, iy, iz, ox, oy, oz, <params by name>) -> f_r`` (module docstring).
    params : sequence of Param
        Its parameters (kinds ``scalar``, ``colour``, ``bool``, ``choice``).
    reciprocal, energy_conserving : bool or None
        The model's claims; None: not claimed (reciprocity is then measured per
        instance, energy by ``brdfkit check``).
    isotropic : bool or None
        Whether f depends on the azimuths only through their difference (and is even
        in it); None: measured when the file is loaded.
    sample, pdf : formula, optional
        A sampler and its pdf (module docstring); both or neither.
    sampler_args : callable, optional
        ``sampler_args(values) -> tuple of float``: the sampler's arguments after the
        leading ones, from the parameter values; default: the parameters named by the
        sampler's own arguments.
    citation, summary : str
        Where the formula comes from; one line saying what it is.
    """
    if not isinstance(name, str) or not name.isidentifier():
        raise ParameterError(f"define: name must be a Python identifier (my.py:NAME chooses "
                             f"it); got {name!r}")
    for what, f in (("eval", eval), ("sample", sample), ("pdf", pdf)):
        if f is not None and not callable(f):
            raise ParameterError(f"define({name!r}): {what} must be a formula (a function "
                                 f"decorated with @formula); got {type(f).__name__}")
    if (sample is None) != (pdf is None):
        raise ParameterError(f"define({name!r}): give both sample and pdf, or neither")
    if sampler_args is not None and (sample is None or not callable(sampler_args)):
        raise ParameterError(f"define({name!r}): sampler_args must be a callable "
                             "values -> tuple, given with sample and pdf")
    params = tuple(params)
    seen: set = set()
    for p in params:
        if not isinstance(p, Param):
            raise ParameterError(f"define({name!r}): params must be Param objects; got "
                                 f"{type(p).__name__} {p!r}")
        if p.kind not in USER_KINDS:
            raise ParameterError(f"define({name!r}): parameter {p.name!r} has kind "
                                 f"{p.kind!r}; a user model's kinds: {', '.join(USER_KINDS)}")
        if p.name in seen or not p.name.isidentifier():
            raise ParameterError(f"define({name!r}): parameter names must be distinct "
                                 f"Python identifiers; got {p.name!r}")
        seen.add(p.name)
    return Declaration(
        name=name, eval=eval, params=params,
        reciprocal=_claim(name, "reciprocal", reciprocal),
        energy_conserving=_claim(name, "energy_conserving", energy_conserving),
        isotropic=_claim(name, "isotropic", isotropic), sample=sample, pdf=pdf,
        sampler_args=sampler_args, citation=str(citation), summary=str(summary))
