"""
Models written in Python: a user's ``.py`` file → model definitions
===================================================================

A spec ``PATH.py`` names the one model a user's Python file declares
(:func:`brdfkit.formula.define`), ``PATH.py:NAME`` one of several. The file is
loaded by path (no package edit, nothing registered): executed once as a module
named after a hash of its path and content (``_brdfkit_user_<hash>``), its
:class:`~brdfkit.formula.Declaration` objects at module level (or in a list or
tuple there) collected in file order. Each becomes a
:class:`~brdfkit.user.model.ModelDefinition`:

- **kernel** — generated module source (:func:`brdfkit.models._drivers._load`, so
  Numba caches it on disk, keyed on the file's content):
  ``kernel(ix, iy, iz, ox, oy, oz, p)`` unpacks one channel's packed row by the
  parameters' names (bools as ``p[k] > 0.5``) into the user's formula and makes it
  0 below the horizon, ``select((iz > 0) & (oz > 0), f, 0)``. It is itself a
  formula, so Dr.Jit traces it; the contract of :mod:`brdfkit._dual` is checked when
  the file is loaded (the error names the function), and the kernel compiled —
  unless the definitions are asked for *interpreted* (``compiled=False``: the
  explorer's first build after an edit): then the kernel's NumPy version
  (:func:`brdfkit._dual.numpy_version`) is evaluated once instead and the definition
  is ``interpreted`` (its models are not compiled; a formula calling a primitive with
  no NumPy version is compiled as usual).
- **isotropy** — declared (``define(isotropic=...)``) or measured
  (:func:`~brdfkit.user.model.measure_isotropy` at the defaults and two further
  parameter points drawn within the bounds).
- **sampler** — the user's ``sample``/``pdf`` formulas with their arguments by
  parameter name (colour ones as the channels' mean) or from ``sampler_args``.

Definitions are cached per (path, content hash, compiled) in the process: an edited
file is read again, an unchanged one is not (the file's code runs once per content:
the compiled and the interpreted definitions share its module).

Errors (:class:`~brdfkit.errors.DataFileError` or
:class:`~brdfkit.errors.UnknownModelError`, one line each, naming the file): no such
file, a syntax error (``file:line:col``), an error while executing it (``file:line``),
no model declared, several declared and no name given (listing them), an unknown
name (listing the valid ones), a formula whose arguments are not the parameters' names,
a formula breaking the contract or not compiling (naming the function).

Public objects
--------------
- :func:`definition` — the definition a ``PATH.py[:NAME]`` spec names.
- :func:`definitions` — every definition of a file.
"""

from __future__ import annotations

import hashlib
import importlib.util
import inspect
import math
import os
import sys
import traceback
from dataclasses import replace

import numba
import numpy as np

from brdfkit._cache import bounded_cache
from brdfkit._dual import drjit_version, formula, numpy_version
from brdfkit.errors import BrdfkitError, DataFileError, ParameterError, UnknownModelError
from brdfkit.formula import Declaration
from brdfkit.models._drivers import _load
from brdfkit.user.model import (
    FormulaBRDF,
    ModelDefinition,
    SamplerFormulas,
    measure_isotropy,
)

__all__ = ["definition", "definitions"]

#: (absolute path, content hash) → the file's definitions; a few files in use at once
_DEFINITIONS = bounded_cache("brdfkit.user.python_file._DEFINITIONS", maxsize=64)

_DIRECTIONS = ("ix", "iy", "iz", "ox", "oy", "oz")
_KERNEL = '''\
"""brdfkit: the kernel of {display} (generated from {path}); do not edit."""
from brdfkit._dual import formula, select
from {module} import __brdfkit_formulas__ as _formulas

_eval = _formulas[{key!r}]
{sampler}

# not inlined into the loops that call it: compiled once, on its own (the loader's first
# call), and called by every loop instead of being compiled again inside each (measured:
# no slower on 10 M pairs); every loop divides as IEEE does, as the formula does
@formula(inline="never"{options})
def kernel(ix, iy, iz, ox, oy, oz, p):
    # 0 below the horizon whatever the formula gives there; a NaN above it is kept
    return select((iz > 0.0) & (oz > 0.0), _eval(ix, iy, iz, ox, oy, oz{args}), 0.0)
'''
_SAMPLER = '''
_sample_user = _formulas[{skey!r}]
_pdf_user = _formulas[{pkey!r}]


@formula(inline="always"{options})
def sample(ox, oy, oz, u0, u1{a}):
    return _sample_user(ox, oy, oz, u0, u1{a})


@formula(inline="always"{options})
def pdf(ix, iy, iz, ox, oy, oz{a}):
    return _pdf_user(ix, iy, iz, ox, oy, oz{a})
'''


# --------------------------------------------------------------------------- specs
def _split(spec: str) -> tuple[str, str | None]:
    head, sep, tail = spec.rpartition(":")
    if sep and head.lower().endswith(".py") and tail.isidentifier():
        return head, tail
    return spec, None


def definition(spec, *, compiled: bool = True) -> ModelDefinition:
    """The model definition ``PATH.py`` (the file's one model) or ``PATH.py:NAME`` names
    (*compiled* False: interpreted, module docstring).

    Raises
    ------
    DataFileError
        No such file, a file that does not load or declares no model, a formula at fault.
    UnknownModelError
        Several models and no NAME, or an unknown NAME (the valid names listed).
    """
    path, name = _split(os.fspath(spec).strip())
    defs = definitions(path, compiled=compiled)
    names = [d.name.rpartition(":")[2] for d in defs]
    if name is None:
        if len(defs) > 1:
            raise UnknownModelError(f"{path} declares {len(defs)} models ({', '.join(names)}); "
                                    f"choose one: {path}:NAME")
        return defs[0]
    if name not in names:
        raise UnknownModelError(f"{path} declares no model {name!r}; its models: "
                                + ", ".join(names))
    return defs[names.index(name)]


def definitions(path, *, compiled: bool = True) -> tuple[ModelDefinition, ...]:
    """Every model definition the Python file *path* declares, in file order (cached per
    path, content and *compiled*; False: interpreted, module docstring)."""
    shown = os.fspath(path)
    full = os.path.abspath(os.path.expanduser(shown))
    try:
        with open(full, "rb") as fh:
            data = fh.read()
    except FileNotFoundError:
        raise DataFileError(f"{shown}: no such file (a model written in Python: "
                            "PATH.py or PATH.py:NAME)") from None
    except OSError as err:
        raise DataFileError(f"{shown}: cannot be read ({err.strerror})") from None
    digest = hashlib.sha256(full.encode() + b"\0" + data).hexdigest()[:16]
    key = (full, digest, bool(compiled))
    if key not in _DEFINITIONS:
        _DEFINITIONS[key] = _read(shown, full, digest, data, bool(compiled))
    return _DEFINITIONS[key]


# --------------------------------------------------------------------------- loading
def _execute(shown: str, full: str, digest: str, data: bytes):
    name = f"_brdfkit_user_{digest}"
    if name in sys.modules:
        return sys.modules[name]
    try:
        code = compile(data, full, "exec", dont_inherit=True)
    except SyntaxError as err:
        raise DataFileError(f"{shown}:{err.lineno}:{err.offset}: syntax error: "
                            f"{err.msg}") from None
    spec = importlib.util.spec_from_file_location(name, full)
    module = importlib.util.module_from_spec(spec)
    sys.modules[name] = module  # Numba's cache and the generated kernels import it by name
    try:
        exec(code, module.__dict__)
    except BrdfkitError as err:  # e.g. define()'s own checks
        sys.modules.pop(name, None)
        raise DataFileError(f"{shown}:{_line(err, full)}: {err}") from None
    except Exception as err:  # noqa: BLE001 - any error of the user's code, reported
        sys.modules.pop(name, None)
        raise DataFileError(f"{shown}:{_line(err, full)}: {type(err).__name__}: "
                            f"{str(err).splitlines()[0] if str(err) else ''}") from None
    return module


def _line(err: BaseException, full: str) -> str:
    lines = [f.lineno for f in traceback.extract_tb(err.__traceback__) if f.filename == full]
    return str(lines[-1]) if lines else "?"


def _declarations(module) -> list[Declaration]:
    found: list = []
    for value in vars(module).values():
        items = value if isinstance(value, list | tuple) else (value,)
        for d in items:
            if isinstance(d, Declaration) and not any(d is f for f in found):
                found.append(d)
    return found


def _read(shown: str, full: str, digest: str, data: bytes,
          compiled: bool) -> tuple[ModelDefinition, ...]:
    module = _execute(shown, full, digest, data)
    decls = _declarations(module)
    if not decls:
        raise DataFileError(f"{shown}: declares no model (keep MODEL = "
                            "brdfkit.formula.define(NAME, eval=..., params=[...]) at module "
                            "level)")
    names = [d.name for d in decls]
    twice = sorted({n for n in names if names.count(n) > 1})
    if twice:
        raise DataFileError(f"{shown}: declares the model {twice[0]!r} twice")
    # what the generated kernels read (one dict per module: a second read of the same
    # content, compiled after interpreted, finds the kernels already importing it)
    formulas: dict = vars(module).setdefault("__brdfkit_formulas__", {})
    return tuple(_definition(shown, full, module, d, formulas, compiled) for d in decls)


def _as_formula(f):
    return f if isinstance(f, numba.core.dispatcher.Dispatcher) else formula(f)


def _arguments(label: str, role: str, f, leading: tuple, params: dict) -> list[str]:
    """The parameter names *f* takes after its *leading* arguments (checked)."""
    py = getattr(f, "py_func", f)
    try:
        sig = inspect.signature(py)
    except (TypeError, ValueError):
        raise DataFileError(f"{label}: {role} must be a Python function") from None
    args = [p.name for p in sig.parameters.values()]
    kinds = {p.kind for p in sig.parameters.values()}
    if kinds - {inspect.Parameter.POSITIONAL_OR_KEYWORD} or len(args) < len(leading):
        raise DataFileError(f"{label}: {role} formula {py.__name__} must take "
                            f"({', '.join(leading)}, <parameters by name>); got "
                            f"({', '.join(args)})")
    rest = args[len(leading):]
    unknown = [a for a in rest if a not in params]
    if unknown:
        raise DataFileError(f"{label}: {role} formula {py.__name__} takes {unknown[0]!r}, "
                            "which is not a declared parameter; declared: "
                            + (", ".join(params) or "none"))
    return rest


def _definition(shown: str, full: str, module, decl: Declaration, formulas: dict,
                compiled: bool = True) -> ModelDefinition:
    label = f"{shown}: model {decl.name!r}"
    params = {p.name: p for p in decl.params}
    columns = {p.name: k for k, p in enumerate(decl.params)}
    kinds = {p.name: p.kind for p in decl.params}
    names = _arguments(label, "eval", decl.eval, _DIRECTIONS, params)
    formulas[f"{decl.name}.eval"] = _as_formula(decl.eval)
    args = "".join(f", p[{columns[n]}] > 0.5" if kinds[n] == "bool" else f", p[{columns[n]}]"
                   for n in names)
    sampler_src, sampler_names, n_args = "", [], 0
    if decl.sample is not None:
        formulas[f"{decl.name}.sample"] = _as_formula(decl.sample)
        formulas[f"{decl.name}.pdf"] = _as_formula(decl.pdf)
        if decl.sampler_args is None:
            sampler_names = _arguments(label, "sample", decl.sample,
                                       ("ox", "oy", "oz", "u0", "u1"), params)
            pdf_names = _arguments(label, "pdf", decl.pdf, _DIRECTIONS, params)
            if pdf_names != sampler_names:
                raise DataFileError(f"{label}: sample and pdf must take the same parameters "
                                    f"in the same order; got ({', '.join(sampler_names)}) "
                                    f"and ({', '.join(pdf_names)})")
            n_args = len(sampler_names)
        else:
            defaults = {p.name: p.default for p in decl.params}
            n_args = len(_call_args(label, decl.sampler_args, defaults))
        sampler_src = _SAMPLER.format(skey=f"{decl.name}.sample", pkey=f"{decl.name}.pdf",
                                      options="{options}",
                                      a="".join(f", a{k}" for k in range(n_args)))
    source = _KERNEL.format(display=f"{os.path.basename(full)}:{decl.name}", path=full,
                            module=module.__name__, key=f"{decl.name}.eval", args=args,
                            sampler=sampler_src, options="{options}")
    generated = _load(source.replace("{options}", ""))
    if generated is None:  # no writable cache directory: the same source in memory
        ns: dict = {}
        exec(compile(source.replace("{options}", ", cache=False"), "<brdfkit user kernel>",
                     "exec"), ns)
        generated = type(module)(f"{module.__name__}_kernel")
        vars(generated).update(ns)
    kernel = generated.kernel
    sampler = None
    if decl.sample is not None:
        sampler = SamplerFormulas(sample=generated.sample, pdf=generated.pdf,
                                  args=_args_builder(label, decl, sampler_names, kinds))
    interpreted = not compiled and _interpretable(kernel)
    target = f"{full}:{decl.name}"
    d = ModelDefinition(
        name=f"{os.path.basename(full)}:{decl.name}", source=full, target=target,
        params=tuple(decl.params), kernel=kernel, pack=None, n_channels=None,
        isotropic=bool(decl.isotropic), reciprocal=decl.reciprocal,
        energy_conserving=decl.energy_conserving, sampler=sampler,
        citation=decl.citation, summary=decl.summary,
        isotropy_reason="declared by the file (define(isotropic=...))",
        interpreted=interpreted)
    _check(label, d, decl, compile=not interpreted)
    if decl.isotropic is None:  # measured with the definition's own models (interpreted too)
        iso = all(measure_isotropy(FormulaBRDF(d, **values))
                  for values in _parameter_points(decl.params))
        d = replace(d, isotropic=iso, isotropy_reason=(
            f"measured: {'unchanged' if iso else 'changed'} by turning both directions about "
            "the normal and by mirroring them (256 random pairs; the defaults and 2 random "
            "parameter points)"))
    return d


def _call_args(label: str, fn, values: dict) -> tuple:
    try:
        args = tuple(float(a) for a in fn(values))
    except Exception as err:  # noqa: BLE001 - the user's function, reported
        raise DataFileError(f"{label}: sampler_args(values) failed: {type(err).__name__}: "
                            f"{err}") from None
    return args


def _args_builder(label: str, decl: Declaration, names: list, kinds: dict):
    if decl.sampler_args is not None:
        user = decl.sampler_args
        return lambda values: _call_args(label, user, values)

    def args(values: dict) -> tuple:
        out = []
        for n in names:
            v = values[n]
            if kinds[n] == "bool":
                out.append(1.0 if v else 0.0)
            elif kinds[n] == "choice":
                out.append(float(next(p for p in decl.params if p.name == n).choices.index(v)))
            else:
                out.append(float(np.mean(v)))  # a colour: the channels' mean (module doc)
        return tuple(out)

    return args


def _interpretable(kernel) -> bool:
    """Whether the kernel has a NumPy version (every primitive it calls has one)."""
    try:
        numpy_version(kernel)
    except TypeError:
        return False
    return True


def _check(label: str, d: ModelDefinition, decl: Declaration, *, compile: bool) -> None:
    """The contract of brdfkit._dual (Dr.Jit's version built: names the function at fault)
    and a first compilation of each formula (Numba's error, first line), at the defaults
    packed as the model packs them; not *compile*: the kernel's NumPy version evaluated
    once instead (its error, first line)."""
    kernel, sampler = d.kernel, d.sampler
    if importlib.util.find_spec("drjit") is not None:
        for f in (kernel,) if sampler is None else (kernel, sampler.sample, sampler.pdf):
            try:
                drjit_version(f)
            except TypeError as err:
                raise DataFileError(f"{label}: {err}") from None
    defaults = {p.name: p.validate(p.default, label) for p in decl.params}
    row = np.ascontiguousarray(FormulaBRDF(d, **defaults).packed[0])
    if not compile:
        one, zero = np.ones(1), np.zeros(1)
        try:
            with np.errstate(all="ignore"):
                numpy_version(kernel)(zero, zero, one, zero, zero, one,
                                      tuple(np.float64(x) for x in row))
        except Exception as err:  # noqa: BLE001 - the user's formula, reported
            first = next((ln.strip() for ln in str(err).splitlines() if ln.strip()), "")
            raise DataFileError(f"{label}: the eval formula fails: {type(err).__name__}: "
                                f"{first}") from None
        return
    calls = [("eval", lambda: kernel(0.0, 0.0, 1.0, 0.0, 0.0, 1.0, row))]
    if sampler is not None:
        a = sampler.args(defaults)
        calls += [("sample", lambda: sampler.sample(0.0, 0.0, 1.0, 0.5, 0.5, *a)),
                  ("pdf", lambda: sampler.pdf(0.0, 0.0, 1.0, 0.0, 0.0, 1.0, *a))]
    for role, call in calls:
        try:
            call()
        except numba.core.errors.NumbaError as err:
            first = next((ln.strip() for ln in str(err).splitlines() if ln.strip()), "")
            raise DataFileError(f"{label}: the {role} formula does not compile: "
                                f"{first}") from None


def _parameter_points(params) -> list[dict]:
    """The defaults, then 2 points drawn within the bounds (fixed seed): finite bounds
    uniformly, half-open ones ×e^±1 about the default; bools and choices at random."""
    rng = np.random.default_rng(2021)
    points = [{}]
    for _ in range(2):
        v: dict = {}
        for p in params:
            if p.kind == "bool":
                v[p.name] = bool(rng.integers(2))
            elif p.kind == "choice":
                v[p.name] = p.choices[int(rng.integers(len(p.choices)))]
            elif p.default is None:
                continue
            elif math.isfinite(p.lower) and math.isfinite(p.upper):
                # 1e-3 of the range inside an open bound
                span = p.upper - p.lower
                v[p.name] = float(rng.uniform(p.lower + 1e-3 * span, p.upper - 1e-3 * span))
            else:
                x = float(p.default) * math.exp(rng.uniform(-1.0, 1.0))
                try:
                    v[p.name] = p.validate(x, "")
                except ParameterError:
                    v[p.name] = float(p.default)
        points.append(v)
    return points
