"""
The compiled evaluation loops of every model
============================================

A model's kernel is a scalar function of one pair of directions
(:mod:`brdfkit.models._base`); these loops run it over all pairs and channels.

- :func:`eval_pairs` — the loop for code that has packed arrays (no checks).
- :func:`eval_pairs_checked` — the same, also testing in the same pass that the
  directions are finite unit vectors (:data:`UNIT_TOL`); the kernel is an argument.
- :func:`checked_driver` — the checked loop compiled for one kernel, inlined
  (composite kernels such as pumped models'; with ``vectorise=True`` the
  vectorised loop of branch-free kernels such as the microfacet models').
- :func:`cached_driver` — the checked loop for a kernel with an importable name,
  compiled once and kept on disk (below): what :meth:`BRDF.eval` runs.
- :func:`cache_dir` — where those loops are kept.

Loops kept on disk
------------------
:meth:`BRDF.eval <brdfkit.models.BRDF.eval>` runs a model's kernel over all
pairs with :func:`~brdfkit.models.eval_pairs_checked`, which takes the kernel
as a first-class function argument. Numba cannot cache such a specialisation
on disk (it is keyed on the kernel's dispatcher, a new object in every
process), so every process paid ~1-2 s per model to compile the loop again:
most of the 5-6 s a one-line ``brdfkit fit`` took.

Here the same loop is written into a tiny generated module per kernel, with the
kernel as a module global, so that Numba's ordinary ``cache=True`` applies: the
second process loads the compiled loop in milliseconds.

Staleness. Numba invalidates a cache entry when *its own* source file changes,
not when a function it calls changes. The generated file's directory is
therefore named after a stamp of every source file of the brdfkit package
(path, size, modification time), Numba's and Python's versions: any edit to
brdfkit gives new files, and the old directories are pruned after a week.

Where. ``$BRDFKIT_CACHE_DIR`` if set, else ``$XDG_CACHE_HOME/brdfkit`` (default
``~/.cache/brdfkit``), subdirectory ``drivers``. When the directory cannot be
written, or a kernel has no importable name (a closure, a composite kernel
built at run time), :func:`cached_driver` returns None and the caller keeps the
uncached generic loop: nothing fails, it is only slower.
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
from pathlib import Path

import numba
import numpy as np

from brdfkit._cache import bounded_cache, memo

__all__ = ["SERIAL_BELOW", "UNIT_TOL", "VECTOR_OPTIONS", "eval_pairs", "eval_pairs_checked",
           "checked_driver", "cached_driver", "cache_dir"]


# Not cached on disk: a specialisation is keyed on the kernel's dispatcher, which is new
# in every process, so an on-disk entry could never be reused (and Numba fails to re-save
# an index holding dead dispatchers). The kernels themselves are cached; compiling this
# loop around one costs ~0.5-1 s once per process and model.
@numba.njit(parallel=True)
def eval_pairs(kernel, wi, wo, P, out):  # pragma: no cover - compiled
    """out[j, c] = kernel(wi[j], wo[j], P[c]) for all pairs j and channels c.

    ``wi``, ``wo``: (N, 3) C-contiguous float64; ``P``: (C, K) packed
    parameters; ``out``: (N, C).
    """
    n = wi.shape[0]
    n_channels = P.shape[0]
    if n_channels == 1:
        # the common case, with the parameter row hoisted out of the loop
        p = P[0]
        for j in numba.prange(n):
            out[j, 0] = kernel(wi[j, 0], wi[j, 1], wi[j, 2], wo[j, 0], wo[j, 1], wo[j, 2], p)
    else:
        for j in numba.prange(n):
            for c in range(n_channels):
                out[j, c] = kernel(wi[j, 0], wi[j, 1], wi[j, 2], wo[j, 0], wo[j, 1], wo[j, 2],
                                   P[c])


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


# Compile options of the vectorising drivers (checked_driver(..., vectorise=True)): a kernel
# inlined into them is compiled with the driver's options, so these are the kernel's.
# error_model="numpy": IEEE division (no zero-divisor test, which would be a branch);
# no fastmath flags: not even "contract" (fused multiply-adds), which LLVM applies
# differently in the vector body and the scalar remainder, so one pair's value depended on
# its position in the array by an ulp (tests/test_registry_properties.py, broadcasting).
VECTOR_OPTIONS = {"error_model": "numpy", "fastmath": set()}
_CHUNK = 4096  # pairs per task of the vectorised drivers (96 KiB of directions)


def checked_driver(kernel, *, vectorise: bool = False):
    """:func:`eval_pairs_checked` specialised to one *kernel* (a new compiled function).

    :func:`eval_pairs_checked` calls its kernel through a first-class function
    argument, which LLVM inlines only when the kernel is small; a composite
    kernel (a pumped model: the base kernel plus table lookups) then stays an
    out-of-line call per pair, with its packed-array argument spilled to the
    stack. Here the kernel is a global of the compiled loop, so Numba inlines it
    into the loop when it is declared ``inline="always"``. Measured on 10 M pairs: a
    pumped Phong at the base model's speed instead of 1.2-1.6x slower. A model
    opts in by setting its ``_driver`` attribute (see :meth:`BRDF.eval`).

    ``vectorise=True`` is for kernels written branch-free and *total*: for any
    input values (NaN, inf, non-unit) they return without side effects and
    read memory only in bounds (see :mod:`brdfkit._kern`). The driver then
    evaluates every pair and selects NaN for the rejected ones instead of
    branching around the kernel, so that LLVM vectorises the loop (4 float64
    lanes with AVX2), and is compiled with :data:`VECTOR_OPTIONS`. The
    directions are read as flat arrays (index 3j + k), which LLVM loads as
    interleaved groups; measured on 10 M pairs (microfacet, Beckmann α = 0.1):
    2.3x the generic loop on one thread.
    """

    if vectorise:
        @numba.njit(**VECTOR_OPTIONS)
        def chunk(a, b, o, p):  # pragma: no cover - compiled
            # One channel of the pairs in a and b (flat, 3 per pair) into o; returns the
            # number of good pairs. What LLVM needs to vectorise this loop, each measured:
            # its own function (inside the prange body Numba keeps the loop's variables
            # live after it), indices from 0 (a signed start needs the negative-index
            # wraparound select, and the loads are no longer an interleaved group),
            # a unit-stride store, and the count as int64(ok) (not a select of 0 and 1).
            good = 0
            for j in range(o.shape[0]):
                ix, iy, iz = a[3 * j], a[3 * j + 1], a[3 * j + 2]
                ox, oy, oz = b[3 * j], b[3 * j + 1], b[3 * j + 2]
                ok = _unit_pair(ix, iy, iz, ox, oy, oz)
                v = kernel(ix, iy, iz, ox, oy, oz, p)  # total: safe for any input
                o[j] = v if ok else math.nan
                good += numba.int64(ok)
            return good

        @numba.njit(parallel=True, **VECTOR_OPTIONS)
        def vector_driver(wi, wo, P, out):  # pragma: no cover - compiled
            n = wi.shape[0]
            n_channels = P.shape[0]
            a = wi.reshape(3 * n)
            b = wo.reshape(3 * n)
            n_chunks = (n + _CHUNK - 1) // _CHUNK
            n_good = 0
            if n_channels == 1:
                o = out.reshape(n)
                p = P[0]
                for q in numba.prange(n_chunks):
                    lo = q * _CHUNK
                    hi = min(n, lo + _CHUNK)
                    n_good += chunk(a[3 * lo:3 * hi], b[3 * lo:3 * hi], o[lo:hi], p)
                return n - n_good
            col = np.empty(n)  # one channel at a time, then strided into out
            for c in range(n_channels):
                p = P[c]
                for q in numba.prange(n_chunks):
                    lo = q * _CHUNK
                    hi = min(n, lo + _CHUNK)
                    n_good += chunk(a[3 * lo:3 * hi], b[3 * lo:3 * hi], col[lo:hi], p)
                out[:, c] = col
            return n - n_good // n_channels

        return vector_driver

    # eval_pairs_checked's statements with the kernel a global of their own namespace (as
    # in the disk-cached loops below), not a shared inline="always" body called from both:
    # there the kernel became a variable of the inlined body and was no longer inlined
    # (measured on 10 M pairs: 4-20 % slower, as slow as the generic loop)
    namespace = {"math": math, "numba": numba, "_unit_pair": _unit_pair, "kernel": kernel}
    exec(compile("def driver(wi, wo, P, out):\n" + _loop_body(), "<brdfkit checked_driver>",
                 "exec"), namespace)
    return numba.njit(parallel=True)(namespace["driver"])


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
            if _unit_pair(ix, iy, iz, ox, oy, oz):
                out[j, 0] = kernel(ix, iy, iz, ox, oy, oz, p)
            else:
                out[j, 0] = math.nan
                n_bad += 1
    else:
        for j in numba.prange(n):
            ix, iy, iz = wi[j, 0], wi[j, 1], wi[j, 2]
            ox, oy, oz = wo[j, 0], wo[j, 1], wo[j, 2]
            if _unit_pair(ix, iy, iz, ox, oy, oz):
                for c in range(n_channels):
                    out[j, c] = kernel(ix, iy, iz, ox, oy, oz, P[c])
            else:
                for c in range(n_channels):
                    out[j, c] = math.nan
                n_bad += 1
    return n_bad



#: Generated directories of other stamps (older brdfkit sources) older than this are
#: removed when a new one is made (a week: long enough that a second checkout or virtual
#: environment in use beside this one keeps its cache).
_PRUNE_AGE_S = 7 * 24 * 3600

# The generated module: eval_pairs_checked's loop (its statements, from its source), with the
# kernel a global so that Numba can cache it and LLVM can inline it; results are bit-equal
# (same code, same compile options). tests/test_driver_cache.py checks both.
_HEADER = '''\
"""Generated by brdfkit.models._drivers for {module}.{qualname}; do not edit."""
import math

import numba

from brdfkit.models._drivers import _unit_pair
from {module} import {head} as _owner

kernel = _owner{tail}


@numba.njit(parallel=True, cache=True)
def driver(wi, wo, P, out):  # pragma: no cover - compiled
'''


def _loop_body() -> str:
    """The statements of :func:`eval_pairs_checked` (its docstring dropped), indented for
    the generated ``driver``: the loop is written once, so the two cannot drift apart."""
    tree = ast.parse(textwrap.dedent(inspect.getsource(eval_pairs_checked.py_func)))
    body = tree.body[0].body[1:]  # [0] is the docstring
    return textwrap.indent("\n".join(ast.unparse(stmt) for stmt in body), "    ") + "\n"


#: id(kernel) -> driver or None (kernels live as long; a driver module keeps its kernel):
#: one per kernel in use, far below the bound
_drivers = bounded_cache("brdfkit.models._drivers._drivers", maxsize=1024)


def cache_dir() -> Path:
    """The directory holding the generated driver modules (not created here)."""
    root = os.environ.get("BRDFKIT_CACHE_DIR")
    if not root:
        xdg = os.environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"), ".cache")
        root = os.path.join(xdg, "brdfkit")
    return Path(root) / "drivers"


@memo(maxsize=1)  # once per process
def _source_stamp() -> str:
    """Hash of every brdfkit source file's (path, size, mtime) and the tool versions."""
    package = Path(__file__).resolve().parents[1]
    h = hashlib.sha256(f"{sys.version}|{numba.__version__}|{package}".encode())
    for path in sorted(package.rglob("*.py")):
        st = path.stat()
        h.update(f"{path.relative_to(package)}|{st.st_size}|{st.st_mtime_ns}\n".encode())
    return h.hexdigest()[:16]


def _resolve(module: str, qualname: str):
    obj = importlib.import_module(module)
    for part in qualname.split("."):
        obj = getattr(obj, part)
    return obj


def _prune(parent: Path, keep: str) -> None:
    now = time.time()
    for old in parent.iterdir():
        try:
            if old.name != keep and old.is_dir() and now - old.stat().st_mtime > _PRUNE_AGE_S:
                shutil.rmtree(old, ignore_errors=True)
        except OSError:  # another process pruned it first
            pass


def _build(kernel):
    py = getattr(kernel, "py_func", None)
    if py is None:
        return None
    module, qualname = py.__module__, py.__qualname__
    if "<" in qualname or module == "__main__":
        return None  # a closure or a lambda: no importable name
    try:
        if _resolve(module, qualname) is not kernel:
            return None  # the name now holds another object (e.g. redefined)
    except (ImportError, AttributeError):
        return None
    stamp = _source_stamp()
    head, _, rest = qualname.partition(".")
    tail = "".join(f".{part}" for part in rest.split(".")) if rest else ""
    source = _HEADER.format(module=module, qualname=qualname, head=head, tail=tail) + _loop_body()
    key = hashlib.sha256(f"{module}:{qualname}".encode()).hexdigest()[:12]
    name = f"_brdfkit_driver_{stamp}_{key}"
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
        # a RuntimeError raised by cache=True): the caller keeps the uncached loop
        sys.modules.pop(name, None)
        return None
    return generated.driver


def cached_driver(kernel):
    """The checked evaluation loop for *kernel*, cached on disk; None when not possible.

    The returned function has :func:`~brdfkit.models.eval_pairs_checked`'s
    signature without the kernel: ``driver(wi, wo, P, out) -> n_bad``.
    """
    key = id(kernel)
    if key not in _drivers:
        _drivers[key] = _build(kernel)
    return _drivers[key]
