"""
The GLSL interpreter's expressions: values, calls, components and assignments
============================================================================

The expression half of :class:`brdfkit.glsl._interp._Interpreter` (a mixin: the
statements, scopes and calls are there): every expression kind of tree-sitter's GLSL
grammar the translator takes, evaluated to a :class:`~brdfkit.glsl._values.Val`;
assignments (``=``, ``+=`` …, to a variable, a swizzle or a constant index) and
``++``/``--`` go through the interpreter's ``assign``, which predicates them.

Public objects (for :mod:`._interp`)
------------------------------------
- :class:`Expressions` — the mixin.
- :func:`number` — a numeric literal's value (int or float, as GLSL types it).
"""

from __future__ import annotations

from brdfkit.glsl import _dag as D
from brdfkit.glsl import _values as V
from brdfkit.glsl._syntax import UNSUPPORTED_CALLS, UNSUPPORTED_NODES, Failure, named, text

__all__ = ["Expressions", "number"]


class Expressions:
    """Expression evaluation (mixed into the interpreter, which provides ``lookup``,
    ``assign``, ``call_named``, ``functions`` and ``_condition``)."""

    def expr(self, node) -> V.Val:
        """The value of the expression *node*; a frame-dependence reason that has no place
        yet gets this expression's (``why @row:col``)."""
        v = self._expr(node)
        if v.why and " @" not in v.why:
            v = V.Val(v.base, v.comps, v.tags, f"{v.why} @{node.start_point[0]}:"
                                               f"{node.start_point[1]}")
        return v

    def _expr(self, node) -> V.Val:  # noqa: C901 - one dispatch over the expression kinds
        t = node.type
        try:
            if t == "number_literal":
                return number(node)
            if t in ("true", "false"):
                return V.scalar(D.const(t == "true"), "bool")
            if t == "identifier":
                return self.lookup(text(node), node).val
            if t == "parenthesized_expression":
                kids = named(node)
                return self.expr(kids[-1])
            if t == "comma_expression":
                kids = named(node)
                for k in kids[:-1]:
                    self.expr(k)
                return self.expr(kids[-1])
            if t == "binary_expression":
                op = text(node.child_by_field_name("operator"))
                a = self.expr(node.child_by_field_name("left"))
                b = self.expr(node.child_by_field_name("right"))
                if op in ("&", "|", "^", "<<", ">>", "%"):
                    raise Failure(node, f"the operator {op!r} is not supported")
                return V.binary(op, a, b)
            if t == "unary_expression":
                op = text(node.child_by_field_name("operator"))
                if op == "~":
                    raise Failure(node, "the operator '~' is not supported")
                return V.unary(op, self.expr(node.child_by_field_name("argument")))
            if t == "conditional_expression":
                c = self._condition(node.child_by_field_name("condition"))
                a = self.expr(node.child_by_field_name("consequence"))
                b = self.expr(node.child_by_field_name("alternative"))
                return V.select(c, a, b)
            if t == "call_expression":
                fn = node.child_by_field_name("function")
                if fn.type not in ("identifier", "type_identifier", "primitive_type"):
                    raise Failure(fn, f"a call of {fn.type.replace('_', ' ')} is not supported")
                name = text(fn)
                if name not in self.functions and (name.startswith(("texture", "sampler"))
                                                   or name in UNSUPPORTED_CALLS):
                    raise Failure(node, f"{name}() is not supported (textures and derivatives)")
                args = [self.expr(a) for a in named(node.child_by_field_name("arguments"))]
                return self.callnamed(name, args, node)
            if t == "field_expression":
                v = self.expr(node.child_by_field_name("argument"))
                fld = text(node.child_by_field_name("field"))
                if fld == "length":
                    raise Failure(node, ".length() of arrays is not supported")
                return V.component(v, V.component_indices(fld, v.n), f"the component .{fld}")
            if t == "subscript_expression":
                v = self.expr(node.child_by_field_name("argument"))
                k = self._index(node.child_by_field_name("index"), v)
                return V.component(v, (k,), f"the component [{k}]")
            if t == "assignment_expression":
                return self._assignment(node)
            if t == "update_expression":
                return self._update(node)
        except V.TypeProblem as e:
            raise Failure(node, str(e)) from None
        if t in UNSUPPORTED_NODES:
            raise Failure(node, f"{UNSUPPORTED_NODES[t]} is not supported")
        raise Failure(node, f"{t.replace('_', ' ')} is not supported")

    def _index(self, node, v: V.Val) -> int:
        k = self.expr(node)
        c = k.comps[0] if k.is_scalar else None
        if c is None or not c.is_const or k.base != "int":
            raise Failure(node, "an index must be a constant int (arrays are not supported)")
        i = int(D.value_of(c))
        if not 0 <= i < v.n:
            raise Failure(node, f"index {i} out of range for {v.type}")
        return i

    def _target(self, node):
        """(variable, name, component indices or None) of an assignment's left side."""
        if node.type == "identifier":
            name = text(node)
            return self.lookup(name, node), name, None
        if node.type == "parenthesized_expression":
            return self._target(named(node)[-1])
        if node.type in ("field_expression", "subscript_expression"):
            var, name, idx = self._target(node.child_by_field_name("argument"))
            n = var.val.n if idx is None else len(idx)
            if node.type == "field_expression":
                sel = V.component_indices(text(node.child_by_field_name("field")), n)
                if len(set(sel)) != len(sel):
                    raise Failure(node, "a swizzle written to repeats a component")
            else:
                sel = (self._index(node.child_by_field_name("index"),
                                   V.Val(var.val.base, (None,) * n)),)
            base_idx = tuple(range(var.val.n)) if idx is None else idx
            return var, name, tuple(base_idx[i] for i in sel)
        raise Failure(node, f"cannot assign to {node.type.replace('_', ' ')}")

    def _write(self, var, name, idx, new: V.Val, node) -> V.Val:
        if idx is None:
            return self.assign(var, new, node, name)
        old = var.val
        new = self._coerce(new, old.base, len(idx), node, f"assignment to {name!r}")
        comps = list(old.comps)
        for i, c in zip(idx, new.comps, strict=False):
            comps[i] = c
        tags = old.tags & (V.SCALARS if "even" in new.tags or "scalars" in new.tags else V.NONE)
        whole = V.Val(old.base, tuple(comps), tags, old.why or new.why or (
            None if tags else "a write to single components of a vector"))
        return self.assign(var, whole, node, name)

    def _read(self, var, idx) -> V.Val:
        return var.val if idx is None else V.component(var.val, idx, "a component")

    def _assignment(self, node):
        op = text(node.child_by_field_name("operator"))
        var, name, idx = self._target(node.child_by_field_name("left"))
        rhs = self.expr(node.child_by_field_name("right"))
        if op != "=":
            sym = op[:-1]
            if sym not in ("+", "-", "*", "/"):
                raise Failure(node, f"the operator {op!r} is not supported")
            rhs = V.binary(sym, self._read(var, idx), rhs)
        return self._write(var, name, idx, rhs, node)

    def _update(self, node):
        op = text(node.child_by_field_name("operator"))
        arg = node.child_by_field_name("argument")
        var, name, idx = self._target(arg)
        old = self._read(var, idx)
        new = V.binary("+" if op == "++" else "-", old, V.scalar(D.const(1.0), "int"))
        self._write(var, name, idx, new, node)
        postfix = node.children[0].id == arg.id
        return old if postfix else new


def number(node) -> V.Val:
    literal = text(node).strip()
    low = literal.lower()
    try:
        if low.startswith("0x"):
            return V.scalar(D.const(int(low.rstrip("u"), 16)), "int")
        if low.endswith("lf"):
            return V.scalar(D.const(float(low[:-2])), "float")
        if "." in low or "e" in low or low.endswith("f"):
            return V.scalar(D.const(float(low.rstrip("f"))), "float")
        if len(low) > 1 and low.startswith("0") and low.rstrip("u").isdigit():
            return V.scalar(D.const(int(low.rstrip("u"), 8)), "int")
        return V.scalar(D.const(int(low.rstrip("u"))), "int")
    except ValueError:
        raise Failure(node, f"malformed number {literal!r}") from None
