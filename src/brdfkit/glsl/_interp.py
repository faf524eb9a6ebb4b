"""
The GLSL interpreter: a shader's ``BRDF`` function run symbolically into a scalar graph
=====================================================================================

:func:`run` executes the syntax tree (tree-sitter's GLSL grammar) of a ``.brdf`` file's
shader section with symbolic inputs: every value is a :class:`~._values.Val` of graph
nodes (:mod:`._dag`), so the result is the BRDF as one expression per colour channel.

- **Control flow becomes data flow.** An ``if`` executes both branches, each under its
  condition; an assignment under a condition c is ``x = select(c, new, old)``; ``return``
  under c sets ``ret = select(c, value, ret)`` and clears the function's *alive*
  predicate, so later statements no longer take effect where it returned (early returns,
  nested). ``break``/``continue`` clear a loop's predicates the same way.
- **Loops with constant bounds are unrolled** (the condition must fold to a constant on
  every iteration; at most :data:`MAX_ITERATIONS`).
- **Functions are inlined**: a call runs the callee's body on the argument values, in
  its own scopes (globals visible; writing a global is refused). A user function hides
  every built-in of its name, as GLSL ≥ 1.30 scopes them and Mesa compiles them (a file's
  own ``reflect`` with the opposite sign is the one called); overloads are chosen by
  exact argument types, then with int → float conversion. A function is visible from its
  first declaration (prototype or definition) on: a call above it reaches the built-in.
  Recursion is refused.
- Declarations: ``const`` and other globals, locals in block scopes, several declarators per
  line; uninitialised locals are 0.

Refused, with the file, line, column and construct: textures and samplers, arrays,
structs, matrices, ``out``/``inout`` parameters, ``discard``, ``switch``, loops whose
bound is not constant, recursion, bit operations, function-like macros and other
preprocessor lines, uniforms declared in the shader (parameters belong in the
``::begin parameters`` block).

Public objects (for :mod:`brdfkit.glsl`)
-----------------------------------------
- :func:`run` — the output channels of ``BRDF`` and their isotropy tags.
- :class:`Failure` — a located problem (raised; the caller formats it).
- :data:`MAX_ITERATIONS`.
"""

from __future__ import annotations

from dataclasses import dataclass, field

from brdfkit.glsl import _dag as D
from brdfkit.glsl import _values as V
from brdfkit.glsl._builtins import BUILTINS
from brdfkit.glsl._expressions import Expressions
from brdfkit.glsl._syntax import UNSUPPORTED_CALLS, UNSUPPORTED_NODES, Failure, named, text

__all__ = ["run", "Failure", "MAX_ITERATIONS"]

#: The most iterations one loop is unrolled to (a shader's loops over lobes or samples have
#: tens; more is a sign of a bound that only looks constant, and of a huge kernel).
MAX_ITERATIONS = 1024

@dataclass
class _Var:
    val: V.Val
    const: bool = False
    is_global: bool = False


@dataclass
class _Function:
    node: object
    name: str
    params: list  # (name, base, n, node)
    ret: tuple | None  # (base, n) or None for void


def _true() -> V.Val:
    return V.scalar(D.const(True), "bool")


@dataclass
class _Loop:
    running: V.Val = field(default_factory=_true)
    iter_alive: V.Val = field(default_factory=_true)


@dataclass
class _Frame:
    function: _Function
    scopes: list
    conds: list = field(default_factory=list)
    loops: list = field(default_factory=list)
    alive: V.Val = field(default_factory=_true)
    ret: V.Val | None = None


def _type_of(node) -> tuple[str, int] | None:
    if node.type not in ("primitive_type", "type_identifier"):
        return None
    name = text(node)
    if name == "void":
        return None
    parsed = V.parse_type(name)
    if parsed is None:
        what = "a matrix" if name.startswith(("mat", "dmat")) else (
            "a sampler" if "sampler" in name else f"the type {name!r}")
        raise Failure(node, f"{what} is not supported (brdfkit takes float, int and bool "
                            "scalars and vectors)")
    return parsed


class _Interpreter(Expressions):
    def __init__(self, root, uniforms: dict):
        self.root = root
        self.globals: dict[str, _Var] = {k: _Var(v, const=True, is_global=True)
                                         for k, v in uniforms.items()}
        self.uniform_names = set(uniforms)
        self.functions: dict[str, list[_Function]] = {}
        #: name → where it is first declared (a prototype or a definition), a byte offset
        self.declared_at: dict[str, int] = {}
        self.frames: list[_Frame] = []

    # ------------------------------------------------------------ top level
    def collect(self):
        for node in named(self.root):
            if node.type == "function_definition":
                self._define(node)
            elif node.type == "declaration":
                for d in named(node):
                    if d.type == "function_declarator":  # a prototype: declared from here
                        fname = text(d.child_by_field_name("declarator"))
                        self.declared_at.setdefault(fname, node.start_byte)
        for node in named(self.root):
            if node.type == "function_definition":
                continue
            if node.type == "declaration":
                self._declare(node, global_scope=True)
            elif node.type == "preproc_def":
                self._define_macro(node)
            elif node.type in UNSUPPORTED_NODES:
                raise Failure(node, f"{UNSUPPORTED_NODES[node.type]} is not supported")
            elif node.type != ";":
                raise Failure(node, f"unexpected {node.type.replace('_', ' ')} at file scope")

    def _define(self, node):
        decl = node.child_by_field_name("declarator")
        if decl is None or decl.type != "function_declarator":
            raise Failure(node, "a function definition without a name and parameters")
        name = text(decl.child_by_field_name("declarator"))
        ret_node = node.child_by_field_name("type")
        ret = _type_of(ret_node)
        params = []
        for p in named(decl.child_by_field_name("parameters")):
            if p.type != "parameter_declaration":
                raise Failure(p, f"unexpected {p.type} in a parameter list")
            quals = [c for c in p.children if c.type in ("out", "inout")]
            if quals:
                raise Failure(quals[0], f"{text(quals[0])} parameters are not supported "
                                        "(outside isFunc); return the value instead")
            ptype = _type_of(p.child_by_field_name("type"))
            pname = p.child_by_field_name("declarator")
            if ptype is None:
                if pname is None:
                    continue  # f(void)
                raise Failure(p, "a parameter of type void")
            if pname is None or pname.type != "identifier":
                raise Failure(p, "a parameter must be a plain name (arrays are not supported)")
            params.append((text(pname), ptype[0], ptype[1], p))
        fn = _Function(node, name, params, ret)
        self.declared_at[name] = min(self.declared_at.get(name, node.start_byte),
                                     node.start_byte)
        for other in self.functions.get(name, []):
            if [(b, n) for _, b, n, _ in other.params] == [(b, n) for _, b, n, _ in params]:
                raise Failure(node, f"function {name!r} is defined twice with the same "
                                    "parameter types")
        self.functions.setdefault(name, []).append(fn)

    def _define_macro(self, node):
        name = text(node.child_by_field_name("name"))
        value = node.child_by_field_name("value")
        if value is None:
            raise Failure(node, f"#define {name} without a value is not supported")
        raise Failure(node, f"#define is not supported (write 'const float {name} = "
                            f"{text(value).strip()};')")

    def brdf(self, inputs):
        fns = self.functions.get("BRDF", [])
        want = [("float", 3)] * 5
        fn = next((f for f in fns if [(b, n) for _, b, n, _ in f.params] == want), None)
        if fn is None or fn.ret != ("float", 3):
            raise Failure(fns[0].node if fns else None,
                          "no function 'vec3 BRDF(vec3 L, vec3 V, vec3 N, vec3 X, vec3 Y)'")
        return self.call(fn, list(inputs), fn.node)

    # ------------------------------------------------------------ calls
    def call(self, fn: _Function, args: list, where) -> V.Val:
        if any(f.function is fn for f in self.frames):
            raise Failure(where, f"recursion ({fn.name} calls itself) is not supported")
        if len(self.frames) > 64:
            raise Failure(where, "function calls nested more than 64 deep")
        scope = {}
        for (pname, base, _n, _), a in zip(fn.params, args, strict=False):
            scope[pname] = _Var(V.convert(a, base))
        frame = _Frame(fn, [scope])
        self.frames.append(frame)
        try:
            self.block(fn.node.child_by_field_name("body"))
        finally:
            self.frames.pop()
        if fn.ret is None:
            return V.Val("float", ())
        if frame.ret is None:
            raise Failure(fn.node, f"function {fn.name!r} does not return a value")
        return frame.ret

    def callnamed(self, name: str, args: list, node) -> V.Val:
        # GLSL (as Mesa implements it): a user function is visible from its first
        # declaration on, and from there hides every built-in of its name
        if name in self.functions:
            if node.start_byte >= self.declared_at.get(name, 0):
                return self.call(self._overload(name, args, node), args, node)
            if name not in BUILTINS:
                raise Failure(node, f"{name!r} is called before it is declared (declare it "
                                    "above, or write a prototype)")
        parsed = V.parse_type(name)
        if parsed is not None:
            try:
                return V.construct(parsed[0], parsed[1], args)
            except V.TypeProblem as e:
                raise Failure(node, str(e)) from None
        if name in BUILTINS:
            try:
                return BUILTINS[name](args)
            except V.TypeProblem as e:
                raise Failure(node, str(e)) from None
        if name.startswith(("texture", "sampler")) or name in UNSUPPORTED_CALLS:
            raise Failure(node, f"{name}() is not supported (textures and derivatives)")
        if name.startswith(("mat", "dmat")):
            raise Failure(node, f"{name}() is not supported (matrices)")
        raise Failure(node, f"unknown function {name!r}")

    def _overload(self, name, args, node) -> _Function:
        cands = self.functions[name]
        types = [(a.base, a.n) for a in args]
        for f in cands:
            if [(b, n) for _, b, n, _ in f.params] == types:
                return f
        for f in cands:
            if len(f.params) == len(args) and all(
                    (b, n) == t or (b == "float" and t == ("int", n))
                    for (_, b, n, _), t in zip(f.params, types, strict=False)):
                return f
        got = ", ".join(V.type_of(*t) for t in types)
        raise Failure(node, f"no function {name}({got}) (defined: " + "; ".join(
            f"{name}(" + ", ".join(V.type_of(b, n) for _, b, n, _ in f.params) + ")"
            for f in cands) + "; a function of this name hides the built-in)")

    # ------------------------------------------------------------ state
    @property
    def frame(self) -> _Frame:
        return self.frames[-1]

    def guard(self) -> V.Val:
        """Where the current statement takes effect: the function has not returned, the
        enclosing ifs' conditions hold, no loop was left or continued (a bool Val)."""
        f = self.frame
        g = f.alive
        for c in f.conds:
            g = V.binary("&&", g, c)
        for lp in f.loops:
            g = V.binary("&&", V.binary("&&", g, lp.running), lp.iter_alive)
        return g

    def lookup(self, name: str, node) -> _Var:
        if self.frames:
            for scope in reversed(self.frame.scopes):
                if name in scope:
                    return scope[name]
        if name in self.globals:
            return self.globals[name]
        raise Failure(node, f"unknown identifier {name!r}")

    def assign(self, var: _Var, new: V.Val, node, name: str):
        if var.const:
            what = "the parameter" if name in self.uniform_names else "the constant"
            raise Failure(node, f"assignment to {what} {name!r}")
        if var.is_global and self.frames:
            raise Failure(node, f"assignment to the global variable {name!r} inside a "
                                "function is not supported (use a local)")
        old = var.val
        new = self._coerce(new, old.base, old.n, node, f"assignment to {name!r}")
        if self._update_scope is not None:  # a for loop's update: its own counters only
            if not any(v is var for v in self._update_scope.values()):
                raise Failure(node, f"a loop update that writes {name!r}, declared outside "
                                    "the loop, is not supported")
            var.val = new  # unguarded: the counter stays a constant, the loop unrolls
            return new
        var.val = _guarded(self.guard() if self.frames else _true(), new, old)
        return var.val

    #: while a for loop's update runs: the loop's own scope (its counters), else None
    _update_scope = None

    def _coerce(self, v: V.Val, base, n, node, what) -> V.Val:
        if v.n != n or (v.base != base and not (base == "float" and v.base == "int")):
            raise Failure(node, f"{what}: expected {V.type_of(base, n)}, found {v.type}")
        return V.convert(v, base)

    # ------------------------------------------------------------ statements
    def block(self, node):
        self.frame.scopes.append({})
        try:
            for child in named(node):
                self.statement(child)
        finally:
            self.frame.scopes.pop()

    def statement(self, node):  # noqa: C901 - one dispatch over the statement kinds
        t = node.type
        if t == "compound_statement":
            return self.block(node)
        if t == "declaration":
            return self._declare(node, global_scope=False)
        if t == "expression_statement":
            kids = named(node)
            if kids and kids[0].type == "identifier" and text(kids[0]) == "discard":
                raise Failure(kids[0], "discard is not supported")
            for k in kids:
                self.expr(k)
            return None
        if t == "if_statement":
            return self._if(node)
        if t == "return_statement":
            return self._return(node)
        if t in ("for_statement", "while_statement", "do_statement"):
            return self._loop(node)
        if t in ("break_statement", "continue_statement"):
            if not self.frame.loops:
                raise Failure(node, f"{t.split('_')[0]} outside a loop")
            lp, g = self.frame.loops[-1], self.guard()
            if t == "break_statement":
                lp.running = V.binary("&&", lp.running, V.unary("!", g))
            else:
                lp.iter_alive = V.binary("&&", lp.iter_alive, V.unary("!", g))
            return None
        if t in UNSUPPORTED_NODES:
            raise Failure(node, f"{UNSUPPORTED_NODES[t]} is not supported")
        raise Failure(node, f"{t.replace('_', ' ')} is not supported")

    def _declare(self, node, *, global_scope: bool):
        quals = [text(c) for c in node.children if c.type in ("type_qualifier", "uniform",
                                                                "in", "out", "attribute",
                                                                "varying", "buffer")]
        for q in quals:
            if q not in ("const", "highp", "mediump", "lowp", "precision"):
                raise Failure(node, f"a {q} declaration in the shader: parameters belong in "
                                    "the '::begin parameters' block")
        type_node = node.child_by_field_name("type")
        decls = [c for c in node.children if node.field_name_for_child(
            node.children.index(c)) == "declarator"]
        if decls and all(d.type == "function_declarator" for d in decls):
            return  # a prototype
        vtype = _type_of(type_node)
        if vtype is None:
            raise Failure(node, "a variable of type void")
        is_const = "const" in quals
        for d in decls:
            value_node = None
            if d.type == "init_declarator":
                value_node = d.child_by_field_name("value")
                d = d.child_by_field_name("declarator")
            if d.type != "identifier":
                what = UNSUPPORTED_NODES.get(d.type, d.type.replace("_", " "))
                raise Failure(d, f"{what} is not supported")
            name = text(d)
            if value_node is not None:
                val = self._coerce(self.expr(value_node), vtype[0], vtype[1], value_node,
                                   f"the initial value of {name!r}")
            else:
                if is_const:
                    raise Failure(d, f"the constant {name!r} has no value")
                zero = D.const(False) if vtype[0] == "bool" else D.const(0.0)
                val = V.Val(vtype[0], (zero,) * vtype[1], V.SCALARS if vtype[1] > 1
                            else V.EVEN)
            scope = self.globals if global_scope else self.frame.scopes[-1]
            if name in scope and (global_scope or name in self.uniform_names):
                raise Failure(d, f"{name!r} is declared twice")
            scope[name] = _Var(val, const=is_const, is_global=global_scope)

    def _if(self, node):
        cond = self._condition(node.child_by_field_name("condition"))
        then, alt = node.child_by_field_name("consequence"), node.child_by_field_name(
            "alternative")
        if alt is not None and alt.type == "else_clause":
            alt = named(alt)[0]
        c = cond.comps[0]
        if c.is_const:
            branch = then if D.value_of(c) else alt
            if branch is not None:
                self._scoped(branch)
            return
        for c_branch, branch in ((cond, then), (V.unary("!", cond), alt)):
            if branch is None:
                continue
            self.frame.conds.append(c_branch)
            try:
                self._scoped(branch)
            finally:
                self.frame.conds.pop()

    def _scoped(self, node):
        if node.type == "compound_statement":
            self.block(node)
        else:
            self.frame.scopes.append({})
            try:
                self.statement(node)
            finally:
                self.frame.scopes.pop()

    def _condition(self, node) -> V.Val:
        kids = named(node) if node.type == "parenthesized_expression" else [node]
        v = self.expr(kids[-1]) if kids else None
        if v is None or v.type != "bool":
            raise Failure(node, f"a condition must be a bool; found {v.type if v else 'nothing'}")
        return v

    def _return(self, node):
        f = self.frame
        kids = named(node)
        if f.function.ret is None:
            if kids:
                raise Failure(node, f"the void function {f.function.name!r} returns a value")
            val = V.Val("float", ())
        else:
            if not kids:
                raise Failure(node, f"{f.function.name!r} must return a value")
            base, n = f.function.ret
            val = self._coerce(self.expr(kids[0]), base, n, kids[0],
                               f"the value {f.function.name!r} returns")
        g = self.guard()
        f.ret = val if f.ret is None else _guarded(g, val, f.ret)
        f.alive = V.binary("&&", f.alive, V.unary("!", g))

    def _loop(self, node):
        f = self.frame
        f.scopes.append({})
        lp = _Loop()
        try:
            init = node.child_by_field_name("initializer")
            if init is not None:
                if init.type == "declaration":
                    self._declare(init, global_scope=False)
                else:
                    self.expr(init)
            cond_node = node.child_by_field_name("condition")
            update = node.child_by_field_name("update")
            body = node.child_by_field_name("body")
            f.loops.append(lp)
            first = node.type == "do_statement"
            for _ in range(MAX_ITERATIONS + 1):
                if not first and cond_node is not None:
                    c = self._condition(cond_node).comps[0]
                    if not c.is_const:
                        raise Failure(cond_node, "a loop whose bound is not a constant is not "
                                                 "supported (loops are unrolled)")
                    if not D.value_of(c):
                        break
                first = False
                run_flag = lp.running.comps[0]
                if run_flag.is_const and not D.value_of(run_flag):
                    break
                lp.iter_alive = _true()
                self._scoped(body)
                if update is not None:
                    self._update_scope = f.scopes[-1]
                    try:
                        self.expr(update)
                    finally:
                        self._update_scope = None
            else:
                raise Failure(node, f"a loop of more than {MAX_ITERATIONS} iterations")
        finally:
            if lp in f.loops:
                f.loops.remove(lp)
            f.scopes.pop()

    # ------------------------------------------------------------ expressions
def _guarded(g: V.Val, new: V.Val, old: V.Val) -> V.Val:
    """*new* where the guard *g* holds, else *old* (the value of an assignment or a return
    under conditions)."""
    c = g.comps[0]
    if c.is_const:
        return new if D.value_of(c) else old
    return V.select(g, new, old)


def run(root, *, uniforms: dict, inputs: list) -> V.Val:
    """The value of ``BRDF(inputs)`` of the shader *root* (a tree-sitter translation unit)
    with the *uniforms* (name → Val). Raises :class:`Failure`."""
    it = _Interpreter(root, uniforms)
    it.collect()
    return it.brdf(inputs)
