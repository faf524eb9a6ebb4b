"""
Formulas written once, compiled by Numba and traced by Dr.Jit
=============================================================

A *formula* is a plain Python function of numbers, decorated with
:func:`formula`. Its module-level version is a Numba ``njit`` function
(inlined into the compiled model kernels, callable from Python); the same code
object, with its global names bound to Dr.Jit's functions, is the version
Mitsuba traces (:func:`drjit_version`), with arrays (``mi.Float``,
``mi.Color3f``, ``mi.Spectrum``) or Python floats as arguments.

The contract (checked by :func:`drjit_version`, which names the offending
formula and name):

- only arithmetic, comparisons, ``&`` and ``|`` of comparisons, tuple
  indexing/packing and calls of *names*; no attribute access (``math.x``), no
  loops, no ``not``/``and``/``or``/``~`` on values (they mean different things
  to NumPy scalars and Dr.Jit arrays);
- a branch on a value is a :func:`select` (both sides are evaluated, so both
  must be finite or harmless: the kernels already were branch-free so that
  Numba vectorises them). ``if`` is allowed only on Python constants that are
  the same in both worlds (a compile-time flag such as ``ggx``);
- every global name a formula reads is one of: another formula, a primitive
  (below, or registered with :func:`primitive`), or a numeric constant
  (``float``, ``int``, ``bool``). Constants keep their float64 values; in
  Dr.Jit's single-precision variants they round to float32 where they meet an
  array (1e-140 → 0, 2⁶⁰⁰ → inf): a formula's select-guarded corner cases for
  float64 underflow are then inert, never NaN-producing (both branches finite
  or the guard constant-false).

Primitives (Numba → Dr.Jit)
---------------------------
==============  ==============================  ===========================
name            Numba                           Dr.Jit
==============  ==============================  ===========================
select(c,a,b)   ``a if c else b``               ``dr.select``
sqrt, exp, log  ``math.*``                      ``dr.*``
log1p           ``math.log1p``                  Goldberg's log(1+x)·x/((1+x)−1)
expm1           ``math.expm1``                  Kahan's (eˣ−1)·x/log eˣ
sin, cos, tan,  ``math.*``                      ``dr.*``
asin, acos,
atan, atan2
power(x, y)     ``x ** y``                      ``dr.power``
floor           ``np.floor`` (a float)          ``dr.floor``
minimum,        ``min``/``max``/``abs``         ``dr.minimum``/``maximum``/
maximum,                                        ``abs``
absolute
exp_nonpos      :func:`brdfkit._kern.exp_nonpos` ``dr.exp``
erfc            ``math.erfc``                   Numerical Recipes' erfcc
                                                (Chebyshev fit, relative
                                                error < 1.2e-7: float32's)
muladd(a,b,c)   ``a * b + c`` (unfused: the     ``dr.fma`` (fused: one
                kernels' value)                 instruction, a rounding less)
==============  ==============================  ===========================

plus those other modules register (:func:`primitive`), e.g. the Beckmann
h(a) of :mod:`brdfkit.models.microfacet_distributions` (a table without libm
calls for Numba, ``dr.erf`` for Dr.Jit).

References
----------
- W. Jakob, S. Speierer, N. Roussel, D. Vicini, *Dr.Jit: A Just-In-Time
  Compiler for Differentiable Rendering*, ACM TOG 41(4), 2022 (tracing).
- D. Goldberg, *What every computer scientist should know about floating-point
  arithmetic*, ACM Computing Surveys 23(1), 1991, Theorem 4 (log1p).
- W. Kahan, as given by N. J. Higham, *Accuracy and Stability of Numerical
  Algorithms*, 2nd ed., SIAM 2002, §1.14.1 (expm1 as (u − 1)·x/log u, u = eˣ).
- W. H. Press et al., *Numerical Recipes in C*, 2nd ed., 1992, §6.2, ``erfcc``
  (erfc with fractional error < 1.2e-7 everywhere).
"""

from __future__ import annotations

import dis
import math
import types
from collections.abc import Callable
from dataclasses import dataclass

import numba
import numpy as np

from brdfkit._cache import bounded_cache
from brdfkit._kern import exp_nonpos

__all__ = ["Formulas", "formula", "compose", "primitive", "drjit_version", "select", "sqrt",
           "exp", "log",
           "log1p", "sin", "cos", "tan", "asin", "acos", "atan", "atan2", "power", "floor",
           "minimum", "maximum", "absolute", "exp_nonpos", "erfc", "muladd", "expm1",
           "numpy_version"]

_jit = numba.njit(cache=True, inline="always")

#: py_func of every formula → its Numba dispatcher
_FORMULAS: dict[Callable, object] = {}
#: Numba-side primitive object → factory dr ↦ its Dr.Jit counterpart
_PRIMITIVES: dict[object, Callable] = {}
#: memo: py_func → Dr.Jit version (every formula and primitive user: tens; the bound is far
#: above them, so a trace never rebuilds a callee)
_DRJIT = bounded_cache("brdfkit._dual._DRJIT", maxsize=256)


@dataclass(frozen=True)
class Formulas:
    """A model's f_r, sampler and pdf as formulas (what ``BRDF.formulas()`` returns).

    ============  ================================================================
    field         meaning
    ============  ================================================================
    eval          ``eval(ix, iy, iz, ox, oy, oz, p) -> f_r`` for one channel's
                  packed row *p* (``model.packed[c]``; indexed, never iterated),
                  wi = (ix, iy, iz) toward the light, wo toward the viewer, local
                  frame, 0 below the horizon; equal to ``model.eval``
    sample        ``sample(ox, oy, oz, u0, u1, *args) -> (ix, iy, iz)``: the
                  model's sampler (the same directions as ``model.sample``)
    pdf           ``pdf(ix, iy, iz, ox, oy, oz, *args) -> p``: its solid-angle
                  density (``model.pdf``)
    args          the sampler's parameters (Python floats, the same for every
                  channel)
    tables        None, or the packed column from which on the row holds tables
                  that *eval* reads with :func:`brdfkit.tables.lookup` (not
                  parameters: the traced route holds those columns as one Dr.Jit
                  array and gathers from it, ``docs/architecture.md``, "Tables
                  in the trace")
    vectorise     True: an engine that composes *eval* into a compiled loop (a
                  compensation's kernel) composes it into the vectorising loop;
                  False: it composes the model's kernel instead (an unrolled
                  network: LLVM's optimiser takes minutes on its ~600 straight-line
                  operations inside that loop)
    ============  ================================================================
    """

    eval: Callable
    sample: Callable
    pdf: Callable
    args: tuple = ()
    tables: int | None = None
    vectorise: bool = True


def formula(f=None, **options):
    """Decorator: *f* as a formula (module docstring); returns its Numba version.

    ``options`` go to ``numba.njit`` (default ``cache=True, inline="always",
    error_model="numpy"``).
    """
    def deco(fn):
        # error_model "numpy": a select evaluates both sides, a discarded one may divide by 0
        opts = {"cache": True, "inline": "always", "error_model": "numpy", **options}
        disp = numba.njit(**opts)(fn)
        _FORMULAS[fn] = disp
        return disp

    return deco if f is None else deco(f)


#: memo: (template, bindings) → the composed formula (one per composition a derived model
#: uses: a pumped or compensated model's structure; tens)
_COMPOSED = bounded_cache("brdfkit._dual._COMPOSED", maxsize=256)


def compose(template: Callable, **bindings) -> Callable:
    """A formula from the plain function *template* with some of its global names bound.

    The formula counterpart of :func:`brdfkit.models._drivers.composed`: *template* is
    written over module globals (another formula, an int offset, a flag) that each
    composition binds; the result is a formula (:func:`formula`, not cached on disk: its
    globals are per composition) whose Dr.Jit version reads the bound values (a bound
    formula is rebound recursively, a bound int or bool is a constant). Memoised per
    (template, bindings).
    """
    key = (template, tuple(sorted(bindings.items())))
    if key not in _COMPOSED:
        ns = dict(template.__globals__)
        ns.update(bindings)
        fn = types.FunctionType(template.__code__, ns, template.__name__,
                                template.__defaults__)
        fn.__qualname__ = f"{template.__qualname__}[{', '.join(sorted(bindings))}]"
        _COMPOSED[key] = formula(fn, cache=False)
    return _COMPOSED[key]


def primitive(obj, drjit: Callable):
    """Register the Numba-side *obj* (a function a formula calls by name) with the factory
    ``drjit(dr) -> function`` of its Dr.Jit counterpart; returns *obj*."""
    _PRIMITIVES[obj] = drjit
    return obj


@_jit
def select(c, a, b):
    """a where c holds, else b (both evaluated)."""
    return a if c else b


@_jit
def minimum(a, b):
    return min(a, b)


@_jit
def maximum(a, b):
    return max(a, b)


@_jit
def absolute(a):
    return abs(a)


@_jit
def power(x, y):
    """x**y (NaN for x < 0 and a non-integer y)."""
    return x ** y


@_jit
def floor(x):
    """The largest integer ≤ x, as a float (``math.floor`` gives an int)."""
    return np.floor(x)


# not inlined in Numba's IR (LLVM inlines it): a formula may call it hundreds of times, and
# Numba's IR inlining of each call site is what costs compile time
@numba.njit(cache=True)
def muladd(a, b, c):
    """a·b + c: unfused in Numba (the same value as the kernels' ``a * b + c``), one fused
    multiply-add in Dr.Jit (a rounding less: float32 traces only gain)."""
    return a * b + c


sqrt = math.sqrt
exp = math.exp
log = math.log
log1p = math.log1p
expm1 = math.expm1
sin = math.sin
cos = math.cos
tan = math.tan
asin = math.asin
acos = math.acos
atan = math.atan
atan2 = math.atan2
erfc = math.erfc

#: Numerical Recipes' erfcc (Press et al. 1992, §6.2): erfc(z) = t exp(−z² + P(t)),
#: t = 1/(1 + z/2), z ≥ 0, P of degree 9 with these coefficients (constant term first)
_ERFCC = (-1.26551223, 1.00002368, 0.37409196, 0.09678418, -0.18628806, 0.27886807,
          -1.13520398, 1.48851587, -0.82215223, 0.17087277)


def _log1p_drjit(dr):
    def log1p_(x):
        u = 1.0 + x
        # Goldberg (1991) Thm. 4: log(u)·x/(u − 1) is accurate where u rounds; u = 1: x
        return dr.select(u == 1.0, x, dr.log(u) * (x / dr.select(u == 1.0, 1.0, u - 1.0)))
    return log1p_


def _expm1_drjit(dr):
    def expm1_(x):
        u = dr.exp(x)
        # Kahan: (u − 1)·x/log u is accurate where u rounds; u = 1: x; u = inf: inf
        # (x/log u = 1 there: the select keeps inf·1 rather than inf/inf)
        d = dr.log(u)
        ok = (u != 1.0) & (d < math.inf)
        return dr.select(ok, (u - 1.0) * (x / dr.select(ok, d, 1.0)),
                         dr.select(u == 1.0, x, u - 1.0))
    return expm1_


def _erfc_drjit(dr):
    def erfc_(x):
        z = dr.abs(x)
        t = 1.0 / (1.0 + 0.5 * z)
        poly = _ERFCC[-1]
        for c in _ERFCC[-2::-1]:  # Horner, in Python: unrolled into the trace
            poly = poly * t + c
        r = t * dr.exp(-z * z + poly)
        return dr.select(x >= 0.0, r, 2.0 - r)  # erfc(−x) = 2 − erfc(x)
    return erfc_


for _obj, _factory in (
        (select, lambda dr: dr.select), (minimum, lambda dr: dr.minimum),
        (maximum, lambda dr: dr.maximum), (absolute, lambda dr: dr.abs),
        (sqrt, lambda dr: dr.sqrt), (exp, lambda dr: dr.exp), (log, lambda dr: dr.log),
        (log1p, _log1p_drjit), (expm1, _expm1_drjit),
        (sin, lambda dr: dr.sin), (cos, lambda dr: dr.cos),
        (tan, lambda dr: dr.tan), (asin, lambda dr: dr.asin), (acos, lambda dr: dr.acos),
        (atan, lambda dr: dr.atan), (atan2, lambda dr: dr.atan2),
        (power, lambda dr: dr.power), (floor, lambda dr: dr.floor),
        (exp_nonpos, lambda dr: dr.exp), (erfc, _erfc_drjit), (muladd, lambda dr: dr.fma)):
    primitive(_obj, _factory)

_CONSTANT_TYPES = (float, int, bool)
# opcodes a formula may not contain (attribute access, loops, ~): see the contract
_FORBIDDEN = {"LOAD_ATTR", "LOAD_METHOD", "FOR_ITER", "UNARY_INVERT", "UNARY_NOT",
              "GET_ITER", "MAKE_FUNCTION", "IMPORT_NAME"}


def _py(f):
    return f.py_func if isinstance(f, numba.core.dispatcher.Dispatcher) else f


def drjit_version(f) -> Callable:
    """The Dr.Jit version of the formula *f* (its Numba dispatcher or Python function).

    The same code object, with a namespace in which every global name the
    formula reads is its Dr.Jit counterpart (formulas recursively); built once
    and cached. Raises ``TypeError`` naming the formula and the name when the
    contract (module docstring) is broken.
    """
    import drjit as dr

    return _version(f, _DRJIT, lambda value: _PRIMITIVES[value](dr), drjit_version)


#: NumPy counterparts of the primitives (arrays in, arrays out): ``numpy_version``
_NUMPY_PRIMITIVES = {select: np.where, minimum: np.minimum, maximum: np.maximum,
                     absolute: np.abs, power: np.power, floor: np.floor,
                     muladd: lambda a, b, c: a * b + c}
_NUMPY_BY_NAME = {"sqrt": np.sqrt, "exp": np.exp, "log": np.log, "log1p": np.log1p,
                  "expm1": np.expm1,
                  "sin": np.sin, "cos": np.cos, "tan": np.tan, "asin": np.arcsin,
                  "acos": np.arccos, "atan": np.arctan, "atan2": np.arctan2,
                  "exp_nonpos": np.exp}  # (erfc: no NumPy version; SciPy's is not imported)
#: memo: py_func → NumPy version
_NUMPY = bounded_cache("brdfkit._dual._NUMPY", maxsize=256)


def numpy_version(f) -> Callable:
    """The NumPy version of the formula *f*: the same code with arrays (``select`` is
    ``np.where``, ``sqrt`` ``np.sqrt`` …), so that a formula is evaluated without being
    compiled (a just-edited ``.brdf`` file in the explorer, while Numba compiles it).
    Raises ``TypeError`` as :func:`drjit_version`, also for a primitive with no NumPy
    counterpart."""
    def numpy_of(value):
        if value in _NUMPY_PRIMITIVES:
            return _NUMPY_PRIMITIVES[value]
        name = next((k for k, v in _NUMPY_BY_NAME.items() if globals().get(k) is value), None)
        if name is None:
            raise TypeError(f"the primitive {value!r} has no NumPy version")
        return _NUMPY_BY_NAME[name]

    return _version(f, _NUMPY, numpy_of, numpy_version)


def _version(f, memo, primitive_of, recurse) -> Callable:
    """*f*'s code with its global names rebound: formulas by ``recurse``, primitives by
    ``primitive_of``, numeric constants kept (the contract: module docstring)."""
    py = _py(f)
    if py in memo:
        return memo[py]
    if py not in _FORMULAS:
        raise TypeError(f"{py.__qualname__} is not a formula (decorate it with @formula)")
    code = py.__code__
    bad = sorted({i.opname for i in dis.get_instructions(code)} & _FORBIDDEN)
    if bad:
        raise TypeError(f"formula {py.__qualname__} uses {', '.join(bad)} (not traceable; "
                        "see brdfkit._dual)")
    ns: dict = {"__name__": py.__globals__.get("__name__"), "__builtins__": {}}
    new = types.FunctionType(code, ns, py.__name__, py.__defaults__)
    memo[py] = new  # before the names: formulas may call each other
    for name in code.co_names:
        value = py.__globals__.get(name)
        inner = _py(value) if value is not None else None
        if inner in _FORMULAS:
            ns[name] = recurse(inner)
        elif _hashable(value) and value in _PRIMITIVES:
            ns[name] = primitive_of(value)
        elif isinstance(value, _CONSTANT_TYPES):
            ns[name] = value
        else:
            del memo[py]
            what = type(value).__name__ if name in py.__globals__ else "a builtin"
            raise TypeError(f"formula {py.__qualname__} reads the global {name!r} "
                            f"({what}), which is neither a formula, a primitive nor a "
                            "numeric constant (see brdfkit._dual)")
    return new


def _hashable(value) -> bool:
    try:
        hash(value)
    except TypeError:
        return False
    return True
