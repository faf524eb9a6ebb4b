"""Scalar building blocks for the compiled model kernels.

Kernels receive the components of wi = (ix, iy, iz) and wo = (ox, oy, oz) in
the local frame (n = +z). These inlined helpers name the dot products the
papers use, so that kernels read like the equations: N·L is ``iz``, N·V is
``oz``, R·V is :func:`r_dot_v`, N·H is :func:`n_dot_h`. :func:`half` and
:func:`n_dot_h` stay exact when the components of L + V are so small that their
squares underflow (both directions within ~1e-154 of the horizon):
:data:`SMALL_LENGTH`, :func:`scaled_length`.

Vectorisable building blocks
----------------------------
Numba's ``prange`` loops are vectorised by LLVM (4 float64 lanes with AVX2)
only when the inlined kernel is one basic block: selects instead of
branches, no libm call (without Intel's SVML, which this Numba does not use,
``math.exp`` stays a scalar call per lane) and no load from an address that
depends on a lane's data unless that address is in bounds for *any* input
(NaN and inf included: the driver computes every lane and selects).
:func:`exp_nonpos` is ``exp`` for x ≤ 0 written that way (< 1 ulp measured
against ``math.exp``); :func:`bits_to_float` builds 2^k from its bits.

A load at a data-dependent index (a table a kernel reads, e.g. a compensation's Ẽ(μ)) is
vectorised with gathers only when LLVM knows the loop's store does not overlap it: Numba
gives array arguments no ``noalias``, and LLVM cannot build the run-time overlap check for
a non-affine index ("loop not vectorized: cannot identify array bounds";
``benchmarks/probe_vectorise_lookup.py``). :func:`load_input` (every read of the "vector"
loop's inputs: directions, packed rows, tables) and :func:`store_output` (its one store)
say so with LLVM's scoped-noalias metadata. Alias sets merge transitively, so *every* load
in such a loop must be a :func:`load_input` (:func:`load_inputs` reads a kernel's
parameters as a tuple) for a gather to vectorise; an ordinary load only costs the
run-time check, as before.
"""

from __future__ import annotations

import math

import numba
from llvmlite import ir
from numba.core import cgutils, types
from numba.extending import intrinsic

INV_PI = 1.0 / math.pi
INV_TWO_PI = 1.0 / (2.0 * math.pi)
_jit = numba.njit(cache=True, inline="always")


@_jit
def below_horizon(iz: float, oz: float) -> bool:
    """True when either direction is at or below the horizon (the BRDF is 0 there)."""
    return iz <= 0.0 or oz <= 0.0


@_jit
def dot3(ax, ay, az, bx, by, bz) -> float:
    return ax * bx + ay * by + az * bz


@_jit
def r_dot_v(ix, iy, iz, ox, oy, oz) -> float:
    """R·V with R = 2N(N·L) − L the mirror of L: 2(N·L)(N·V) − L·V (symmetric in L, V)."""
    return 2.0 * iz * oz - (ix * ox + iy * oy + iz * oz)


# |L + V| is computed from squared components; when all of them are below ~1e-154 the squares
# underflow (both directions within ~1e-154 of the horizon and nearly opposite), the sum is
# 0 or subnormal and H = s/|s| would be 0/0, inf or inaccurate. Below this length the
# components are first scaled by the largest one (exact: a division by a positive number),
# which costs one compare on the common path. 1e-140: a component whose square underflows
# (< 2.3e-308) then changes |s|² ≥ 1e-280 by < 1e-27 relative.
SMALL_LENGTH = 1e-140


@_jit
def scaled_length(x, y, z) -> float:
    """√(x² + y² + z²) without underflow: the slow path for lengths below SMALL_LENGTH."""
    m = max(abs(x), abs(y), abs(z))
    if m == 0.0:
        return 0.0
    a, b, c = x / m, y / m, z / m
    return m * math.sqrt(a * a + b * b + c * c)


@_jit
def half(ix, iy, iz, ox, oy, oz):
    """Unit half vector H = (L + V)/|L + V| and |L + V|.

    Returns (hx, hy, hz, length). When L = −V the bisector is undefined;
    the normal is returned with length 0 so that callers can treat it.
    Above the horizon L + V has z-component N·L + N·V > 0, so H is defined;
    it is computed without underflow also when every component of L + V is
    subnormal (see SMALL_LENGTH), where H may still be far from the normal.
    """
    hx = ix + ox
    hy = iy + oy
    hz = iz + oz
    length = math.sqrt(hx * hx + hy * hy + hz * hz)
    if length < SMALL_LENGTH:
        length = scaled_length(hx, hy, hz)  # rare: squares underflowed
        if length == 0.0:
            return 0.0, 0.0, 1.0, 0.0
        # divide by the largest component first: length/m ≥ 1 is normal, so no 1/length
        # overflow or subnormal quotient
        m = max(abs(hx), abs(hy), abs(hz))
        r = length / m
        return (hx / m) / r, (hy / m) / r, (hz / m) / r, length
    return hx / length, hy / length, hz / length, length


@_jit
def n_dot_h(ix, iy, iz, ox, oy, oz) -> float:
    """N·H = (N·L + N·V)/|L + V| (without underflow; see :func:`half`)."""
    s = iz + oz
    hx = ix + ox
    hy = iy + oy
    length = math.sqrt(hx * hx + hy * hy + s * s)
    if length < SMALL_LENGTH:
        m = max(abs(hx), abs(hy), abs(s))  # rare: squares underflowed; scale first
        if m == 0.0:
            return 0.0
        a, b, c = hx / m, hy / m, s / m
        return c / math.sqrt(a * a + b * b + c * c)
    return s / length


@_jit
def pos(x: float) -> float:
    """max(0, x) — the clamp every lobe applies outside its support."""
    return x if x > 0.0 else 0.0


@_jit
def pos_pow(x: float, n: float) -> float:
    """max(0, x)ⁿ with 0⁰ = 1 (so n = 0 is a constant lobe, as Lewis §7 uses)."""
    if x <= 0.0:
        return 1.0 if n == 0.0 else 0.0
    return x**n


# --------------------------------------------------------------------------- no-alias accesses
def _input_scope(module):
    """The metadata list of the one scope "inputs of a pair loop" (uniqued by content, so
    the same node in every module Numba links)."""
    domain = module.add_metadata(["brdfkit pair loop"])
    return module.add_metadata([module.add_metadata(["brdfkit pair loop inputs", domain])])


def _element_pointer(context, builder, arr_type, arr, index):
    """Address of element *index* (an intp) of the 1-D array *arr* (its stride honoured)."""
    ary = context.make_array(arr_type)(context, builder, arr)
    return cgutils.get_item_pointer(context, builder, arr_type, ary, [index], wraparound=False)


@intrinsic
def load_input(typingctx, arr, index):
    """``arr[index]`` of a 1-D array, tagged as an input of the pair loop
    (``!alias.scope``): no wraparound of negative indices and no bounds check — callers
    pass an index in bounds (0 ≤ index < len), as the kernels' totality requires."""
    if not (isinstance(arr, types.Array) and arr.ndim == 1 and isinstance(index, types.Integer)):
        return None
    sig = arr.dtype(arr, types.intp)

    def codegen(context, builder, signature, args):
        value = builder.load(_element_pointer(context, builder, signature.args[0], *args))
        value.set_metadata("alias.scope", _input_scope(builder.module))
        return value

    return sig, codegen


@intrinsic
def store_output(typingctx, arr, index, value):
    """``arr[index] = value`` declared not to alias any :func:`load_input` (``!noalias``):
    the loop's output is never one of its inputs (``BRDF.eval`` allocates it)."""
    if not (isinstance(arr, types.Array) and arr.ndim == 1 and isinstance(index, types.Integer)):
        return None
    sig = types.void(arr, types.intp, arr.dtype)

    def codegen(context, builder, signature, args):
        ptr = _element_pointer(context, builder, signature.args[0], args[0], args[1])
        store = builder.store(args[2], ptr)
        store.set_metadata("noalias", _input_scope(builder.module))
        return context.get_dummy_value()

    return sig, codegen


@intrinsic
def load_inputs(typingctx, arr, n):
    """``(arr[0], …, arr[n − 1])`` as a tuple, each a :func:`load_input`; *n* a compile-time
    constant (a base kernel's parameter count), so that a kernel reading its parameters
    ``p[CONST]`` reads them from the tuple instead of memory."""
    if not (isinstance(arr, types.Array) and arr.ndim == 1
            and isinstance(n, types.IntegerLiteral)):
        return None
    count = n.literal_value
    tup = types.UniTuple(arr.dtype, count)

    def codegen(context, builder, signature, args):
        scope = _input_scope(builder.module)
        out = context.get_constant_undef(tup)
        for i in range(count):
            ptr = _element_pointer(context, builder, signature.args[0], args[0],
                                   context.get_constant(types.intp, i))
            value = builder.load(ptr)
            value.set_metadata("alias.scope", scope)
            out = builder.insert_value(out, value, i)
        return out

    return tup(arr, n), codegen


@intrinsic
def clamp_unit(typingctx, x):
    """*x* clamped to [0, 1], NaN to 0: two LLVM selects in one basic block. The
    if-statement clamps of a lookup compiled to branches (merged by jump threading into a
    three-way phi that stays a branch), which kept its loop from vectorising."""
    if not isinstance(x, types.Float):
        return None
    sig = types.float64(types.float64)

    def codegen(context, builder, signature, args):
        zero, one = ir.Constant(ir.DoubleType(), 0.0), ir.Constant(ir.DoubleType(), 1.0)
        low = builder.select(builder.fcmp_ordered(">=", args[0], zero), args[0], zero)
        return builder.select(builder.fcmp_ordered("<", low, one), low, one)

    return sig, codegen


# --------------------------------------------------------------------------- vectorisable exp
@intrinsic
def bits_to_float(typingctx, bits):
    """The float64 whose IEEE-754 bit pattern is the int64 *bits* (an LLVM bitcast)."""
    sig = types.float64(types.int64)

    def codegen(context, builder, signature, args):
        return builder.bitcast(args[0], ir.DoubleType())

    return sig, codegen


LOG2E = 1.4426950408889634
LN2_HI = 6.93147180369123816490e-01  # ln 2 split for Cody-Waite reduction: k·LN2_HI is exact
LN2_LO = 1.90821492927058770002e-10  # for |k| < 2^11
# Taylor coefficients 1/j!, j = 0…13: on |r| ≤ ln2/2 the remainder is
# (ln2/2)^14/14! < 3e-18, below half an ulp of e^r ≥ 0.7.
_EXP_C = tuple(1.0 / math.factorial(j) for j in range(14))
# Below this exp(x) is 0 in float64 (e^{−745.2} < 2^{−1075}); inputs are clamped here so that
# the two scale factors 2^{k/2} stay normal (k ≥ −1097).
EXP_FLOOR = -760.0


@_jit
def exp_nonpos(x: float) -> float:
    """e^x for x ≤ 0 (NaN and x > 0 are not supported; −inf and x < −745.2 give 0).

    Branch-free, so LLVM vectorises the loop it is inlined into: x = k ln2 + r,
    |r| ≤ ln2/2, e^r by its Taylor polynomial of degree 13 (Horner), times 2^k
    built from its bits in two halves (k < −1022 gives a subnormal or 0
    result, rounded once, like libm). Measured relative error against
    ``math.exp`` on [−708, 0]: ≤ 2.3e-16 (test_fast_kernels).
    """
    x = x if x > EXP_FLOOR else EXP_FLOOR  # clamp: see EXP_FLOOR (also maps −inf to it)
    k = math.floor(x * LOG2E + 0.5)
    r = (x - k * LN2_HI) - k * LN2_LO
    c = _EXP_C
    q = c[13]
    q = q * r + c[12]
    q = q * r + c[11]
    q = q * r + c[10]
    q = q * r + c[9]
    q = q * r + c[8]
    q = q * r + c[7]
    q = q * r + c[6]
    q = q * r + c[5]
    q = q * r + c[4]
    q = q * r + c[3]
    q = q * r + c[2]
    q = q * r + c[1]
    q = q * r + c[0]
    ki = numba.int64(k)
    k1 = ki >> 1
    k2 = ki - k1
    return q * bits_to_float((k1 + 1023) << 52) * bits_to_float((k2 + 1023) << 52)
