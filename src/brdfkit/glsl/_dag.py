"""
Scalar expression graphs: the translator's intermediate form, folded and emitted
================================================================================

The interpreter (:mod:`brdfkit.glsl._interp`) scalarises a shader into a graph of
:class:`Node` values — inputs (the direction components), packed parameters, constants
and operations — interned so that a sub-expression computed twice is one node (common
sub-expressions for free, and identity is equality). Operations on constants are folded
here, in float64, with GLSL's meaning; :func:`emit` writes the graph reachable from the
outputs as the straight-line body of a formula (:mod:`brdfkit._dual`): one assignment per
node, in dependency order.

Values are floats (GLSL's ``int`` values too: float64 holds every int a shader uses
exactly, and the operations that differ — integer division, ``int()`` — are written with
``trunc``) or booleans (``kind`` ``"b"``: comparisons, ``&&``, bool uniforms).

Algebraic simplifications, as a GPU compiler makes them: x·0 = 0, x·1 = x, x + 0 = x,
x − 0 = x, x/1 = x, select on a constant condition, select(c, a, a) = a. They drop a NaN
only where it is multiplied by a literal 0 (e.g. the frame's zero components in
``dot(N, v)``), never one that reaches the value otherwise.

Public objects (for the translator)
-----------------------------------
- :class:`Node`, :func:`const`, :func:`leaf`, :func:`op` — build the graph (inside
  :func:`graph`, one interning table per translation).
- :func:`emit` — the graph as Python statements.
"""

from __future__ import annotations

import contextlib
import contextvars
import math

__all__ = ["Node", "const", "leaf", "op", "emit", "graph", "FLOAT", "BOOL"]

FLOAT, BOOL = "f", "b"

#: operation → (result kind, Python emission template, constant folding or None)
_ARITH = {"add": "({0} + {1})", "sub": "({0} - {1})", "mul": "({0} * {1})",
          "div": "({0} / {1})", "neg": "(-{0})"}
_COMPARE = {"lt": "<", "le": "<=", "gt": ">", "ge": ">=", "eq": "==", "ne": "!="}
#: calls of primitives of brdfkit._dual (name in the formula = name here)
CALLS = {"sqrt": 1, "exp": 1, "log": 1, "sin": 1, "cos": 1, "tan": 1, "asin": 1, "acos": 1,
         "atan": 1, "atan2": 2, "power": 2, "floor": 1, "absolute": 1, "minimum": 2,
         "maximum": 2}


class Node:
    """One scalar of the graph: ``kind`` (FLOAT or BOOL), ``op``, ``args`` (Nodes) and
    ``value`` (a constant's value, an input's name, a parameter's index). Built only through
    :func:`const`, :func:`leaf` and :func:`op`, which intern them."""

    __slots__ = ("kind", "op", "args", "value", "__weakref__")

    def __init__(self, kind, op_, args, value):
        self.kind, self.op, self.args, self.value = kind, op_, args, value

    @property
    def is_const(self) -> bool:
        return self.op == "const"

    def __repr__(self):
        if self.op in ("const", "in", "p"):
            return f"{self.op}({self.value!r})"
        return f"{self.op}({', '.join(map(repr, self.args))})"


#: The interning table of the translation in progress (a context variable: translations in
#: two threads, e.g. the explorer reloading two files, never share one); :func:`graph`
#: gives each translation its own.
_TABLE: contextvars.ContextVar = contextvars.ContextVar("brdfkit.glsl._dag._TABLE")


@contextlib.contextmanager
def graph():
    """A fresh interning table for the nodes built inside the ``with`` block (one
    translation); the nodes outlive it, the table does not."""
    token = _TABLE.set({})
    try:
        yield
    finally:
        _TABLE.reset(token)


def _intern(kind, op_, args, value):
    table = _TABLE.get(None)
    if table is None:
        raise RuntimeError("brdfkit.glsl._dag: nodes are built inside `with graph():`")
    key = (kind, op_, tuple(id(a) for a in args), value)
    node = table.get(key)
    if node is None:
        node = Node(kind, op_, tuple(args), value)
        table[key] = (node, args)  # args kept alive: their ids stay theirs
        return node
    return node[0]


def const(value) -> Node:
    """A constant: a Python bool, or a number (as float64; -0.0 kept)."""
    if isinstance(value, bool):
        return _intern(BOOL, "const", (), value)
    v = float(value)
    return _intern(FLOAT, "const", (), ("nan",) if math.isnan(v) else (v, math.copysign(1, v)))


def value_of(node: Node):
    """A constant node's Python value."""
    v = node.value
    if node.kind == BOOL:
        return v
    return math.nan if v == ("nan",) else v[0]


def leaf(kind: str, what: str, value) -> Node:
    """An input (``what`` "in", value the component's name) or a packed parameter
    (``what`` "p", value its index)."""
    return _intern(kind, what, (), value)


def _fold(name, vals):
    """The value of *name* on constant arguments, with GLSL's (IEEE float64) meaning."""
    a = vals[0]
    b = vals[1] if len(vals) > 1 else None
    try:
        if name == "add":
            return a + b
        if name == "sub":
            return a - b
        if name == "mul":
            return a * b
        if name == "div":
            if b == 0.0:
                return math.nan if a == 0.0 or math.isnan(a) else math.copysign(
                    math.inf, a) * math.copysign(1.0, b)
            return a / b
        if name == "neg":
            return -a
        if name == "power":
            if a < 0.0:
                return math.nan  # undefined in GLSL (GPUs compute exp2(y log2 x): NaN)
            return math.pow(a, b) if not (a == 0.0 and b < 0.0) else math.inf
        if name == "atan2":
            return math.atan2(a, b)
        if name in ("minimum", "maximum"):
            return min(a, b) if name == "minimum" else max(a, b)
        if name == "absolute":
            return abs(a)
        if name == "floor":
            return float(math.floor(a)) if math.isfinite(a) else a
        return getattr(math, name)(a)
    except (ValueError, OverflowError):  # outside the domain: the GPU's NaN / inf
        return math.nan if name != "exp" else math.inf


def _zero(n: Node) -> bool:
    return n.is_const and n.kind == FLOAT and value_of(n) == 0.0


def _one(n: Node) -> bool:
    return n.is_const and n.kind == FLOAT and value_of(n) == 1.0


def op(name: str, *args: Node) -> Node:
    """The node ``name(args)``, folded when every argument is constant, simplified
    (module docstring) and interned."""
    if name == "select":
        c, a, b = args
        if c.is_const:
            return a if value_of(c) else b
        if a is b:
            return a
        return _intern(a.kind, "select", args, None)
    if all(a.is_const for a in args):
        vals = [value_of(a) for a in args]
        if name in _COMPARE:
            return const(_compare(name, *vals))
        if name in ("and", "or", "not"):
            return const(vals[0] and vals[1] if name == "and" else
                         vals[0] or vals[1] if name == "or" else not vals[0])
        return const(_fold(name, vals))
    if name in _COMPARE:
        return _intern(BOOL, name, args, None)
    if name in ("and", "or"):
        a, b = args
        for x, y in ((a, b), (b, a)):
            if x.is_const:  # true && y = y, false && y = false; false || y = y, true || y = true
                return y if value_of(x) == (name == "and") else x
        return _intern(BOOL, name, args, None)
    if name == "not":
        return _intern(BOOL, "not", args, None)
    if name == "mul":
        a, b = args
        if _zero(a) or _zero(b):
            return const(0.0)
        if _one(a):
            return b
        if _one(b):
            return a
    elif name == "add":
        a, b = args
        if _zero(a):
            return b
        if _zero(b):
            return a
    elif name == "sub":
        a, b = args
        if _zero(b):
            return a
        if _zero(a):
            return op("neg", b)
    elif name == "div" and _one(args[1]):
        return args[0]
    return _intern(FLOAT, name, args, None)


def _compare(name, a, b) -> bool:
    return {"lt": a < b, "le": a <= b, "gt": a > b, "ge": a >= b, "eq": a == b,
            "ne": a != b}[name]


def _literal(n: Node) -> str:
    v = value_of(n)
    if n.kind == BOOL:
        return repr(bool(v))
    if math.isnan(v):
        return "_NAN"
    if math.isinf(v):
        return "_INF" if v > 0 else "(-_INF)"
    return repr(float(v))


def emit(outputs: list[Node], *, param_name: str = "p") -> tuple[list[str], list[str]]:
    """(statements, expressions): the assignments computing every node reachable from
    *outputs*, in dependency order, and one expression per output. Inputs are their names,
    parameters ``u{k}`` (read once from *param_name*), constants literals (``_NAN``,
    ``_INF`` for the non-finite ones: module constants of the generated code)."""
    names: dict[int, str] = {}
    lines: list[str] = []
    params: dict[int, str] = {}

    def name_of(root: Node) -> str:
        # iterative post-order: a Disney-sized shader's graph is deeper than Python's stack
        stack = [(root, False)]
        while stack:
            n, ready = stack.pop()
            if id(n) in names:
                continue
            if n.op == "const":
                names[id(n)] = _literal(n)
            elif n.op == "in":
                names[id(n)] = n.value
            elif n.op == "p":
                k = int(n.value)
                if k not in params:
                    params[k] = f"u{k}"
                    lines.append(f"u{k} = {param_name}[{k}]")
                names[id(n)] = params[k]
            elif not ready:
                stack.append((n, True))
                stack.extend((a, False) for a in reversed(n.args) if id(a) not in names)
            else:
                a = [names[id(x)] for x in n.args]
                if n.op in _ARITH:
                    expr = _ARITH[n.op].format(*a)
                elif n.op in _COMPARE:
                    expr = f"({a[0]} {_COMPARE[n.op]} {a[1]})"
                elif n.op in ("and", "or"):
                    expr = f"({a[0]} {'&' if n.op == 'and' else '|'} {a[1]})"
                elif n.op == "not":
                    expr = f"select({a[0]}, False, True)"
                elif n.op == "select":
                    expr = f"select({a[0]}, {a[1]}, {a[2]})"
                else:
                    expr = f"{n.op}({', '.join(a)})"
                t = f"t{len(names)}"
                lines.append(f"{t} = {expr}")
                names[id(n)] = t
        return names[id(root)]

    exprs = [name_of(o) for o in outputs]
    return lines, exprs
