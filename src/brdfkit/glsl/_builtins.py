"""
GLSL's built-in functions, as brdfkit evaluates them
====================================================

Every built-in a ``.brdf`` file may call, over scalarised values (:mod:`._values`), with
the definitions of the GLSL 4.60 specification, §8 (angle, exponential, common and
geometric functions), in float64:

===============================  ==========================================================
built-in                         definition used
===============================  ==========================================================
radians, degrees                 x·π/180, x·180/π
sin cos tan asin acos            libm (asin/acos: NaN outside [−1, 1], as undefined there)
atan(y_over_x), atan(y, x)       atan, atan2
pow(x, y)                        x^y; NaN for x < 0 (undefined in GLSL; GPUs compute
                                 exp2(y·log2 x))
exp log exp2 log2 sqrt           libm; exp2(x) = exp(x ln 2), log2(x) = log(x)/ln 2
inversesqrt(x)                   1/√x
abs sign floor ceil trunc round  sign ∈ {−1, 0, 1}; round: half away from zero
fract(x)                         x − floor(x)
mod(x, y)                        x − y·floor(x/y)
min max clamp(x, a, b)           min(max(x, a), b)
mix(x, y, a)                     x·(1 − a) + y·a (a bool a: select)
step(e, x)                       0 if x < e else 1
smoothstep(e0, e1, x)            t²(3 − 2t), t = clamp((x − e0)/(e1 − e0), 0, 1)
length distance dot cross        √(v·v), length(a − b), Σ aᵢbᵢ, the cross product
normalize(v)                     v/√(v·v) (NaN for the zero vector: it reaches the status)
reflect(I, N)                    I − 2(N·I)N
faceforward(N, I, Nref)          N if Nref·I < 0 else −N
===============================  ==========================================================

Vector forms are component-wise (a scalar argument broadcasts where GLSL allows it).

Public objects
--------------
- :data:`BUILTINS` — name → implementation ``f(args: list[Val]) -> Val``.
"""

from __future__ import annotations

import math

from brdfkit.glsl import _dag as D
from brdfkit.glsl import _values as V

__all__ = ["BUILTINS"]

_PI = math.pi
_LN2 = math.log(2.0)


def _c(x: float):
    return D.const(x)


def _float_args(name, args, count):
    if len(args) not in count:
        raise V.TypeProblem(f"{name} takes {' or '.join(map(str, count))} arguments; got "
                            f"{len(args)}")
    out = []
    for a in args:
        if a.base == "bool":
            raise V.TypeProblem(f"{name} does not take {a.type}")
        out.append(V.convert(a, "float"))
    return out


def _unary(name, fn):
    def impl(args):
        (a,) = _float_args(name, args, (1,))
        return V.apply(name, fn, a)
    return impl


def _binary(name, fn, tag_name=None):
    def impl(args):
        a, b = _float_args(name, args, (2,))
        return V.apply(tag_name or name, fn, a, b)
    return impl


def _op(name):
    return lambda *xs: D.op(name, *xs)


def _floor(x):
    return D.op("floor", x)


def _sign(x):
    return D.op("select", D.op("gt", x, _c(0.0)), _c(1.0),
                D.op("select", D.op("lt", x, _c(0.0)), _c(-1.0), _c(0.0)))


def _trunc(x):
    return D.op("select", D.op("lt", x, _c(0.0)), D.op("neg", _floor(D.op("neg", x))),
                _floor(x))


def _round(x):  # half away from zero (GLSL leaves the direction of .5 to the implementation)
    return D.op("select", D.op("lt", x, _c(0.0)),
                D.op("neg", _floor(D.op("add", D.op("neg", x), _c(0.5)))),
                _floor(D.op("add", x, _c(0.5))))


def _mod(x, y):
    return D.op("sub", x, D.op("mul", y, _floor(D.op("div", x, y))))


def _clamp(x, lo, hi):
    return D.op("minimum", D.op("maximum", x, lo), hi)


def _mix(x, y, a):
    return D.op("add", D.op("mul", x, D.op("sub", _c(1.0), a)), D.op("mul", y, a))


def _step(edge, x):
    return D.op("select", D.op("lt", x, edge), _c(0.0), _c(1.0))


def _smoothstep(e0, e1, x):
    t = _clamp(D.op("div", D.op("sub", x, e0), D.op("sub", e1, e0)), _c(0.0), _c(1.0))
    return D.op("mul", D.op("mul", t, t), D.op("sub", _c(3.0), D.op("mul", _c(2.0), t)))


def _ternary(name, fn):
    def impl(args):
        a, b, c = _float_args(name, args, (3,))
        return V.apply(name, fn, a, b, c)
    return impl


def _mix_impl(args):
    if len(args) == 3 and args[2].base == "bool":  # mix(x, y, bvec): select per component
        x, y = _float_args("mix", args[:2], (2,))
        a = args[2]
        if a.n not in (1, x.n):
            raise V.TypeProblem(f"mix: a {a.type} selector for {x.type}")
        comps = tuple(D.op("select", c, yy, xx) for c, xx, yy in zip(
            a.comps * (x.n if a.n == 1 else 1), x.comps, y.comps, strict=False))
        tags = x.tags & y.tags if a.tags & (V.EVEN | V.SCALARS) else V.NONE
        return V.Val("float", comps, tags, x.why or y.why or a.why)
    return _ternary("mix", _mix)(args)


def _atan(args):
    if len(args) == 1:
        return _unary("atan", _op("atan"))(args)
    y, x = _float_args("atan", args, (2,))
    return V.apply("atan2", _op("atan2"), y, x)


def _length(args):
    (a,) = _float_args("length", args, (1,))
    d = V.dot(a, a)
    return V.Val("float", (D.op("sqrt", d.comps[0]),), d.tags and V.EVEN, d.why)


def _distance(args):
    a, b = _float_args("distance", args, (2,))
    return _length([V.binary("-", a, b)])


def _dot(args):
    a, b = _float_args("dot", args, (2,))
    return V.dot(a, b)


def _cross(args):
    a, b = _float_args("cross", args, (2,))
    return V.cross(a, b)


def _normalize(args):
    (a,) = _float_args("normalize", args, (1,))
    inv = V.apply("inversesqrt", lambda d: D.op("div", _c(1.0), D.op("sqrt", d)), V.dot(a, a))
    return V.binary("*", a, inv)


def _reflect(args):
    i, n = _float_args("reflect", args, (2,))
    return V.binary("-", i, V.binary("*", V.binary("*", V.scalar(_c(2.0)), V.dot(n, i)), n))


def _faceforward(args):
    n, i, nref = _float_args("faceforward", args, (3,))
    cond = V.binary("<", V.dot(nref, i), V.scalar(_c(0.0)))
    return V.select(cond, n, V.unary("-", n))


def _exp2(x):
    return D.op("exp", D.op("mul", x, _c(_LN2)))


def _log2(x):
    return D.op("div", D.op("log", x), _c(_LN2))


def _minmax(name):
    prim = "minimum" if name == "min" else "maximum"
    return _binary(name, _op(prim), tag_name=name)


#: The built-ins, by name (module docstring).
BUILTINS = {
    "radians": _unary("radians", lambda x: D.op("mul", x, _c(_PI / 180.0))),
    "degrees": _unary("degrees", lambda x: D.op("mul", x, _c(180.0 / _PI))),
    "sin": _unary("sin", _op("sin")), "cos": _unary("cos", _op("cos")),
    "tan": _unary("tan", _op("tan")), "asin": _unary("asin", _op("asin")),
    "acos": _unary("acos", _op("acos")), "atan": _atan,
    "pow": _binary("pow", _op("power")), "exp": _unary("exp", _op("exp")),
    "log": _unary("log", _op("log")), "exp2": _unary("exp2", _exp2),
    "log2": _unary("log2", _log2), "sqrt": _unary("sqrt", _op("sqrt")),
    "inversesqrt": _unary("inversesqrt", lambda x: D.op("div", _c(1.0), D.op("sqrt", x))),
    "abs": _unary("absolute", _op("absolute")), "sign": _unary("sign", _sign),
    "floor": _unary("floor", _floor),
    "ceil": _unary("ceil", lambda x: D.op("neg", _floor(D.op("neg", x)))),
    "trunc": _unary("trunc", _trunc), "round": _unary("round", _round),
    "fract": _unary("fract", lambda x: D.op("sub", x, _floor(x))),
    "mod": _binary("mod", _mod), "min": _minmax("min"), "max": _minmax("max"),
    "clamp": _ternary("clamp", _clamp), "mix": _mix_impl, "step": _binary("step", _step),
    "smoothstep": _ternary("smoothstep", _smoothstep),
    "length": _length, "distance": _distance, "dot": _dot, "cross": _cross,
    "normalize": _normalize, "reflect": _reflect, "faceforward": _faceforward,
}
