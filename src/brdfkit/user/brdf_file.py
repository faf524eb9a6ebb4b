"""
BRDF Explorer ``.brdf`` files as brdfkit models
===============================================

Disney's BRDF Explorer reads an *analytic* BRDF from a text file (its loader,
``BRDFBase::loadBRDF`` and ``BRDFAnalytic``, github.com/wdas/brdf): the first line
``analytic``; lines starting with ``#`` (after leading blanks) and blank lines skipped
everywhere, the shader included; sections ``::begin NAME`` … ``::end NAME``, not nested:

- ``parameters``: ``float NAME MIN MAX DEFAULT``, ``bool NAME DEFAULT`` (0 or 1; brdfkit
  also reads ``true``/``false``) and ``color NAME R G B``;
- ``shader``: GLSL defining ``vec3 BRDF(vec3 L, vec3 V, vec3 N, vec3 X, vec3 Y)`` and its
  helpers; BRDF Explorer prepends ``uniform float|bool|vec3 NAME;`` per parameter;
- ``isFunc``: an importance-sampling function for BRDF Explorer's image-based lighting;
  brdfkit ignores it and says so in the model's notes (it samples the model from its own
  values, :mod:`brdfkit.data.sampler`).

:func:`definition` reads a file into a :class:`~brdfkit.user.model.ModelDefinition`
(parameters named exactly as the file writes them; the shader translated by
:mod:`brdfkit.glsl` into a formula, compiled by Numba and cached on disk, keyed on the
shader's content), which :class:`~brdfkit.user.model.FormulaBRDF` builds with values.

Parameters. ``float``: bounds [MIN, MAX] as written (the default must lie inside).
``color``: 3 components, each in [0, 1] (BRDF Explorer's colour picker; a larger
default widens the bound to it); a scalar value means grey. ``bool``: a compile-time
constant of the kernel (each combination is its own kernel, so a flag costs nothing in
the formula and isotropy is decided per combination); held, never fitted.

Channels. A ``color`` parameter, or a shader whose three channels differ, makes a
3-channel (RGB) model; otherwise the model is grey. Every packed row holds all the float
parameters, all colour components and, last, its channel index (the shader may mix
components, e.g. a luminance of the base colour).

A file claims nothing: reciprocity and energy are computed (``brdfkit check``), isotropy
is decided from the formula (:mod:`brdfkit.glsl._values`: a shader that reads X or Y,
or a direction's x or y component, is anisotropic).

Errors name the file, the line and column, what was expected and what was found
(:class:`~brdfkit.errors.DataFileError`); the shader's by :func:`brdfkit.glsl.translate`.

Public objects
--------------
- :func:`definition` — the model definition of a ``.brdf`` file (cached per content).
- :func:`read_brdf_file` — the file's sections and parameters, as :class:`BrdfFile`.
- :class:`BrdfFile`, :class:`FileParam`.
"""

from __future__ import annotations

import hashlib
import math
import os
from dataclasses import dataclass, replace

import numpy as np

from brdfkit._cache import bounded_cache
from brdfkit.errors import DataFileError, ParameterError
from brdfkit.models import Param

__all__ = ["definition", "read_brdf_file", "BrdfFile", "FileParam"]

#: Largest .brdf file read (the files in circulation are a few kB; a 1 MB one is not one).
MAX_FILE_BYTES = 1 << 20
_IS_FUNC_NOTE = ("isFunc section ignored: brdfkit samples the model from its own values "
                 "(a tabulated half-vector sampler)")


@dataclass(frozen=True)
class FileParam:
    """One parameter line: ``kind`` ("float", "bool", "color"), ``name``, ``default``
    (float, bool or 3 floats), ``lower``/``upper`` (floats only) and its ``line``."""

    kind: str
    name: str
    default: object
    lower: float = -math.inf
    upper: float = math.inf
    line: int = 0


@dataclass(frozen=True)
class BrdfFile:
    """A read ``.brdf`` file: ``path``, ``params`` (FileParams in file order), ``shader``
    (the section's text with skipped lines blanked, so that its line numbers are the
    file's from ``shader_line``, the line of ``::begin shader``), ``notes`` and
    ``digest`` (of the whole content)."""

    path: str
    params: tuple
    shader: str
    shader_line: int
    notes: tuple
    digest: str


def _fail(path, line, col, message) -> DataFileError:
    return DataFileError(f"{path}:{line}:{col}: {message}")


def _number(path, line, col, token, what) -> float:
    try:
        x = float(token)
    except ValueError:
        raise _fail(path, line, col, f"{what} must be a number; found {token!r}") from None
    if not math.isfinite(x):
        raise _fail(path, line, col, f"{what} must be finite; found {token!r}")
    return x


_FORMS = {"float": "float NAME MIN MAX DEFAULT", "bool": "bool NAME DEFAULT",
          "color": "color NAME R G B"}


def _parameter(path, line, raw: str) -> FileParam:
    stripped = raw.strip()
    indent = len(raw) - len(raw.lstrip())
    tokens, cols, pos = [], [], 0
    for tok in stripped.split():
        pos = stripped.index(tok, pos)
        tokens.append(tok)
        cols.append(indent + pos + 1)
        pos += len(tok)
    kind = tokens[0]
    if kind not in _FORMS:
        raise _fail(path, line, cols[0], f"a parameter line must start with float, bool or "
                                         f"color; found {kind!r}")
    want = {"float": 5, "bool": 3, "color": 5}[kind]
    extra = tokens[want:]
    if len(tokens) < want or (extra and not extra[0].startswith("#")):
        col = cols[min(len(tokens), want) - 1] if len(tokens) >= want else cols[-1]
        raise _fail(path, line, col, f"expected '{_FORMS[kind]}'; found {stripped!r}")
    name = tokens[1]
    if not (name.isidentifier() and name.isascii()):
        raise _fail(path, line, cols[1], f"a parameter name must be a GLSL identifier; "
                                         f"found {name!r}")
    if kind == "bool":
        word = tokens[2].lower()
        if word not in ("0", "1", "true", "false"):
            raise _fail(path, line, cols[2], f"bool {name}: DEFAULT must be 0 or 1 (or true/"
                                             f"false); found {tokens[2]!r}")
        return FileParam("bool", name, word in ("1", "true"), line=line)
    nums = [_number(path, line, c, t, f"{kind} {name}: {w}") for t, c, w in zip(
        tokens[2:5], cols[2:5], ("MIN", "MAX", "DEFAULT") if kind == "float" else "RGB",
        strict=False)]
    if kind == "color":
        bad = [(x, c) for x, c in zip(nums, cols[2:5], strict=False) if x < 0.0]
        if bad:
            raise _fail(path, line, bad[0][1], f"color {name}: components must be >= 0; found "
                                               f"{bad[0][0]:g}")
        return FileParam("color", name, tuple(nums), 0.0, max(1.0, *nums), line)
    lo, hi, default = nums
    if lo > hi:
        raise _fail(path, line, cols[2], f"float {name}: MIN {lo:g} is above MAX {hi:g}")
    if not lo <= default <= hi:
        raise _fail(path, line, cols[4], f"float {name}: DEFAULT {default:g} lies outside "
                                         f"[{lo:g}, {hi:g}]")
    return FileParam("float", name, default, lo, hi, line)


def read_brdf_file(path) -> BrdfFile:
    """The sections and parameters of the ``.brdf`` file *path* (module docstring).

    Raises
    ------
    DataFileError
        The file cannot be read, is not an ``analytic`` file, or a line is malformed
        (``path:line:col``, expected vs found); no ``shader`` section.
    """
    path = os.fspath(path)
    try:
        if os.path.isdir(path):
            raise IsADirectoryError(path)
        size = os.path.getsize(path)
        if size > MAX_FILE_BYTES:
            raise DataFileError(f"{path}: {size} bytes is not a .brdf file (at most "
                                f"{MAX_FILE_BYTES} bytes)")
        with open(path, "rb") as fh:
            data = fh.read(MAX_FILE_BYTES + 1)
    except OSError as e:
        raise DataFileError(f"{path}: cannot read the .brdf file ({e.strerror or e})") from None
    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError as e:
        raise DataFileError(f"{path}: not a text file (byte {e.start} is not UTF-8)") from None
    lines = text.splitlines()
    first = lines[0].strip().split(" ")[0] if lines else ""
    if first != "analytic":
        found = "bparam (BRDF Explorer's parametric format)" if first == "bparam" else repr(
            lines[0].strip()[:40] if lines else "")
        raise _fail(path, 1, 1, f"expected 'analytic' on the first line (an analytic .brdf "
                                f"file); found {found}")
    params, seen, notes = [], {}, []
    section, begin_line = "", 0
    shader_lines, shader_line, have_shader = None, 0, False
    for i, raw in enumerate(lines[1:], start=2):
        line = raw.strip()
        if not line or line.startswith("#"):
            if section == "shader":
                shader_lines.append("")  # BRDF Explorer drops it; the line count stays
            continue
        tokens = line.split()
        if tokens[0] in ("::begin", "::end"):
            name = tokens[1] if len(tokens) > 1 else ""
            if tokens[0] == "::begin":
                if section:
                    raise _fail(path, i, 1, f"'::begin {name}' inside the section '{section}' "
                                            f"(begun on line {begin_line}; sections do not nest)")
                section, begin_line = name, i
                if name == "shader":
                    if have_shader:
                        raise _fail(path, i, 1, "a second '::begin shader' section")
                    shader_lines, shader_line, have_shader = [], i, True
                elif name == "isFunc":
                    notes.append(_IS_FUNC_NOTE)
                elif name != "parameters":
                    notes.append(f"section '{name}' (line {i}) ignored: brdfkit reads the "
                                 "parameters and shader sections")
            else:
                if name != section:
                    raise _fail(path, i, 1, f"'::end {name}' does not close the open section "
                                            f"'{section or '(none)'}'")
                section = ""
            continue
        if section == "parameters":
            p = _parameter(path, i, raw)
            if p.name in seen:
                first = seen[p.name]
                raise _fail(path, i, raw.index(p.name) + 1,
                            f"parameter {p.name!r} is declared twice (first on line {first})")
            seen[p.name] = i
            params.append(p)
        elif section == "shader":
            shader_lines.append(raw)
    if section:
        raise _fail(path, begin_line, 1, f"'::begin {section}' is not closed by "
                                         f"'::end {section}'")
    if not have_shader:
        raise DataFileError(f"{path}: no '::begin shader' section (the GLSL defining "
                            "vec3 BRDF(vec3 L, vec3 V, vec3 N, vec3 X, vec3 Y))")
    return BrdfFile(path=path, params=tuple(params), shader="\n".join(shader_lines) + "\n",
                    shader_line=shader_line, notes=tuple(notes),
                    digest=hashlib.sha256(data).hexdigest()[:16])


# --------------------------------------------------------------------------- the model
def _variant(f: BrdfFile):
    """The definition for the bools among a model's values (validated as its parameters),
    of the content the model was built from: a fit's or an explorer's rebuilds with new
    values never read the file again."""
    flags = {p.name: p for p in _declarations(f) if p.kind == "bool"}
    if not flags:
        return None
    base = os.path.basename(f.path)

    def variant(values: dict):
        return _definition_of(f, {k: flags[k].validate(v, base) for k, v in values.items()
                                  if k in flags})

    return variant


def _declarations(f: BrdfFile) -> tuple:
    out = []
    for p in f.params:
        if p.kind == "float":
            out.append(Param(p.name, p.default, p.lower, p.upper,
                             doc=f"float parameter of {os.path.basename(f.path)} "
                                 f"(line {p.line})"))
        elif p.kind == "bool":
            out.append(Param(p.name, p.default, kind="bool",
                             doc=f"bool parameter of {os.path.basename(f.path)} "
                                 f"(line {p.line}); a compile-time flag, held by fits"))
        else:
            out.append(Param(p.name, list(p.default), 0.0, p.upper, kind="colour",
                             doc=f"color parameter (R, G, B) of {os.path.basename(f.path)} "
                                 f"(line {p.line})"))
    return tuple(out)


def _layout(f: BrdfFile):
    """(offset of each float and colour parameter in the packed row, the row's width before
    the channel index): the floats in file order, then the colours, 3 entries each."""

    offsets, k = {}, 0
    for p in f.params:
        if p.kind == "float":
            offsets[p.name], k = k, k + 1
    for p in f.params:
        if p.kind == "color":
            offsets[p.name], k = k, k + 3
    return offsets, k


def _packer(f: BrdfFile, name: str, coloured: bool):
    """The rows of :func:`_layout`, plus the channel index (0 for a grey model)."""
    floats = [p.name for p in f.params if p.kind == "float"]
    colours = [p.name for p in f.params if p.kind == "color"]

    def pack(values: dict) -> np.ndarray:
        row = [float(values[n]) for n in floats]
        for n in colours:
            c = np.asarray(values[n], dtype=np.float64).reshape(-1)
            if c.size == 1:
                c = np.repeat(c, 3)  # a scalar colour is grey
            if c.size != 3:
                raise ParameterError(f"{name}: parameter {n!r} is a color: give 3 components "
                                     f"(R, G, B) or one (grey); got {c.size}")
            row.extend(c.tolist())
        if not coloured:
            return np.array([row + [0.0]], dtype=np.float64)
        return np.array([row + [float(ch)] for ch in range(3)], dtype=np.float64)

    return pack


_definitions = bounded_cache("brdfkit.user.brdf_file._definitions", maxsize=64)


def definition(path, *, bools: dict | None = None, compiled: bool = True):
    """The :class:`~brdfkit.user.model.ModelDefinition` of the ``.brdf`` file *path*,
    with the file's bool parameters at *bools* (default: the file's defaults);
    *compiled* False: the same definition ``interpreted`` (its models evaluate the
    kernel's NumPy version; nothing here compiles: Numba compiles on first evaluation).

    Read and translated once per file content and bool values (the kernel's compiled
    loops are cached on disk by :mod:`brdfkit.models._drivers`). Raises
    :class:`~brdfkit.errors.DataFileError` (the file) or
    :class:`~brdfkit.errors.BrdfkitError` (the shader: ``path:line:col``).
    """
    path = os.path.abspath(os.fspath(path))
    f = read_brdf_file(path)
    unknown = sorted(set(bools or {}) - {p.name for p in f.params if p.kind == "bool"})
    if unknown:
        raise ParameterError(f"{os.path.basename(path)}: {unknown[0]!r} is not a bool parameter")
    d = _definition_of(f, bools or {})
    return d if compiled else replace(d, interpreted=True)


def _definition_of(f: BrdfFile, bools: dict):
    """The definition of the read file *f* with its bools at *bools* (the rest at the
    file's defaults), translated once per content and bool values."""
    flags = {p.name: bool(p.default) for p in f.params if p.kind == "bool"}
    flags.update({k: bool(v) for k, v in bools.items()})
    key = (f.digest, f.path, tuple(sorted(flags.items())))
    if key not in _definitions:
        _definitions[key] = _build(f, flags)
    return _definitions[key]


def _build(f: BrdfFile, flags: dict):
    from brdfkit.glsl import Uniform, translate
    from brdfkit.models._drivers import _load
    from brdfkit.user.model import ModelDefinition

    offsets, width = _layout(f)
    uniforms = [Uniform(p.name, "bool", value=flags[p.name]) if p.kind == "bool" else
                Uniform(p.name, "float" if p.kind == "float" else "vec3", offsets[p.name])
                for p in f.params]
    base = os.path.basename(f.path)
    tr = translate(f.shader, uniforms, path=f.path, first_line=f.shader_line,
                   channel_offset=width)
    module = _load(tr.source)
    if module is None:  # no writable cache directory: the same code, compiled in memory
        namespace: dict = {"__name__": f"brdfkit_brdf_{tr.digest}"}
        exec(compile(tr.source, f"<{base}>", "exec"), namespace)
        kernel = namespace["kernel"]
    else:
        kernel = module.kernel
    coloured = (not tr.grey) or any(p.kind == "color" for p in f.params)
    pack = _packer(f, base, coloured)
    flag_text = ", ".join(f"{k}={'true' if v else 'false'}" for k, v in flags.items())
    return ModelDefinition(
        name=base, source=f.path, target=f.path, params=_declarations(f), kernel=kernel,
        pack=pack, n_channels=3 if coloured else None, isotropic=tr.isotropic,
        isotropy_reason=tr.isotropy_reason + (f" (with {flag_text})" if flag_text else ""),
        reciprocal=None, energy_conserving=None, sampler=None,
        variant=_variant(f), citation=f"BRDF Explorer file {base}",
        summary=f"the BRDF of {base} (GLSL translated by brdfkit.glsl, {tr.n_nodes} "
                "operations; float64)",
        notes=f.notes)
