"""
GLSL to formulas: a BRDF Explorer shader as a compiled, traceable brdfkit kernel
================================================================================

:func:`translate` turns the GLSL of a ``.brdf`` file's shader section — helper
functions, constants and ``vec3 BRDF(vec3 L, vec3 V, vec3 N, vec3 X, vec3 Y)`` — into
the source of a Python module defining one formula (:mod:`brdfkit._dual`),
``kernel(ix, iy, iz, ox, oy, oz, p)``: Numba compiles it as the model's kernel (the
speed of a built-in model), and Dr.Jit traces the same code into Mitsuba.

How. The shader is parsed by tree-sitter's GLSL grammar (a real parser: a syntax error
is located, nothing is matched by regular expressions) and run symbolically
(:mod:`._interp`): scalarised (vectors are tuples of scalars), functions inlined, loops
with constant bounds unrolled, branches turned into selects (:mod:`._values`,
:mod:`._builtins`), constants folded, common sub-expressions shared (:mod:`._dag`). The
result is one expression per colour channel, written out as straight-line code.

The frame and the channels. L = ω_i = (ix, iy, iz), V = ω_o, N = +z, X = +x, Y = +y
(brdfkit's local frame, as BRDF Explorer's). A ``float`` uniform reads ``p[k]``, a
``vec3`` (colour) uniform ``p[k:k+3]``, as the caller lays them out; a ``bool`` uniform
is a compile-time constant (each combination of bools is its own kernel; they are few and
a fit holds them). A grey result (three equal channels) gives one channel; otherwise the
kernel returns the channel ``p[C]`` (0, 1, 2: the last entry of each packed row).
Below the horizon (iz ≤ 0 or oz ≤ 0) the value is 0, whatever the shader computes.

Precision. GLSL's ``float`` is 32-bit; brdfkit evaluates in float64, so its values
agree with a GPU's to float32 precision (≈1e-6 relative, more where the formula cancels),
and are exact where the GPU rounds. A NaN the shader makes (``normalize`` of a zero
vector, ``acos`` outside [−1, 1]) stays NaN: the engines report it in their status.

Public objects
--------------
- :func:`translate`, :class:`Translation`, :class:`Uniform`.
- :func:`parse` — the tree-sitter syntax tree of GLSL source, with syntax errors raised.
- :data:`PRIMITIVES` — the names of :mod:`brdfkit._dual` the generated code calls.

References
----------
- J. Kessenich, D. Baldwin, R. Rost, *The OpenGL Shading Language*, version 4.60.8
  (2023): §5 (operators, implicit conversions), §6.1 (function definitions, hiding of
  built-ins), §8 (built-in functions).
- Walt Disney Animation Studios, *BRDF Explorer* (github.com/wdas/brdf),
  ``BRDFBase::loadShaderFromFile``: the uniforms prepended to the shader.
- M. Brunsfeld et al., *tree-sitter* and *tree-sitter-glsl* (the parser).
"""

from __future__ import annotations

import hashlib
from dataclasses import dataclass

from brdfkit.errors import BrdfkitError
from brdfkit.glsl import _dag as D
from brdfkit.glsl import _values as V
from brdfkit.glsl._interp import Failure, run

__all__ = ["translate", "Translation", "Uniform", "parse", "PRIMITIVES", "TRANSLATOR_VERSION"]

#: Bumped when the generated code changes meaning (part of every generated module's key).
TRANSLATOR_VERSION = 1
#: The names of brdfkit._dual the generated code may call.
PRIMITIVES = ("select", "sqrt", "exp", "log", "sin", "cos", "tan", "asin", "acos", "atan",
              "atan2", "power", "floor", "absolute", "minimum", "maximum")


@dataclass(frozen=True)
class Uniform:
    """A shader parameter as the kernel reads it: ``name``; ``type`` ("float", "bool",
    "vec3"); ``offset`` into the packed row (floats, colours) or ``value`` (bools: a
    compile-time constant)."""

    name: str
    type: str
    offset: int = -1
    value: bool = False


@dataclass(frozen=True)
class Translation:
    """The result of :func:`translate`.

    ``source``: the generated module's source (defines ``kernel``); ``grey``: whether the
    three channels are one expression (then the kernel ignores the channel entry);
    ``channel_offset``: where the kernel reads its channel (coloured kernels); ``isotropic``
    and ``isotropy_reason``: whether the value provably depends on L and V only through
    rotation- and mirror-invariant quantities (:mod:`._values`), and why (or why not, with
    the file, line and column of the first frame-dependent step); ``n_nodes``: the size of
    the scalar graph; ``digest``: the key of the source (content and translator version).
    """

    source: str
    grey: bool
    channel_offset: int
    isotropic: bool
    isotropy_reason: str
    n_nodes: int
    digest: str


class _Place:
    def __init__(self, path: str, first_line: int):
        self.path, self.first_line = path, first_line

    def __call__(self, row: int, col: int) -> str:
        return f"{self.path}:{self.first_line + row + 1}:{col + 1}"


def _language():
    import warnings

    import tree_sitter
    import tree_sitter_glsl

    with warnings.catch_warnings():  # tree-sitter-glsl 0.2 hands over its grammar as an int
        warnings.simplefilter("ignore", DeprecationWarning)
        return tree_sitter.Language(tree_sitter_glsl.language())


def parse(text: str, *, path: str = "<shader>", first_line: int = 0):
    """The tree-sitter tree of GLSL *text*; raises :class:`~brdfkit.errors.BrdfkitError`
    naming ``path:line:col`` (lines counted from *first_line*, the line before the text)
    at the first syntax error."""
    import tree_sitter

    parser = tree_sitter.Parser(_language())
    tree = parser.parse(text.encode("utf-8"))
    if tree.root_node.has_error:
        bad = _first_error(tree.root_node)
        where = _Place(path, first_line)(*bad.start_point)
        if bad.is_missing:
            raise BrdfkitError(f"{where}: syntax error: expected {bad.type!r}")
        snippet = bad.text.decode("utf-8", "replace").strip().splitlines()
        near = f" near {snippet[0][:40]!r}" if snippet and snippet[0] else ""
        raise BrdfkitError(f"{where}: syntax error{near}")
    return tree


def _first_error(node):
    stack = [node]
    while stack:
        n = stack.pop()
        if n.is_missing or n.type == "ERROR":
            return n
        if n.has_error:
            stack.extend(reversed(n.children))
    return node


def translate(text: str, uniforms: list[Uniform], *, path: str = "<shader>",
              first_line: int = 0, channel_offset: int | None = None) -> Translation:
    """The kernel module of the GLSL shader *text* (module docstring).

    Parameters
    ----------
    text : str
        The shader section: helper functions, constants and ``BRDF``.
    uniforms : list of Uniform
        The file's parameters, as the kernel reads them.
    path, first_line : str, int
        For error messages: the file, and the line before *text*'s first line.
    channel_offset : int, optional
        Where a coloured kernel reads its channel index (default: after the last
        uniform's entries).

    Raises
    ------
    BrdfkitError
        ``path:line:col: message`` for a syntax error, an unknown identifier or
        function, a type mismatch or an unsupported construct; one line.
    """
    place = _Place(path, first_line)
    tree = parse(text, path=path, first_line=first_line)
    width = max((u.offset + (3 if u.type == "vec3" else 1) for u in uniforms
                 if u.type != "bool"), default=0)
    chan = width if channel_offset is None else int(channel_offset)
    try:
        with D.graph():
            vals = {u.name: _uniform(u) for u in uniforms}
            inputs = [V.vector((D.leaf(D.FLOAT, "in", f"{w}{c}") for c in "xyz"), tags=V.EQ)
                      for w in ("i", "o")]
            frame_n = V.vector((D.const(0.0), D.const(0.0), D.const(1.0)),
                               tags=V.EQ | V.SCALARS)
            frame_x = V.vector((D.const(1.0), D.const(0.0), D.const(0.0)),
                               why="reads the tangent X")
            frame_y = V.vector((D.const(0.0), D.const(1.0), D.const(0.0)),
                               why="reads the bitangent Y")
            out = run(tree.root_node, uniforms=vals,
                      inputs=[*inputs, frame_n, frame_x, frame_y])
            return _emit(out, chan, path, text, place)
    except Failure as f:
        raise BrdfkitError(f"{place(f.row, f.col)}: {f.message}") from None


def _uniform(u: Uniform) -> V.Val:
    if u.type == "float":
        return V.scalar(D.leaf(D.FLOAT, "p", u.offset), "float", V.EVEN)
    if u.type == "bool":
        return V.scalar(D.const(bool(u.value)), "bool", V.EVEN)
    if u.type == "vec3":
        return V.vector((D.leaf(D.FLOAT, "p", u.offset + k) for k in range(3)), "float",
                        V.SCALARS)
    raise ValueError(f"uniform type must be float, bool or vec3; got {u.type!r}")


_HEADER = '''\
"""Generated by brdfkit.glsl (translator version {version}) from {path}; do not edit.

Shader digest {digest}.
"""
from brdfkit._dual import formula, {primitives}
from brdfkit.models._drivers import VECTOR_OPTIONS

_NAN = float("nan")
_INF = float("inf")
_CACHE = "__file__" in globals()  # compiled code kept on disk when loaded from a file


@formula(cache=_CACHE, **VECTOR_OPTIONS)
def kernel(ix, iy, iz, ox, oy, oz, p):
'''


def _emit(out: V.Val, chan: int, path: str, text: str, place: _Place) -> Translation:
    r, g, b = out.comps
    grey = r is g is b
    channel = D.leaf(D.FLOAT, "p", chan)
    value = r if grey else D.op("select", D.op("eq", channel, D.const(0.0)), r, D.op(
        "select", D.op("eq", channel, D.const(1.0)), g, b))
    lines, (expr,) = D.emit([value])
    n_nodes = len(lines)
    digest = hashlib.sha256(f"{TRANSLATOR_VERSION}\n{text}".encode()).hexdigest()[:16]
    body = "".join(f"    {line}\n" for line in lines)
    body += f"    return select((iz > 0.0) & (oz > 0.0), {expr}, 0.0)\n"
    source = _HEADER.format(version=TRANSLATOR_VERSION, path=path.replace('"', "'"),
                            digest=digest, primitives=", ".join(PRIMITIVES)) + body
    isotropic = "scalars" in out.tags
    if isotropic:
        reason = "reads L, V and N only through rotation- and mirror-invariant quantities"
    else:
        why, _, at = (out.why or "depends on the tangent frame").partition(" @")
        row, _, col = at.partition(":")
        reason = f"{why} ({place(int(row), int(col))})" if col else why
    return Translation(source=source, grey=grey, channel_offset=chan, isotropic=isotropic,
                       isotropy_reason=reason, n_nodes=n_nodes, digest=digest)
