"""
Shared pieces of the GLSL interpreter: located failures, syntax-tree helpers, what is refused
============================================================================================

Public objects (for :mod:`._interp` and :mod:`._expressions`)
-------------------------------------------------------------
- :class:`Failure` — a problem at a node (raised; :func:`brdfkit.glsl.translate` formats
  it as ``file:line:col: message``).
- :func:`text`, :func:`named` — a node's source text; its named children, comments left out.
- :data:`UNSUPPORTED_CALLS`, :data:`UNSUPPORTED_NODES` — constructs refused by name.
"""

from __future__ import annotations

__all__ = ["Failure", "text", "named", "UNSUPPORTED_CALLS", "UNSUPPORTED_NODES"]

UNSUPPORTED_CALLS = ("texture", "texelFetch", "textureLod", "texture2D", "textureCube",
                      "dFdx", "dFdy", "fwidth", "noise1", "noise2", "noise3")
UNSUPPORTED_NODES = {
    "switch_statement": "a switch statement", "goto_statement": "goto",
    "struct_specifier": "a struct", "array_declarator": "an array",
    "preproc_function_def": "a function-like macro", "preproc_if": "#if",
    "preproc_ifdef": "#ifdef", "preproc_call": "a preprocessor directive",
    "preproc_include": "#include", "pointer_expression": "a pointer",
    "cast_expression": "a C cast", "sizeof_expression": "sizeof",
    "compound_literal_expression": "a compound literal",
}


class Failure(Exception):
    """A problem at (row, column) of the shader (0-based), with its message."""

    def __init__(self, node, message: str):
        super().__init__(message)
        self.row, self.col = (node.start_point[0], node.start_point[1]) if node else (0, 0)
        self.message = message


def text(node) -> str:
    return node.text.decode("utf-8", "replace")


def named(node):
    return [c for c in node.named_children if c.type != "comment"]
