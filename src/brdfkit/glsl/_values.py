"""
GLSL values, scalarised, and what they are under rotations and mirrors of the frame
==================================================================================

A :class:`Val` is one GLSL value of type ``float``/``int``/``bool`` or ``vecN``/
``ivecN``/``bvecN`` (N = 2…4) as a tuple of scalar graph nodes (:mod:`._dag`), with the
GLSL operators on it (component-wise, with scalar broadcast and int → float promotion).

Isotropy, detected. Each value carries *tags*, what it provably is when the tangent
frame turns about N (a rotation) or is mirrored in a plane containing N — brdfkit's
``isotropic`` needs both (:class:`~brdfkit.models.BRDF`). For a scalar: ``even``
(unchanged by both) or ``odd`` (unchanged by rotations, negated by mirrors: e.g.
N·(L × V)). For a vector: ``eq`` (turns with the frame: L, V, N and their linear
combinations with even coefficients, ``normalize``, ``reflect``), ``pseudo`` (a cross
product of two such: turns, and flips sign under a mirror) or ``scalars`` (a tuple of
even scalars, e.g. an RGB colour). No tag: frame-dependent — reading X or Y, a direction's
x or y component, a component-wise product of directions. The rules: dot(eq, eq) and
length(eq) are even, dot(eq, pseudo) odd; even × eq = eq, odd × eq = pseudo; sums keep a
tag both terms have; an even function of an even value is even; a select keeps what both
sides are, when its condition is even. Conservative: an isotropic formula written through
frame-dependent steps is reported anisotropic (and then integrated over the full azimuth:
slower, never wrong); a value tagged even is isotropic by construction. ``why`` records
the first step that made a value frame-dependent, for ``brdfkit models FILE``.

Public objects (for the translator)
-----------------------------------
- :class:`Val`, :func:`scalar`, :func:`vector`, :func:`type_of`, :func:`convert`.
- :func:`binary`, :func:`unary`, :func:`select`, :func:`apply`, :func:`dot`,
  :func:`cross`, :func:`component`, :func:`construct`.
"""

from __future__ import annotations

from dataclasses import dataclass

from brdfkit.glsl import _dag as D

__all__ = ["Val", "scalar", "vector", "type_of", "convert", "binary", "unary", "select",
           "apply", "dot", "cross", "component", "construct", "EVEN", "SCALARS", "EQ", "NONE",
           "TypeProblem"]

EVEN, ODD = frozenset({"even"}), frozenset({"odd"})
EQ, PSEUDO, SCALARS = frozenset({"eq"}), frozenset({"pseudo"}), frozenset({"scalars"})
NONE = frozenset()

_BASES = {"float": ("float", "vec"), "int": ("int", "ivec"), "bool": ("bool", "bvec")}


class TypeProblem(Exception):
    """Raised by operations on values of incompatible types; the interpreter adds where."""


@dataclass(frozen=True)
class Val:
    """A GLSL value: ``base`` ("float", "int", "bool"), ``comps`` (one node per component:
    1 for a scalar), ``tags`` (module docstring), ``why`` (why it is frame-dependent)."""

    base: str
    comps: tuple
    tags: frozenset = NONE
    why: str | None = None

    @property
    def n(self) -> int:
        return len(self.comps)

    @property
    def type(self) -> str:
        return type_of(self.base, self.n)

    @property
    def is_scalar(self) -> bool:
        return len(self.comps) == 1


def type_of(base: str, n: int) -> str:
    """The GLSL type name of *n* components of *base* (``float``, 3 → ``vec3``)."""
    scalar_name, vector_name = _BASES[base]
    return scalar_name if n == 1 else f"{vector_name}{n}"


def parse_type(name: str) -> tuple[str, int] | None:
    """(base, n) of a GLSL scalar or vector type name, or None."""
    for base, (s, v) in _BASES.items():
        if name == s:
            return base, 1
        if name.startswith(v) and name[len(v):] in ("2", "3", "4"):
            return base, int(name[len(v):])
    return None


def scalar(node, base: str = "float", tags=EVEN, why=None) -> Val:
    return Val(base, (node,), tags, why)


def vector(nodes, base: str = "float", tags=NONE, why=None) -> Val:
    return Val(base, tuple(nodes), tags, why)


_ODD_WHY = "a value that changes sign when the frame is mirrored (such as N·(L × V))"


def _why(*vals: Val, reason: str | None = None) -> str | None:
    for v in vals:
        if v.why:
            return v.why
    if any("odd" in v.tags for v in vals):
        return _ODD_WHY
    return reason


def _splat(v: Val) -> bool:
    return v.n > 1 and all(c is v.comps[0] for c in v.comps)


def convert(v: Val, base: str) -> Val:
    """*v* converted to *base* components (GLSL's constructors and implicit int → float)."""
    if v.base == base:
        return v
    if base == "bool":
        comps = tuple(D.op("ne", c, D.const(0.0)) for c in v.comps)
    elif v.base == "bool":
        comps = tuple(D.op("select", c, D.const(1.0), D.const(0.0)) for c in v.comps)
    elif base == "int":  # float → int truncates toward 0
        comps = tuple(_trunc(c) for c in v.comps)
    else:
        comps = v.comps  # int → float: the same float64 value
    return Val(base, comps, v.tags, v.why)


def _trunc(c):
    return D.op("select", D.op("lt", c, D.const(0.0)), D.op("neg", D.op("floor", D.op("neg", c))),
                D.op("floor", c))


def _promote(a: Val, b: Val) -> tuple[Val, Val]:
    if a.base == b.base:
        return a, b
    if {a.base, b.base} == {"int", "float"}:
        return convert(a, "float"), convert(b, "float")
    raise TypeProblem(f"cannot combine {a.type} and {b.type}")


def _mul_tags(a: Val, b: Val) -> frozenset:
    sa, sb = a.is_scalar or _splat(a), b.is_scalar or _splat(b)
    if sa and sb:
        ta = a.tags if a.is_scalar else (EVEN if "scalars" in a.tags else NONE)
        tb = b.tags if b.is_scalar else (EVEN if "scalars" in b.tags else NONE)
        if a.is_scalar and b.is_scalar:
            out = set()
            if ta & tb:
                out.add("even")
            if ("even" in ta and "odd" in tb) or ("odd" in ta and "even" in tb):
                out.add("odd")
            return frozenset(out)
        return SCALARS if "even" in ta and "even" in tb else NONE
    if sa or sb:  # a vector times a scalar (or a splat)
        s, v = (a, b) if sa else (b, a)
        ts = s.tags if s.is_scalar else (EVEN if "scalars" in s.tags else NONE)
        out = set()
        for t in v.tags:
            if "even" in ts:
                out.add(t)
            if "odd" in ts and t in ("eq", "pseudo"):
                out.add("pseudo" if t == "eq" else "eq")
        return frozenset(out)
    return SCALARS if "scalars" in a.tags and "scalars" in b.tags else NONE


def _broadcast(a: Val, b: Val) -> tuple[tuple, tuple]:
    if a.n == b.n:
        return a.comps, b.comps
    if a.n == 1:
        return a.comps * b.n, b.comps
    if b.n == 1:
        return a.comps, b.comps * a.n
    raise TypeProblem(f"cannot combine {a.type} and {b.type} (sizes differ)")


_OPS = {"+": "add", "-": "sub", "*": "mul", "/": "div", "<": "lt", "<=": "le", ">": "gt",
        ">=": "ge", "==": "eq", "!=": "ne", "&&": "and", "||": "or", "^^": "ne"}


def binary(symbol: str, a: Val, b: Val) -> Val:
    """``a symbol b`` with GLSL's rules (broadcast, promotion, integer division)."""
    name = _OPS.get(symbol)
    if name is None:
        raise TypeProblem(f"operator {symbol!r} is not supported")
    if name in ("and", "or") or symbol == "^^":
        if a.base != "bool" or b.base != "bool" or not (a.is_scalar and b.is_scalar):
            raise TypeProblem(f"{symbol} needs two bool scalars; got {a.type} and {b.type}")
        tags = EVEN if "even" in a.tags and "even" in b.tags else NONE
        return scalar(D.op(name, a.comps[0], b.comps[0]), "bool", tags,
                      _why(a, b) if not tags else None)
    if a.base == "bool" or b.base == "bool":
        if name not in ("eq", "ne") or a.type != b.type:
            raise TypeProblem(f"operator {symbol!r} does not apply to {a.type} and {b.type}")
    else:
        a, b = _promote(a, b)
    if name in ("lt", "le", "gt", "ge"):
        if not (a.is_scalar and b.is_scalar):
            raise TypeProblem(f"{symbol} compares scalars; got {a.type} and {b.type} "
                              "(use lessThan and friends)")
        tags = EVEN if "even" in a.tags and "even" in b.tags else NONE
        return scalar(D.op(name, a.comps[0], b.comps[0]), "bool", tags,
                      _why(a, b, reason="a comparison of values that depend on the frame")
                      if not tags else None)
    if name in ("eq", "ne"):  # vectors: all components equal (a bool scalar)
        if a.type != b.type:
            raise TypeProblem(f"{symbol} needs operands of one type; got {a.type}, {b.type}")
        out = D.const(True)
        for x, y in zip(a.comps, b.comps, strict=False):
            out = D.op("and", out, D.op("eq", x, y))
        if name == "ne":
            out = D.op("not", out)
        ok = a.tags & b.tags & (EVEN | SCALARS)
        return scalar(out, "bool", EVEN if ok else NONE, None if ok else _why(a, b))
    ca, cb = _broadcast(a, b)
    if name in ("add", "sub"):
        tags = a.tags & b.tags if a.n == b.n else (
            SCALARS if "even" in (a.tags | b.tags) and "scalars" in (a.tags | b.tags) else NONE)
        comps = tuple(D.op(name, x, y) for x, y in zip(ca, cb, strict=False))
    else:
        tags = _mul_tags(a, b) if name == "mul" else _div_tags(a, b)
        if name == "div" and a.base == "int":  # integer division truncates toward 0
            comps = tuple(_trunc(D.op("div", x, y)) for x, y in zip(ca, cb, strict=False))
        else:
            comps = tuple(D.op(name, x, y) for x, y in zip(ca, cb, strict=False))
    why = None if tags else _why(a, b, reason=f"a component-wise {symbol} of directions")
    return Val(a.base, comps, tags, why)


def _div_tags(a: Val, b: Val) -> frozenset:
    if b.is_scalar or _splat(b):
        return _mul_tags(a, b)  # 1/s is even/odd as s is
    return SCALARS if "scalars" in a.tags and "scalars" in b.tags else NONE


def unary(symbol: str, a: Val) -> Val:
    """``-a``, ``+a`` or ``!a``."""
    if symbol == "+":
        return a
    if symbol == "-":
        if a.base == "bool":
            raise TypeProblem(f"unary - does not apply to {a.type}")
        return Val(a.base, tuple(D.op("neg", c) for c in a.comps), a.tags, a.why)
    if symbol == "!":
        if a.type != "bool":
            raise TypeProblem(f"! needs a bool; got {a.type}")
        return scalar(D.op("not", a.comps[0]), "bool", a.tags, a.why)
    raise TypeProblem(f"unary operator {symbol!r} is not supported")


def select(c: Val, a: Val, b: Val) -> Val:
    """``c ? a : b`` (both evaluated), component-wise; *c* a bool scalar."""
    if c.type != "bool":
        raise TypeProblem(f"a condition must be a bool; got {c.type}")
    if c.comps[0].is_const and a.type == b.type:  # a constant choice: that side, as it is
        return a if D.value_of(c.comps[0]) else b
    if a.type != b.type:
        if {a.base, b.base} == {"int", "float"} and a.n == b.n:
            a, b = _promote(a, b)
        else:
            raise TypeProblem(f"both sides of ?: must have one type; got {a.type} and {b.type}")
    tags = a.tags & b.tags if "even" in c.tags else NONE
    comps = tuple(D.op("select", c.comps[0], x, y) for x, y in zip(a.comps, b.comps, strict=False))
    why = None if tags else _why(c, a, b, reason="a choice made on a frame-dependent value")
    return Val(a.base, comps, tags, why)


#: functions of one argument that are odd (f(−x) = −f(x)) or even (f(−x) = f(x))
_ODD = {"sin", "tan", "asin", "atan", "sign"}
_EVEN = {"absolute", "cos"}


def apply(name: str, fn, *args: Val) -> Val:
    """The component-wise function *fn* (scalar nodes → node) of *args* (broadcast to the
    widest), named *name* for the tag rules."""
    n = max(a.n for a in args)
    cols = []
    for a in args:
        if a.n not in (1, n):
            raise TypeProblem(f"{name}: arguments of sizes {', '.join(x.type for x in args)}")
        cols.append(a.comps * n if a.n == 1 else a.comps)
    comps = tuple(fn(*xs) for xs in zip(*cols, strict=False))
    if n == 1:
        if all("even" in a.tags for a in args):
            tags = EVEN
        elif len(args) == 1 and "odd" in args[0].tags:
            tags = ODD if name in _ODD else EVEN if name in _EVEN else NONE
        else:
            tags = NONE
    else:
        ok = all(("scalars" in a.tags) if a.n > 1 else ("even" in a.tags) for a in args)
        tags = SCALARS if ok else NONE
    base = "float" if any(a.base == "float" for a in args) else args[0].base
    why = None if tags else _why(*args, reason=f"{name} of a frame-dependent value")
    return Val(base, comps, tags, why)


def dot(a: Val, b: Val) -> Val:
    """dot(a, b), a scalar: even for two directions or two pseudo-vectors, odd for one of
    each, even for two tuples of even scalars."""
    if a.n != b.n:
        raise TypeProblem(f"dot of {a.type} and {b.type}")
    a, b = _promote(a, b)
    out = None
    for x, y in zip(a.comps, b.comps, strict=False):
        term = D.op("mul", x, y)
        out = term if out is None else D.op("add", out, term)
    tags = set()
    if ("eq" in a.tags and "eq" in b.tags) or ("pseudo" in a.tags and "pseudo" in b.tags) \
            or ("scalars" in a.tags and "scalars" in b.tags) or (
            a.is_scalar and "even" in a.tags and "even" in b.tags):
        tags.add("even")
    if ("eq" in a.tags and "pseudo" in b.tags) or ("pseudo" in a.tags and "eq" in b.tags):
        tags.add("odd")
    tags = frozenset(tags)
    return scalar(out, "float", tags,
                  None if tags else _why(a, b, reason="a dot product with a frame-dependent "
                                                      "vector"))


def cross(a: Val, b: Val) -> Val:
    """cross(a, b) of two vec3: pseudo for two directions (a mirror flips it)."""
    if a.type != "vec3" or b.type != "vec3":
        raise TypeProblem(f"cross needs two vec3; got {a.type} and {b.type}")
    (ax, ay, az), (bx, by, bz) = a.comps, b.comps

    def d(p, q, r, s):
        return D.op("sub", D.op("mul", p, q), D.op("mul", r, s))

    comps = (d(ay, bz, az, by), d(az, bx, ax, bz), d(ax, by, ay, bx))
    table = {("eq", "eq"): "pseudo", ("eq", "pseudo"): "eq", ("pseudo", "eq"): "eq",
             ("pseudo", "pseudo"): "pseudo", ("scalars", "scalars"): "scalars"}
    tags = frozenset(table[(x, y)] for x in a.tags for y in b.tags if (x, y) in table)
    return vector(comps, "float", tags, None if tags else _why(a, b, reason="a cross product "
                                                                          "with a frame-"
                                                                          "dependent vector"))


_LETTERS = ("xyzw", "rgba", "stpq")


def component_indices(field: str, n: int) -> tuple[int, ...]:
    """The component indices of a swizzle *field* of an *n*-vector (``xzy`` → 0, 2, 1)."""
    for letters in _LETTERS:
        if all(ch in letters for ch in field):
            idx = tuple(letters.index(ch) for ch in field)
            if max(idx) >= n or not 1 <= len(idx) <= 4:
                break
            return idx
    raise TypeProblem(f"no component {field!r} in a vector of {n} components")


def component(v: Val, idx: tuple[int, ...], what: str) -> Val:
    """The components *idx* of *v* (a swizzle or an index), with their tags: the z (N)
    component of a direction is even (odd of a pseudo-vector), x and y depend on the frame."""
    comps = tuple(v.comps[i] for i in idx)
    if "scalars" in v.tags:
        tags = EVEN if len(idx) == 1 else SCALARS
    elif idx == tuple(range(v.n)):
        tags = v.tags  # the identity swizzle
    elif len(idx) == 1 and idx[0] == 2 and v.n == 3 and v.tags & (EQ | PSEUDO):
        tags = EVEN if "eq" in v.tags else ODD
    elif all(c.is_const for c in comps):
        tags = EVEN if len(idx) == 1 else SCALARS
    else:
        tags = NONE
    why = None if tags else _why(v, reason=f"{what} of a direction")
    return Val(v.base, comps, tags, why)


def construct(base: str, n: int, args: list[Val]) -> Val:
    """The constructor ``vecN(args)`` / ``float(x)`` … (GLSL's rules: one scalar fills
    every component; else the components of the arguments in order, as many as needed)."""
    args = [convert(a, base) for a in args]
    if len(args) == 1 and args[0].is_scalar:
        a = args[0]
        tags = (SCALARS if n > 1 else EVEN) if "even" in a.tags else (a.tags if n == 1
                                                                        else NONE)
        why = a.why if a.why or tags else _ODD_WHY
        return Val(base, a.comps * n, tags, why)
    comps = [c for a in args for c in a.comps]
    if len(comps) < n:
        raise TypeProblem(f"{type_of(base, n)} needs {n} components; got {len(comps)}")
    if len(args) == 1 and args[0].n >= n:  # vec3(v4): the first n components
        return component(args[0], tuple(range(n)), f"{type_of(base, n)}()")
    comps = tuple(comps[:n])
    if all("even" in a.tags or "scalars" in a.tags for a in args):
        tags = SCALARS if n > 1 else EVEN
    else:
        tags = NONE
    if n == 3 and comps[0].is_const and comps[1].is_const and D.value_of(comps[0]) == 0.0 \
            and D.value_of(comps[1]) == 0.0 and len(args) == 3 and "even" in args[2].tags:
        tags = tags | EQ  # (0, 0, c) = c·N: a direction as well
    why = None if tags else _why(*args, reason=f"{type_of(base, n)}() of frame-dependent parts")
    return Val(base, comps, tags, why)
