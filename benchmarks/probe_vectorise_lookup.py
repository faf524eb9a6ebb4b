"""Why a compensated kernel does not vectorise: LLVM's own answer (issue 22 §5).

Compiles, outside brdfkit, the shape of the "vector" loop (``models/_drivers.py``:
directions read as flat arrays, one store per pair) around the Kulla–Conty arithmetic
f + (1 − Ẽ(μ_i))(1 − Ẽ(μ_o)) with Ẽ a single-level table lookup (uniform cells, contiguous
cubic coefficients, index clamped by selects: no branches), and prints for each variant
LLVM's loop-vectorize remarks and the vector instructions of the loop (Numba's
``inspect_asm``):

1. ``plain`` — the lookup as brdfkit's kernels read their packed row ``p[b]``;
2. ``no-index`` — the same arithmetic with the coefficients at constant offsets (no
   data-dependent index);
3. ``scoped`` — every load of the loop tagged ``!alias.scope`` and the store ``!noalias``
   (scoped-noalias metadata, written by a Numba ``@intrinsic``);
4. ``scoped+1`` — as 3 with one untagged load of ``p`` at a constant index (as a base
   kernel reads its parameters).

Measured (Numba 0.68.1/llvmlite 0.50, LLVM host CPU "rocketlake" with AVX-512): 1 "loop not
vectorized: cannot identify array bounds" (0 gathers); 2 vectorised; 3 vectorised, width 4,
``vgatherqpd`` on ymm; 4 "cannot identify array bounds" again. Numba gives array arguments
no ``noalias`` (no ``njit`` option sets it), so LLVM may vectorise a loop that stores into
``out`` and reads ``p`` only after a run-time overlap check, which it can build for affine
indices and not for a data-dependent one; alias sets merge transitively, so one untagged
load in the loop is enough to need it. brdfkit's vector loop and compensated kernels
are written that way since (``brdfkit._kern.load_input``; ``docs/compensation.md``,
"Speed"; ``docs/architecture.md``, "Gathers in the vectorising loop").

Run: ``.venv/bin/python benchmarks/probe_vectorise_lookup.py`` (about a minute).
"""

from __future__ import annotations

import os
import re
import sys

import llvmlite.binding as ll
import numba
import numpy as np
from numba.core import types
from numba.extending import intrinsic

OPTIONS = {"error_model": "numpy", "fastmath": set()}  # as VECTOR_OPTIONS


def _scope(module):
    domain = module.add_metadata(["probe tables domain"])
    return module.add_metadata([module.add_metadata(["probe tables", domain])])


@intrinsic
def ld(typingctx, arr, i):
    """arr[i] tagged !alias.scope (no wraparound, no bounds check)."""
    def codegen(context, builder, sig, args):
        a = context.make_array(sig.args[0])(context, builder, args[0])
        v = builder.load(builder.gep(a.data, [args[1]]))
        v.set_metadata("alias.scope", _scope(builder.module))
        return v
    return arr.dtype(arr, i), codegen


@intrinsic
def st(typingctx, arr, i, x):
    """arr[i] = x tagged !noalias of the loads' scope."""
    def codegen(context, builder, sig, args):
        a = context.make_array(sig.args[0])(context, builder, args[0])
        s = builder.store(args[2], builder.gep(a.data, [args[1]]))
        s.set_metadata("noalias", _scope(builder.module))
        return context.get_dummy_value()
    return types.void(arr, i, x), codegen


@numba.njit(inline="always", **OPTIONS)
def lookup(p, off, mu):  # single level: N uniform cells in mu, cubic coefficients at off+1
    n = p[off]
    mu = mu if mu > 0.0 else 0.0  # select: clamp to [0, 1]
    mu = mu if mu < 1.0 else 1.0
    x = mu * n
    j = numba.int64(x)
    last = numba.int64(n) - 1
    j = j if j < last else last  # select: mu = 1 reads the last cell
    t = x - j
    b = off + 1 + 4 * j
    return ((p[b] * t + p[b + 1]) * t + p[b + 2]) * t + p[b + 3]


@numba.njit(inline="always", **OPTIONS)
def lookup_scoped(p, off, mu):
    n = ld(p, off)
    mu = mu if mu > 0.0 else 0.0
    mu = mu if mu < 1.0 else 1.0
    x = mu * n
    j = numba.int64(x)
    last = numba.int64(n) - 1
    j = j if j < last else last
    t = x - j
    b = off + 1 + 4 * j
    return ((ld(p, b) * t + ld(p, b + 1)) * t + ld(p, b + 2)) * t + ld(p, b + 3)


@numba.njit(inline="always", **OPTIONS)
def lookup_no_index(p, off, mu):
    x = mu * p[off]
    t = x - numba.int64(x)
    return ((p[off + 1] * t + p[off + 2]) * t + p[off + 3]) * t + p[off + 4]


@numba.njit(**OPTIONS)
def plain(a, o, p):
    for j in range(o.shape[0]):
        iz, oz = a[3 * j + 2], a[3 * j + 1]
        o[j] = iz * oz + (1.0 - lookup(p, 2, iz)) * (1.0 - lookup(p, 2, oz))


@numba.njit(**OPTIONS)
def no_index(a, o, p):
    for j in range(o.shape[0]):
        iz, oz = a[3 * j + 2], a[3 * j + 1]
        o[j] = iz * oz + (1.0 - lookup_no_index(p, 2, iz)) * (1.0 - lookup_no_index(p, 2, oz))


@numba.njit(**OPTIONS)
def scoped(a, o, p):
    for j in range(o.shape[0]):
        iz, oz = ld(a, 3 * j + 2), ld(a, 3 * j + 1)
        st(o, j, iz * oz + (1.0 - lookup_scoped(p, 2, iz)) * (1.0 - lookup_scoped(p, 2, oz)))


@numba.njit(**OPTIONS)
def scoped_plus_one(a, o, p):
    for j in range(o.shape[0]):
        iz, oz = ld(a, 3 * j + 2), ld(a, 3 * j + 1) * p[1]  # p[1]: untagged, uniform
        st(o, j, iz * oz + (1.0 - lookup_scoped(p, 2, iz)) * (1.0 - lookup_scoped(p, 2, oz)))


def main():
    ll.set_option("", "-pass-remarks=loop-vectorize")
    ll.set_option("", "-pass-remarks-missed=loop-vectorize")
    ll.set_option("", "-pass-remarks-analysis=loop-vectorize")
    print(f"# LLVM host CPU {ll.get_host_cpu_name()}; numba {numba.__version__}")
    rng = np.random.default_rng(0)
    p = np.concatenate([[0.0, 1.0, 64.0], rng.uniform(size=4 * 64)])
    a, o = rng.uniform(size=3 * 1000), np.zeros(1000)
    for label, fn in (("plain", plain), ("no-index", no_index), ("scoped", scoped),
                      ("scoped+1", scoped_plus_one)):
        print(f"\n{label}: remarks (LLVM, stderr) follow", flush=True)
        sys.stderr.flush()
        fn(a, o, p)  # compiles: the remarks are printed to stderr now
        sys.stderr.flush()
        asm = "\n".join(fn.inspect_asm().values())
        counts = ", ".join(f"{k} {len(re.findall(k, asm))}"
                           for k in ("vgatherqpd", "vmulpd", "vmulsd", "ymm", "zmm"))
        print(f"{label}: {counts}", flush=True)
    os.sys.stdout.flush()


if __name__ == "__main__":
    main()
