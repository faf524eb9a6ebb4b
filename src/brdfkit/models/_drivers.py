"""
The compiled evaluation loops of every model: one loop generator
================================================================

A model's kernel is a scalar function of one pair of directions
(:mod:`brdfkit.models._base`); these loops run it over all pairs and channels.
Every loop is written once, here, and generated per kernel into a tiny module
that Numba caches on disk (below).

- :func:`eval_pairs_checked` — the loop over all pairs, testing in the same pass
  that the directions are finite unit vectors (:data:`UNIT_TOL`); the kernel is
  an argument. Its statements are the ``"checked"`` and ``"plain"`` loops.
- :func:`eval_pairs` — the same without the test, for code that has packed,
  checked arrays (:func:`generic_loop` ``("plain")``).
- :data:`LOOPS` — the loops the generator writes, each from one hand-written template:
  ``"checked"`` and ``"plain"`` (one pair per iteration, parallel over pairs),
  ``"vector"`` (chunks of pairs whose inner loop LLVM vectorises, for branch-free total
  kernels), ``"rgb"`` (the same, three channels at once from all packed rows),
  ``"blocked"`` (locate a block of pairs, then read them: table lookups), ``"albedo"``
  (the albedo engine's loop over angles and nodes); :func:`add_loop` adds a higher
  layer's (the exact sphere's, :mod:`brdfkit.render.sphere`).
- :func:`loop_driver` — the loop *loop* for one kernel with an importable name,
  generated as a module and cached on disk (else compiled in memory);
  :func:`blocked_driver` — the blocked loop with its hooks, likewise.
- :func:`composed` — a kernel built from a template function and bound names
  (a pumped model's: the base kernel, a table offset, flags) with its loop, both
  generated as one cached module.
- :func:`generic_loop` — a loop with the kernel as its first argument (compiled
  per kernel in each process: for code that loops over many kernels once).
- :func:`cached_driver` — the disk-cached checked loop or None; :func:`checked_driver`.
- :func:`numba_threads` — re-exported from :mod:`brdfkit._threads` (Numba's threads).
- :func:`cache_dir` — where the generated loops are kept.

Loops kept on disk
------------------
:func:`eval_pairs_checked` takes the kernel as a first-class function argument.
Numba cannot cache such a specialisation on disk (it is keyed on the kernel's
dispatcher, a new object in every process), and a closure (a vectorised or
pumped driver built at run time) has no file to cache into: every process paid
~1-3 s per model to compile its loop again.

Here each loop is written into a tiny generated module per kernel, with the kernel a
module global (so that LLVM inlines it), and Numba's ordinary ``cache=True`` applies:
the second process loads the compiled loop in milliseconds. A composite kernel is
generated in the same module from its template (``types.FunctionType`` of the
template's code object with the bound names as globals: a closure's values).

Staleness. Numba invalidates a cache entry when *its own* source file changes, not
when a function it calls changes: the generated files' directory is named after
:func:`brdfkit._cache.source_stamp` (every brdfkit source file's path, size and time;
Numba's and Python's versions), so an edit gives new files in the next process; old
directories are pruned after a week.

Where. ``$BRDFKIT_CACHE_DIR`` if set, else ``$XDG_CACHE_HOME/brdfkit`` (default
``~/.cache/brdfkit``), subdirectory ``drivers``. An unwritable directory, or a kernel
with no importable name (a closure, a lambda): the loop is compiled in memory.
"""

from __future__ import annotations

import ast
import hashlib
import importlib
import importlib.util
import inspect
import math
import os
import shutil
import sys
import textwrap
import time
import types
from pathlib import Path

import numba
import numpy as np
from numba.np.unsafe.ndarray import to_fixed_tuple

from brdfkit._cache import bounded_cache, disk_cache_dir, memo, source_stamp
from brdfkit._kern import load_input, store_output
from brdfkit._threads import numba_threads  # noqa: F401  (re-exported)

__all__ = ["SERIAL_BELOW", "UNIT_TOL", "VECTOR_OPTIONS", "LOOPS", "add_loop", "eval_pairs",
           "eval_pairs_checked", "loop_driver", "blocked_driver", "composed", "generic_loop",
           "checked_driver", "cached_driver", "numba_threads", "cache_dir"]


# --------------------------------------------------------------------------- the loops
# Directions must be unit vectors: |‖w‖² − 1| ≤ UNIT_TOL, tested in the compiled pass (the
# same read of the data as the NaN/inf test, which it subsumes: comparisons with NaN are
# false and ‖w‖² of an infinite component is inf). 1e-3 on the squared norm (5e-4 on the
# norm): directions normalised in float32 (within ~4e-7) and vectors typed with three or
# four digits, such as (0.2, 0, −0.98) with ‖w‖² = 1.0004, pass; a vector scaled by mistake
# (‖w‖ = 2), an unnormalised sum or difference of directions, or a half-converted angle
# does not. The check guards against mistakes, not rounding: the kernels take the
# components as given.
#: Calls with fewer pairs run their parallel region on the calling thread alone: a few
#: thousand pairs cost ~0.1 ms serially, and on a loaded 2-core machine the OpenMP barrier
#: of a parallel region waits for a descheduled worker for milliseconds (the explorer's
#: 181-point slices took 16 ms instead of 0.1 ms under a load of 5).
SERIAL_BELOW = 4096
UNIT_TOL = 1e-3


@numba.njit(inline="always")
def _unit_pair(ix, iy, iz, ox, oy, oz) -> bool:
    """Both directions finite with |‖w‖² − 1| ≤ UNIT_TOL (False for NaN or inf)."""
    return ((abs(ix * ix + iy * iy + iz * iz - 1.0) <= UNIT_TOL)
            & (abs(ox * ox + oy * oy + oz * oz - 1.0) <= UNIT_TOL))


# Compile options of the vectorising loop ("vector"): a kernel inlined into it is compiled
# with the loop's options, so these are the kernel's.
# error_model="numpy": IEEE division (no zero-divisor test, which would be a branch);
# no fastmath flags: not even "contract" (fused multiply-adds), which LLVM applies
# differently in the vector body and the scalar remainder, so one pair's value depended on
# its position in the array by an ulp (tests/test_registry_properties.py, broadcasting).
VECTOR_OPTIONS = {"error_model": "numpy", "fastmath": set()}
_CHUNK = 4096  # pairs per task of the vectorised loop (96 KiB of directions)


#: The checked loop's test of the directions, on (True) in :func:`eval_pairs_checked` and the
#: ``"checked"`` loop, off (False: a compile-time constant, the test compiled away) in the
#: ``"plain"`` loop and :func:`eval_pairs`.
CHECK = True


@numba.njit(parallel=True)
def eval_pairs_checked(kernel, wi, wo, P, out):  # pragma: no cover - compiled
    """:func:`eval_pairs` that also tests the directions in the same pass.

    Pairs with a non-finite component or a direction that is not a unit
    vector (|‖w‖² − 1| > :data:`UNIT_TOL`) are not passed to the kernel (their
    ``out`` rows are NaN). Returns the number of such pairs, so that the
    caller can raise; reading the directions once instead of twice is what
    makes this faster than ``np.isfinite`` followed by :func:`eval_pairs`.
    """
    n = wi.shape[0]
    n_channels = P.shape[0]
    n_bad = 0
    if n_channels == 1:
        p = P[0]
        for j in numba.prange(n):
            ix, iy, iz = wi[j, 0], wi[j, 1], wi[j, 2]
            ox, oy, oz = wo[j, 0], wo[j, 1], wo[j, 2]
            if not CHECK or _unit_pair(ix, iy, iz, ox, oy, oz):
                out[j, 0] = kernel(ix, iy, iz, ox, oy, oz, p)
            else:
                out[j, 0] = math.nan
                n_bad += 1
    else:
        for j in numba.prange(n):
            ix, iy, iz = wi[j, 0], wi[j, 1], wi[j, 2]
            ox, oy, oz = wo[j, 0], wo[j, 1], wo[j, 2]
            if not CHECK or _unit_pair(ix, iy, iz, ox, oy, oz):
                for c in range(n_channels):
                    out[j, c] = kernel(ix, iy, iz, ox, oy, oz, P[c])
            else:
                for c in range(n_channels):
                    out[j, c] = math.nan
                n_bad += 1
    return n_bad


# The "vector" loop, for kernels written branch-free and *total*: for any input values
# (NaN, inf, non-unit) they return without side effects and read memory only in bounds
# (see brdfkit._kern). The loop evaluates every pair and selects NaN for the rejected ones
# instead of branching around the kernel, so that LLVM vectorises it (4 float64 lanes with
# AVX2); the directions are read as flat arrays (index 3j + k), which LLVM loads as
# interleaved groups. Measured on 10 M pairs (microfacet, Beckmann α = 0.1): 2.3x the
# checked loop on one thread. Templates only (plain functions, never compiled here):
# `kernel` and `chunk` are the globals of each generated module. "rgb": the same with RGB =
# True, kernel(…, t) -> (f0, f1, f2) over the rows as one tuple: shared work done once.
def _vector_chunk(a, b, o, p):  # pragma: no cover - compiled in the generated modules
    # Pairs of a and b (flat, 3 per pair) into o; returns the good pairs' count. LLVM vectorises
    # it given (each measured): its own function (in a prange body Numba keeps the loop's
    # variables live), indices from 0 (no wraparound select: the loads an interleaved group),
    # unit-stride stores, int64(ok) counts, no p loads (RGB), load_input/store_output (_kern).
    good = 0
    for j in range(o.shape[0] // (3 if RGB else 1)):  # noqa: F821
        ix, iy, iz = load_input(a, 3 * j), load_input(a, 3 * j + 1), load_input(a, 3 * j + 2)
        ox, oy, oz = load_input(b, 3 * j), load_input(b, 3 * j + 1), load_input(b, 3 * j + 2)
        ok = _unit_pair(ix, iy, iz, ox, oy, oz)
        if RGB:  # noqa: F821 - a constant: Numba prunes the branch not taken; o: (m, 3) flat
            v0, v1, v2 = kernel(ix, iy, iz, ox, oy, oz, p)  # noqa: F821 - total
            store_output(o, 3 * j, v0 if ok else math.nan)  # an interleaved store group
            store_output(o, 3 * j + 1, v1 if ok else math.nan)
            store_output(o, 3 * j + 2, v2 if ok else math.nan)
        else:
            v = kernel(ix, iy, iz, ox, oy, oz, p)  # noqa: F821 - total: safe for any input
            store_output(o, j, v if ok else math.nan)
        good += numba.int64(ok)
    return good


def _vector_loop(wi, wo, P, out):  # pragma: no cover - compiled in the generated modules
    n = wi.shape[0]
    n_channels = P.shape[0]
    a = wi.reshape(3 * n)
    b = wo.reshape(3 * n)
    n_chunks = (n + _CHUNK - 1) // _CHUNK
    n_good = 0
    if RGB:  # noqa: F821 - the rows as one tuple of WIDTH = 3 K: no loads in the loop
        t = to_fixed_tuple(P.reshape(P.size), WIDTH)  # noqa: F821
        o = out.reshape(3 * n)
        for q in numba.prange(n_chunks):
            lo = q * _CHUNK
            hi = min(n, lo + _CHUNK)
            n_good += chunk(a[3 * lo:3 * hi], b[3 * lo:3 * hi], o[3 * lo:3 * hi], t)  # noqa: F821
        return n - n_good
    if n_channels == 1:
        o = out.reshape(n)
        p = P[0]
        for q in numba.prange(n_chunks):
            lo = q * _CHUNK
            hi = min(n, lo + _CHUNK)
            n_good += chunk(a[3 * lo:3 * hi], b[3 * lo:3 * hi], o[lo:hi], p)  # noqa: F821
        return n - n_good
    col = np.empty(n)  # one channel at a time, then strided into out
    for c in range(n_channels):
        p = P[c]
        for q in numba.prange(n_chunks):
            lo = q * _CHUNK
            hi = min(n, lo + _CHUNK)
            n_good += chunk(a[3 * lo:3 * hi], b[3 * lo:3 * hi], col[lo:hi], p)  # noqa: F821
        out[:, c] = col
    return n - n_good // n_channels


# The "blocked" loop, for table lookups (a measured material): the pairs of a block are
# first located (arithmetic: the bin or cell of each), then read (random reads of a large
# table, whose cache and TLB misses the memory system then serves many at once). Three
# hooks, the globals of each generated module: `block_state()` the block's scratch arrays,
# `block_pair(state, t, ix, iy, iz, ox, oy, oz, P)` locates pair t of the block,
# `block_emit(state, t, P, out, j)` writes row j and returns 1 for a rejected pair, else 0;
# `BLOCK` the pairs per block. A template only, as the vector loop.
def _blocked_loop(wi, wo, P, out):  # pragma: no cover - compiled in the generated modules
    n = wi.shape[0]
    n_bad = 0
    for q in numba.prange((n + BLOCK - 1) // BLOCK):  # noqa: F821
        lo = q * BLOCK  # noqa: F821
        hi = min(n, lo + BLOCK)  # noqa: F821
        state = block_state()  # noqa: F821
        for j in range(lo, hi):
            block_pair(state, j - lo, wi[j, 0], wi[j, 1], wi[j, 2],  # noqa: F821
                       wo[j, 0], wo[j, 1], wo[j, 2], P)
        for j in range(lo, hi):
            n_bad += block_emit(state, j - lo, P, out, j)  # noqa: F821
    return n_bad


# The "albedo" loop: the albedo engine's nodes, incident directions (sin θ_i cos φ_i,
# sin θ_i sin φ_i, cos θ_i) by angle and outgoing directions by node (offsets[i]..offsets[i+1]
# for angle i), generated for ω_i at azimuth 0 and rotated here about the normal by φ_i (the
# engine's one seam for the incidence azimuth; rotation commutes with every frame the nodes
# are built in). φ_i = 0 reads the nodes as they are (no rotation: the same values, bit for
# bit, as before the azimuth existed). Serial: it compiles in ~0.3 s instead of ~1 s for a
# prange loop (Table 2 compiles it for every registered model), and the engine's calls are
# small. A template only, as above.
def _albedo_nodes(kernel, P, thetas, phis, offsets, wo, vals, bad):  # pragma: no cover
    """vals[j, c] = kernel(ω_i(θ, φ of j), R_φ wo[j], P[c]) with R_φ the rotation by φ about
    the normal; bad[i] counts the non-finite values of angle i (stored as 0 so that they
    cannot poison the sums of the other angles)."""
    for i in range(thetas.shape[0]):
        s = math.sin(thetas[i])
        iz = math.cos(thetas[i])
        rotate = phis[i] != 0.0
        cp = math.cos(phis[i])
        sp = math.sin(phis[i])
        ix = s * cp if rotate else s
        iy = s * sp if rotate else 0.0
        for j in range(offsets[i], offsets[i + 1]):
            ox, oy = wo[j, 0], wo[j, 1]
            if rotate:
                ox, oy = cp * wo[j, 0] - sp * wo[j, 1], sp * wo[j, 0] + cp * wo[j, 1]
            for ch in range(P.shape[0]):
                if wo[j, 2] <= 0.0:
                    vals[j, ch] = 0.0
                    continue
                v = kernel(ix, iy, iz, ox, oy, wo[j, 2], P[ch])
                if math.isfinite(v):
                    vals[j, ch] = v
                else:
                    vals[j, ch] = 0.0
                    bad[i] += 1


#: The loops the generator writes: name → (the functions of the generated module, each
#: (its name there, its template, its compile options as source); the module's
#: constants). The template's statements are copied (docstring and a leading ``kernel``
#: argument dropped), so a loop is written once and the generated copies cannot drift
#: from it; every generated module calls its loop ``driver``: ``(wi, wo, P, out) -> n_bad``,
#: except ``"albedo"``'s ``(P, thetas, phis, offsets, wo, vals, bad)``. ``"plain"`` is
#: ``"checked"`` without the test (for arrays already checked).
# Every loop divides as IEEE does (error_model "numpy"): the kernel is inlined into the
# loop and compiled with the loop's options, and a user's formula (a .brdf file, a Python
# model) may divide by zero where it makes a NaN or an infinity that the engines report —
# Python's error model would raise ZeroDivisionError from inside the loop instead. For the
# built-in kernels, which never divide by zero, the values are the same.
LOOPS = {
    "checked": ((("driver", eval_pairs_checked, 'parallel=True, error_model="numpy"'),),
                {"CHECK": True}),
    "plain": ((("driver", eval_pairs_checked, 'parallel=True, error_model="numpy"'),),
              {"CHECK": False}),
    "vector": ((("chunk", _vector_chunk, "**VECTOR_OPTIONS"),
                ("driver", _vector_loop, "parallel=True, **VECTOR_OPTIONS")), {"RGB": False}),
    "rgb": ((("chunk", _vector_chunk, "**VECTOR_OPTIONS"),
             ("driver", _vector_loop, "parallel=True, **VECTOR_OPTIONS")), {"RGB": True}),
    "blocked": ((("driver", _blocked_loop, 'parallel=True, error_model="numpy"'),), {}),
    "albedo": ((("driver", _albedo_nodes, 'error_model="numpy"'),), {}),
}


def add_loop(loop: str, functions: tuple, constants: dict | None = None) -> None:
    """Register a higher layer's loop (render's sphere loop) in :data:`LOOPS`, in the same
    form: :func:`loop_driver` generates and caches it per kernel. A name is taken once."""
    if LOOPS.setdefault(loop, (functions, constants or {})) != (functions, constants or {}):
        raise ValueError(f"loop {loop!r} is registered already with other functions")


#: Loops (branching) calling ``kernel`` via ``_kernel_call``, not inlined in Numba's IR at each
#: site (which redoes its own inlining each time: the checked loop's two prange sites cost 170 s
#: of a pumped nielsen's 265 s cold test). Same values (error model, no fastmath).
CALLED_KERNEL_LOOPS = frozenset({"checked", "plain", "albedo"})
KERNEL_CALL = ("def _kernel_call(ix, iy, iz, ox, oy, oz, p):  # pragma: no cover\n"
               "    return kernel(ix, iy, iz, ox, oy, oz, p)\n")


@memo(maxsize=32)  # one entry per (loop, flags): 5 loops × a few flag sets
def _loop_source(loop: str, *, cache: bool, generic: bool = False,
                 parallel: bool = True) -> str:
    """The functions of loop *loop* as source, decorated (``cache=True`` when *cache*), with
    the loop's constants first. *generic*: the kernel stays the first argument (one
    compiled loop for any kernel, keyed per kernel by Numba), else :data:`CALLED_KERNEL_LOOPS`
    call it through ``_kernel_call``; *parallel* False: serial."""
    if loop not in LOOPS:
        raise ValueError(f"loop must be one of {', '.join(LOOPS)}; got {loop!r}")
    functions, constants = LOOPS[loop]
    parts = ["".join(f"{k} = {v!r}\n" for k, v in constants.items())]
    if called := not generic and loop in CALLED_KERNEL_LOOPS:
        parts.append(f'@numba.njit(error_model="numpy"{", cache=True" * cache})\n{KERNEL_CALL}')
    for name, template, options in functions:
        py = getattr(template, "py_func", template)
        fn = ast.parse(textwrap.dedent(inspect.getsource(py))).body[0]
        fn.name = name
        fn.decorator_list = []
        if fn.args.args[0].arg == "kernel" and not generic:  # the kernel becomes a global
            fn.args.args = fn.args.args[1:]
        for node in ast.walk(fn) if called else ():  # every kernel call through _kernel_call
            if isinstance(node, ast.Name) and node.id == "kernel":
                node.id = "_kernel_call"
        body = fn.body
        if (isinstance(body[0], ast.Expr) and isinstance(body[0].value, ast.Constant)
                and isinstance(body[0].value.value, str)):
            fn.body = body[1:]  # the docstring
        flags = options if parallel else options.replace("parallel=True", "parallel=False")
        flags = ", ".join(f for f in (flags, "cache=True" if cache else "") if f)
        parts.append(f"@numba.njit({flags})\n{ast.unparse(fn)}  # pragma: no cover\n")
    return "\n\n".join(parts)


def generic_loop(loop: str = "plain", *, parallel: bool = True):
    """The loop *loop* with the kernel as its first argument, compiled in memory (Numba
    specialises it per kernel in each process): ``driver(kernel, wi, wo, P, out)``."""
    namespace = dict(_LOOP_GLOBALS)
    exec(compile(_loop_source(loop, cache=False, generic=True, parallel=parallel),
                 f"<brdfkit generic {loop} loop>", "exec"), namespace)
    return namespace["driver"]


def _compose(template, module: str, bindings: dict, options: dict):
    """*template* compiled with *bindings* as globals, named ``kernel`` of *module*.

    The same code object as the template (so the same compiled code as a closure
    over these values would give); Numba reads the bound globals as compile-time
    constants.
    """
    namespace = dict(template.__globals__)
    namespace.update(bindings)
    namespace["__name__"] = module
    fn = types.FunctionType(template.__code__, namespace, "kernel", template.__defaults__)
    fn.__qualname__ = "kernel"
    return numba.njit(**options)(fn)


# --------------------------------------------------------------------------- the generator
#: Generated directories of other stamps (older brdfkit sources) older than this are
#: removed when a new one is made (a week: long enough that a second checkout or virtual
#: environment in use beside this one keeps its cache).
_PRUNE_AGE_S = 7 * 24 * 3600

_HEADER = '''\
"""Generated by brdfkit.models._drivers ({what}, the {loop} loop); do not edit."""
import math

import numba
import numpy as np

from brdfkit.models._drivers import (_CHUNK, VECTOR_OPTIONS, _compose, _unit_pair,
                                     load_input, store_output, to_fixed_tuple)
'''
# the globals every generated loop reads, for the loops compiled in memory
_LOOP_GLOBALS = {"math": math, "numba": numba, "np": np, "_unit_pair": _unit_pair, "_CHUNK": _CHUNK,
                 "VECTOR_OPTIONS": VECTOR_OPTIONS, "to_fixed_tuple": to_fixed_tuple,
                 "load_input": load_input, "store_output": store_output}

#: memo key -> (what it was built from, result): the entry holds what it was built from, so
#: an id() in a key stays that object's while the entry lives; one entry per kernel, loop
#: and composition in use, far below the bound
_generated = bounded_cache("brdfkit.models._drivers._generated", maxsize=1024)


def cache_dir() -> Path:
    """The directory holding the generated driver modules (not created here)."""
    return disk_cache_dir("drivers")


def _resolve(module: str, qualname: str):
    obj = importlib.import_module(module)
    for part in qualname.split("."):
        obj = getattr(obj, part)
    return obj


def _import_line(obj, alias: str) -> str | None:
    """``from M import H as alias`` (+ the attribute tail) naming *obj*, or None when it
    has no importable name (a closure, a lambda, ``__main__``, a name rebound since)."""
    py = getattr(obj, "py_func", obj)
    module, qualname = getattr(py, "__module__", None), getattr(py, "__qualname__", "<")
    if module is None or "<" in qualname or module == "__main__":
        return None
    try:
        if _resolve(module, qualname) is not obj:
            return None
    except (ImportError, AttributeError):
        return None
    head, _, rest = qualname.partition(".")
    tail = "".join(f".{part}" for part in rest.split(".")) if rest else ""
    if tail:
        return f"from {module} import {head} as _{alias}_owner\n{alias} = _{alias}_owner{tail}\n"
    return f"from {module} import {head} as {alias}\n"


def _prune(parent: Path, keep: str) -> None:
    now = time.time()
    for old in parent.iterdir():
        try:
            if old.name != keep and old.is_dir() and now - old.stat().st_mtime > _PRUNE_AGE_S:
                shutil.rmtree(old, ignore_errors=True)
        except OSError:  # another process pruned it first
            pass


def _load(source: str):
    """The generated module of *source*, written once per source stamp; None when the
    cache directory cannot be written or Numba finds no place for its cache."""
    stamp = source_stamp()
    key = hashlib.sha256(source.encode()).hexdigest()[:12]
    name = f"_brdfkit_driver_{stamp}_{key}"
    if name in sys.modules:
        return sys.modules[name]
    directory = cache_dir() / stamp
    path = directory / f"{name}.py"
    try:
        if not path.exists():
            fresh = not directory.exists()
            directory.mkdir(parents=True, exist_ok=True)
            tmp = directory / f".{name}.{os.getpid()}.tmp"
            tmp.write_text(source)
            os.replace(tmp, path)  # atomic: a concurrent process sees the whole file or none
            if fresh:
                _prune(directory.parent, keep=stamp)
        spec = importlib.util.spec_from_file_location(name, path)
        generated = importlib.util.module_from_spec(spec)
        sys.modules[name] = generated  # Numba's cache locator looks the module up by name
        spec.loader.exec_module(generated)
    except (OSError, RuntimeError):
        # not writable, or Numba found no place for its cache ("no locator available",
        # a RuntimeError raised by cache=True): the caller compiles in memory
        sys.modules.pop(name, None)
        return None
    return generated


def _literal(value, alias: str) -> str | None:
    """``alias = value`` for a Python number or flag, else the import naming *value*."""
    if isinstance(value, bool | int | float) and not isinstance(value, np.generic):
        return f"{alias} = {value!r}\n"
    return _import_line(value, alias)


def _generate(what: str, loop: str, bindings: dict, kernel: tuple | None = None):
    """The loop *loop* with *bindings* (name → kernel, hook or number) as the globals of one
    generated module, cached on disk; else compiled in memory. *kernel* = (template,
    bound names, njit options): a ``kernel`` composed in the same module (:func:`composed`).
    Returns the module's namespace (``driver``, and ``kernel``)."""
    lines = [_literal(v, k) for k, v in bindings.items()]
    if kernel is not None:
        template, bound, options = kernel
        lines.append(_import_line(template, "_template"))
        lines += [_literal(v, f"_bound_{k}") for k, v in bound.items()]
        names = ", ".join(f"{k!r}: _bound_{k}" for k in bound)
        lines.append(f"kernel = _compose(_template, __name__, {{{names}}}, {options!r})\n")
    if all(line is not None for line in lines):
        source = (_HEADER.format(what=what, loop=loop) + "".join(lines) + "\n\n"
                  + _loop_source(loop, cache=True))
        generated = _load(source)
        if generated is not None:
            return vars(generated)
    namespace = {**_LOOP_GLOBALS, **bindings}
    if kernel is not None:
        template, bound, options = kernel
        namespace["kernel"] = _compose(template, "<brdfkit composed>", dict(bound), options)
    exec(compile(_loop_source(loop, cache=False), f"<brdfkit {loop} loop>", "exec"), namespace)
    return namespace


def _memo(key, build):
    if key not in _generated:
        _generated[key] = build()
    return _generated[key][1]


def _name(obj) -> str:
    py = getattr(obj, "py_func", obj)
    return f"{py.__module__}.{py.__qualname__}"


def loop_driver(kernel, *, loop: str = "checked", width: int = 0):
    """The loop *loop* (:data:`LOOPS`: ``"checked"``, ``"plain"``, ``"vector"``, ``"rgb"``)
    for *kernel*: ``driver(wi, wo, P, out) -> n_bad`` (``"rgb"``: P (3, K) passed to the
    kernel as the flat tuple of its *width* = 3 K values, three channels out, (N, 3)).

    Generated as a module and cached on disk when the kernel has an importable name (the
    second process loads it in milliseconds); else compiled in memory. Memoised.
    """
    bound = {"kernel": kernel, **({"WIDTH": int(width)} if width else {})}
    return _memo((id(kernel), loop, width), lambda: (kernel, _generate(
        f"kernel {_name(kernel)}", loop, bound)["driver"]))


def blocked_driver(*, state, pair, emit, block: int):
    """The ``"blocked"`` loop (:func:`_blocked_loop`) with its hooks: *state* (the block's
    scratch), *pair* (locate one pair), *emit* (write one row; 1 for a rejected pair),
    ``inline="always"`` functions with importable names; *block* pairs per block.
    Cached on disk as :func:`loop_driver`; ``driver(wi, wo, P, out) -> n_bad``."""
    hooks = {"block_state": state, "block_pair": pair, "block_emit": emit, "BLOCK": int(block)}
    return _memo(("blocked", id(state), id(pair), id(emit), int(block)), lambda: (
        hooks, _generate(f"hooks {_name(pair)}", "blocked", hooks)["driver"]))


def cached_driver(kernel):
    """The checked loop for *kernel*, cached on disk; None when not possible (no importable
    name, no writable cache directory). :meth:`BRDF.eval` uses :func:`loop_driver`."""
    def build():
        line = _import_line(kernel, "kernel")
        if line is None:
            return kernel, None
        generated = _load(_HEADER.format(what=f"kernel {_name(kernel)}", loop="checked")
                          + line + "\n\n" + _loop_source("checked", cache=True))
        return kernel, None if generated is None else generated.driver

    return _memo((id(kernel), "checked", "disk"), build)


def checked_driver(kernel, *, vectorise: bool = False):
    """:func:`loop_driver` of *kernel*, ``"vector"`` when *vectorise* else ``"checked"``."""
    return loop_driver(kernel, loop="vector" if vectorise else "checked")


def composed(template, *, loop: str = "checked", options: dict | None = None, **bindings):
    """(kernel, driver): *template* compiled with *bindings* as its globals, and its loop.

    *template* is a plain module-level function written over globals that each
    composition binds (another kernel, an int offset, a flag: compile-time constants
    in the compiled code); *options* are its ``numba.njit`` options (default
    ``inline="always"``, so that it is inlined into its loop). Both are generated as
    one module and cached on disk when the template and every bound kernel have
    importable names (a composed kernel has one: ``kernel`` of its generated
    module, so compositions nest); otherwise compiled in memory. Memoised.
    """
    options = {"inline": "always"} if options is None else dict(options)
    bound = dict(sorted(bindings.items()))
    key = (template, loop, repr(sorted(options.items())),
           tuple((k, id(v) if hasattr(v, "py_func") else v) for k, v in bound.items()))

    def build():
        ns = _generate(f"{_name(template)} with {', '.join(bound)}", loop, {},
                       kernel=(template, bound, options))
        return (template, bound), (ns["kernel"], ns["driver"])

    return _memo(key, build)


#: :func:`eval_pairs_checked` without the test (``"plain"``), for code that has packed,
#: checked arrays: ``eval_pairs(kernel, wi, wo, P, out)``, out[j, c] = kernel(wi[j], wo[j],
#: P[c]). Not cached on disk: a specialisation is keyed on the kernel's dispatcher, which is
#: new in every process (the kernels themselves are cached; compiling this loop around one
#: costs ~0.5-1 s once per process and model).
eval_pairs = generic_loop("plain")
