"""Real GLSL as the tests' reference: a ``.brdf`` file's shader run by Mesa (llvmpipe).

The independent second implementation the ``.brdf`` tests compare brdfkit against
(issue 21, §5): the file's GLSL compiled by Mesa's GLSL compiler and executed by its
llvmpipe software rasteriser in a GL 4.3 compute shader, through ``moderngl`` with a
headless EGL context (Debian ``libegl-mesa0 libgl1-mesa-dri libegl1``; ``scripts/setup.sh
--test`` installs them as root). Nothing here imports brdfkit: the file is read by the
simple line-based loop of BRDF Explorer's loader (wdas/brdf, ``BRDFBase::loadBRDF``), the
uniforms are prepended as its ``loadShaderFromFile`` does (``uniform float`` for every
float parameter, then ``uniform bool``, then ``uniform vec3`` for colours, each in file
order), then the shader section, then a ``main()`` that reads (L, V) pairs from a storage
buffer, calls ``BRDF(L, V, N, X, Y)`` with N = (0, 0, 1), X = (1, 0, 0), Y = (0, 1, 0)
(brdfkit's local frame) and writes the vec3 it returns.

GLSL's ``float`` is 32-bit: results are float32, whatever the inputs (they are rounded to
float32 on the way in; give brdfkit the same rounded values to compare arithmetic only).
The shader is run as written at every pair: below the horizon it returns whatever the
formula gives there (brdfkit gives 0; the tests compare those pairs separately).

Differences from BRDF Explorer, none of which changes what a shader computes:

- its loader drops blank lines and ``#`` lines everywhere, also inside the shader; here
  a ``#`` line of the shader becomes an empty line and blank lines stay, and a ``#line``
  directive before the shader makes Mesa's messages name the ``.brdf`` file's own lines
  (:func:`mesa_errors`). The corpus has no preprocessor lines in its shaders.
- the shader is compiled as ``#version 430`` (compute shaders) instead of its templates'
  ``#version 410``; the language of the constructs the files use is the same.

Public objects
--------------
- :class:`Parameter`, :class:`BrdfSource`, :func:`read_brdf` — a ``.brdf`` file's parts.
- :func:`unavailable_reason` — why there is no Mesa context (None when there is one).
- :func:`compute_source` — the compute shader built from a file.
- :class:`GlslBRDF` — a compiled file: ``GlslBRDF(path)(wi, wo, **params)`` → float32 (N, 3);
  ``.sample(u, **params)`` runs its isFunc ``sampleBRDF`` (value, wi, pdf).
- :func:`mesa_errors` — Mesa's compile errors for a file, as (line, column, message).
- :func:`require_mesa` — the context, or a pytest skip with the reason (the body of the
  test modules' ``mesa`` fixture).
- :func:`random_directions`, :func:`as_float32`, :func:`perturbation_spread`,
  :func:`float32_bound`, :func:`worst_ratio` — the tests' sampling of pairs and their
  float32 error model (:data:`RTOL`, :data:`ACOS_RTOL`, :data:`SPREAD_FACTOR`, :data:`ATOL`).
"""

from __future__ import annotations

import functools
import math
import re
from dataclasses import dataclass
from pathlib import Path

import numpy as np

__all__ = ["Parameter", "BrdfSource", "read_brdf", "unavailable_reason", "compute_source",
           "GlslBRDF", "mesa_errors", "require_mesa", "random_directions", "as_float32",
           "perturbation_spread", "float32_bound", "worst_ratio", "RTOL", "ACOS_RTOL",
           "SPREAD_FACTOR", "ATOL", "SETUP_HINT", "CORPUS"]

#: The corpus of .brdf files (the project's own): good files here, bad ones in bad/.
CORPUS = Path(__file__).resolve().parent / "brdf_files"

SETUP_HINT = ("install moderngl (pip install moderngl glcontext) and Debian's "
              "libegl-mesa0 libgl1-mesa-dri libegl1 (scripts/setup.sh --test does both as root)")

#: Work-group size of the compute shader (llvmpipe runs 8-wide SIMD; any multiple works).
LOCAL_SIZE = 64

#: Names the harness adds to the shader; prefixed so that a file's own names cannot clash.
_PREFIX = "brdfref_"


# --------------------------------------------------------------------------- the file
@dataclass(frozen=True)
class Parameter:
    """One line of the parameter block: kind ``float``, ``bool`` or ``color``."""

    kind: str
    name: str
    default: float | bool | tuple
    minimum: float | None = None  # float parameters only
    maximum: float | None = None


@dataclass(frozen=True)
class BrdfSource:
    """A ``.brdf`` file's parts: its parameters (file order), shader and isFunc text.

    ``shader_line`` (``is_func_line``) is the 1-based line of the file where the shader
    (isFunc) text starts; ``is_func`` is "" when the file has no isFunc section.
    """

    path: Path
    params: tuple
    shader: str
    shader_line: int
    is_func: str = ""
    is_func_line: int = 0

    def param(self, name: str) -> Parameter:
        for p in self.params:
            if p.name == name:
                return p
        raise KeyError(f"{self.path.name}: no parameter {name!r}")


def _parameter(tokens: list, where: str) -> Parameter:
    kind = tokens[0]
    counts = {"float": 5, "bool": 3, "color": 5}
    if kind not in counts or len(tokens) < counts[kind]:
        raise ValueError(f"{where}: not a parameter line: {' '.join(tokens)!r}")
    name = tokens[1]
    if kind in ("float", "color"):
        try:
            numbers = [float(t) for t in tokens[2:5]]
        except ValueError:
            raise ValueError(f"{where}: {kind} {name}: expected 3 numbers, got "
                             f"{' '.join(tokens[2:5])!r}") from None
    if kind == "float":
        lo, hi, default = numbers
        return Parameter("float", name, default, lo, hi)
    if kind == "bool":
        # BRDF Explorer reads the default with `stream >> bool`: 0 or 1
        word = tokens[2].lower()
        if word not in ("0", "1", "true", "false"):
            raise ValueError(f"{where}: bool default must be 0 or 1, got {tokens[2]!r}")
        return Parameter("bool", name, word in ("1", "true"))
    return Parameter("color", name, tuple(numbers))


def read_brdf(path) -> BrdfSource:
    """Read a ``.brdf`` file as BRDF Explorer's loader does (see the module docstring).

    Raises ValueError naming the file and line for what that loader rejects (first line
    not ``analytic``, nested or unbalanced sections, a bad parameter line).
    """
    path = Path(path)
    lines = path.read_text().splitlines()
    if not lines or lines[0].strip().split(" ")[0] != "analytic":
        raise ValueError(f"{path}:1: the first line must be 'analytic'")
    params, sections, starts = [], {}, {}
    current = ""
    for number, line in enumerate(lines[1:], start=2):
        text = line.strip()
        tokens = text.split()
        if tokens[:1] == ["::begin"]:
            if current:
                raise ValueError(f"{path}:{number}: section inside section {current!r}")
            current = tokens[1] if len(tokens) > 1 else ""
            sections[current] = []
            starts[current] = number + 1
            continue
        if tokens[:1] == ["::end"]:
            if (tokens[1] if len(tokens) > 1 else "") != current:
                raise ValueError(f"{path}:{number}: '::end' does not close {current!r}")
            current = ""
            continue
        if current == "parameters":
            if text and not text.startswith("#"):
                params.append(_parameter(tokens, f"{path}:{number}"))
        elif current:
            # keep the line count (messages name file lines); '#' lines are dropped by
            # BRDF Explorer's loader: an empty line here
            sections[current].append("" if text.startswith("#") else line)
    if current:
        raise ValueError(f"{path}: section {current!r} is not closed")
    if "shader" not in sections:
        raise ValueError(f"{path}: no '::begin shader' section")
    is_func = "\n".join(sections.get("isFunc", []))
    return BrdfSource(path, tuple(params), "\n".join(sections["shader"]) + "\n",
                      starts["shader"], is_func + "\n" if is_func.strip() else "",
                      starts.get("isFunc", 0))


# --------------------------------------------------------------------------- the context
@functools.cache
def _context():
    """The process's one headless context (EGL, GL ≥ 4.3), or the exception raised."""
    try:
        import moderngl
    except ImportError as exc:
        return exc
    try:
        return moderngl.create_context(standalone=True, backend="egl", require=430)
    except Exception as exc:  # noqa: BLE001 - any failure means "no context": reported
        return exc


def unavailable_reason() -> str | None:
    """None when a Mesa/EGL GL 4.3 context exists, else why not (and how to get one)."""
    ctx = _context()
    if isinstance(ctx, ImportError):
        return f"moderngl is not installed ({ctx}); {SETUP_HINT}"
    if isinstance(ctx, Exception):
        first = str(ctx).strip().splitlines()[0] if str(ctx).strip() else type(ctx).__name__
        return f"no headless EGL/Mesa GL 4.3 context ({first}); {SETUP_HINT}"
    return None


def require_mesa():
    """The moderngl context, or ``pytest.skip`` with the reason (the fixture's body)."""
    import pytest

    reason = unavailable_reason()
    if reason is not None:
        pytest.skip(reason)
    return _context()


def renderer() -> str:
    """The GL renderer string (``llvmpipe (LLVM …)`` on Mesa's software rasteriser)."""
    return _context().info["GL_RENDERER"]


# --------------------------------------------------------------------------- the shader
#: BRDF Explorer's importance-sampling function (BRDFBase::getISFunction's signature)
IS_FUNC_CALL = "sampleBRDF(u, v, N, X, Y, wi, pdf)"


def compute_source(source: BrdfSource, *, sample: bool = False) -> str:
    """The compute shader: version, buffers, the uniforms, the shader, then main().

    The isFunc section, if any, follows the shader (as BRDF Explorer inserts it). With
    *sample*, main() calls ``vec3 sampleBRDF(float u, float v, vec3 N, vec3 X, vec3 Y,
    out vec3 wi, out float pdf)`` instead of BRDF, reading (u, v) from the pairs' first
    two components and writing (value, wi, pdf) as two vec4.
    """
    head = [
        "#version 430",
        f"layout(local_size_x = {LOCAL_SIZE}) in;",
        # (L, V) as two vec4 per pair (std430: a vec3 array has a 16-byte stride anyway)
        f"layout(std430, binding = 0) readonly buffer {_PREFIX}In {{ vec4 {_PREFIX}dirs[]; }};",
        f"layout(std430, binding = 1) writeonly buffer {_PREFIX}Out "
        f"{{ vec4 {_PREFIX}out[]; }};",
        f"uniform uint {_PREFIX}n;",
    ]
    # exactly as BRDF Explorer's loadShaderFromFile: floats, then bools, then colours
    for kind, glsl in (("float", "float"), ("bool", "bool"), ("color", "vec3")):
        head += [f"uniform {glsl} {p.name};" for p in source.params if p.kind == kind]
    if sample:
        main = (
            "void main() {\n"
            "    uint i = gl_GlobalInvocationID.x;\n"
            f"    if (i >= {_PREFIX}n) return;\n"
            f"    float u = {_PREFIX}dirs[2u * i].x;\n"
            f"    float v = {_PREFIX}dirs[2u * i].y;\n"
            "    vec3 N = vec3(0.0, 0.0, 1.0);\n"
            "    vec3 X = vec3(1.0, 0.0, 0.0);\n"
            "    vec3 Y = vec3(0.0, 1.0, 0.0);\n"
            "    vec3 wi;\n"
            "    float pdf;\n"
            f"    vec3 value = {IS_FUNC_CALL};\n"
            f"    {_PREFIX}out[2u * i] = vec4(value, 0.0);\n"
            f"    {_PREFIX}out[2u * i + 1u] = vec4(wi, pdf);\n"
            "}\n")
    else:
        main = None
    main = main or (
        "void main() {\n"
        "    uint i = gl_GlobalInvocationID.x;\n"
        f"    if (i >= {_PREFIX}n) return;\n"
        f"    vec3 L = {_PREFIX}dirs[2u * i].xyz;\n"
        f"    vec3 V = {_PREFIX}dirs[2u * i + 1u].xyz;\n"
        "    vec3 N = vec3(0.0, 0.0, 1.0);\n"
        "    vec3 X = vec3(1.0, 0.0, 0.0);\n"
        "    vec3 Y = vec3(0.0, 1.0, 0.0);\n"
        f"    {_PREFIX}out[i] = vec4(BRDF(L, V, N, X, Y), 0.0);\n"
        "}\n")
    # '#line n': the next line is line n, so Mesa's messages name the .brdf file's lines
    is_func = f"#line {source.is_func_line}\n{source.is_func}" if source.is_func else ""
    return "\n".join(head) + f"\n#line {source.shader_line}\n" + source.shader + \
        is_func + "#line 100000\n" + main


_ERROR = re.compile(r"^\d+:(\d+)\((\d+)\): error: (.*)$", re.MULTILINE)


def mesa_errors(path) -> list:
    """Mesa's compile errors for the file's shader: [(line, column, message), ...].

    Lines are the ``.brdf`` file's (1-based), columns Mesa's (1-based); [] when it compiles.
    Link-time errors (e.g. recursion) carry Mesa's line 0.
    """
    ctx = require_mesa()
    source = compute_source(read_brdf(path))
    try:
        ctx.compute_shader(source).release()
    except Exception as exc:  # noqa: BLE001 - moderngl raises a plain Error with the log
        found = [(int(a), int(b), m) for a, b, m in _ERROR.findall(str(exc))]
        return found or [(0, 0, str(exc).strip())]
    return []


def _as_rows(a, name: str) -> np.ndarray:
    a = np.asarray(a, dtype=np.float64)
    if a.ndim != 2 or a.shape[1] != 3:
        raise ValueError(f"{name} must have shape (N, 3); got {a.shape}")
    return a


class GlslBRDF:
    """A ``.brdf`` file compiled by Mesa: ``model(wi, wo, **params)`` → float32 (N, 3).

    Parameters not given take the file's defaults; bools are Python bools (or 0/1),
    colours 3 numbers. Values are set as uniforms per call (the GPU rounds them to float32).
    """

    def __init__(self, path):
        self.source = read_brdf(path)
        self.path = self.source.path
        self._ctx = require_mesa()
        self._program = self._ctx.compute_shader(compute_source(self.source))
        self._sampler = None  # the isFunc program, compiled on first use

    def __call__(self, wi, wo, **params) -> np.ndarray:
        wi, wo = _as_rows(wi, "wi"), _as_rows(wo, "wo")
        if wi.shape != wo.shape:
            raise ValueError(f"wi and wo must have the same shape; got {wi.shape}, {wo.shape}")
        return self._run(self._program, wi, wo, 1, params)[:, 0, :3].copy()

    def sample(self, u, **params):
        """The file's isFunc ``sampleBRDF`` at *u* (N, 2) in [0, 1)²: (value (N, 3), wi
        (N, 3), pdf (N,)), float32. ValueError when the file has no isFunc section."""
        if not self.source.is_func:
            raise ValueError(f"{self.path.name} has no isFunc section")
        if self._sampler is None:
            self._sampler = self._ctx.compute_shader(compute_source(self.source, sample=True))
        u = np.asarray(u, dtype=np.float64)
        if u.ndim != 2 or u.shape[1] != 2:
            raise ValueError(f"u must have shape (N, 2); got {u.shape}")
        rows = np.zeros((u.shape[0], 3))
        rows[:, :2] = u
        out = self._run(self._sampler, rows, rows, 2, params)
        return out[:, 0, :3].copy(), out[:, 1, :3].copy(), out[:, 1, 3].copy()

    def _run(self, program, wi, wo, n_out: int, params: dict) -> np.ndarray:
        """Set the uniforms, run *program* over the pairs: float32 (N, n_out, 4)."""
        names = {p.name for p in self.source.params}
        unknown = set(params) - names
        if unknown:
            raise KeyError(f"{self.path.name}: unknown parameters {sorted(unknown)}; "
                           f"valid: {sorted(names)}")
        for p in self.source.params:
            value = params.get(p.name, p.default)
            uniform = program.get(p.name, None)  # None: optimised away (unused)
            if uniform is None:
                continue
            if p.kind == "color":
                uniform.value = tuple(float(c) for c in np.broadcast_to(value, (3,)))
            elif p.kind == "bool":
                uniform.value = bool(value)
            else:
                uniform.value = float(value)
        n = wi.shape[0]
        dirs = np.zeros((n, 2, 4), dtype=np.float32)
        dirs[:, 0, :3] = wi
        dirs[:, 1, :3] = wo
        inp = self._ctx.buffer(dirs.tobytes() if n else bytes(32))
        res = self._ctx.buffer(reserve=max(n, 1) * n_out * 16)
        try:
            inp.bind_to_storage_buffer(0)
            res.bind_to_storage_buffer(1)
            program[f"{_PREFIX}n"].value = n
            program.run(group_x=max(1, -(-n // LOCAL_SIZE)))
            return np.frombuffer(res.read(), dtype=np.float32).reshape(-1, n_out, 4)[:n]
        finally:
            inp.release()
            res.release()


# --------------------------------------------------------------------------- test helpers
def random_directions(rng, n: int, *, theta_min_deg: float = 3.0,
                      theta_max_deg: float = 87.0) -> np.ndarray:
    """Uniform directions on the part of the upper hemisphere with θ in [min, max] degrees.

    The tests keep away from the normal and the horizon by default: GLSL files take
    acos of cosines (ill-conditioned at 1: δθ = δcos/sin θ) and divide by N·L, N·V
    (ill-conditioned at 0), so float32 loses its precision there by construction.
    """
    ct = rng.uniform(np.cos(np.radians(theta_max_deg)), np.cos(np.radians(theta_min_deg)), n)
    phi = rng.uniform(0.0, 2.0 * np.pi, n)
    st = np.sqrt(1.0 - ct * ct)
    return np.stack([st * np.cos(phi), st * np.sin(phi), ct], axis=-1)


def as_float32(a) -> np.ndarray:
    """*a* rounded to float32 and back to float64: the values the GPU actually sees."""
    return np.asarray(a, dtype=np.float32).astype(np.float64)


def perturbation_spread(model: GlslBRDF, wi, wo, **params) -> np.ndarray:
    """Σ_k |Mesa(x + ulp_k e_k) − Mesa(x)| over the six coordinates x_k of (wi, wo), each
    moved to the next float32 away from zero: how much float32 rounding of the directions
    alone moves the shader's value at each pair (a first-order condition estimate), (N, 3).
    """
    wi = np.asarray(wi, dtype=np.float64)
    wo = np.asarray(wo, dtype=np.float64)
    base = model(wi, wo, **params).astype(np.float64)
    total = np.zeros_like(base)
    for which in (0, 1):
        for k in range(3):
            moved = [wi.copy(), wo.copy()]
            x = moved[which][:, k].astype(np.float32)
            moved[which][:, k] = np.nextafter(x, np.copysign(np.float32(np.inf), x))
            total += np.abs(model(moved[0], moved[1], **params).astype(np.float64) - base)
    return total


#: Relative agreement expected of a float32 evaluation with a float64 one (issue 21 §5,
#: "≈1e-5"): a shader of ~100 operations, each rounded to 2⁻²⁴ ≈ 6e-8, worst case summed.
RTOL = 1e-5
#: Relative tolerance for files taking acos/asin of their cosines (oren_nayar.brdf): Mesa
#: approximates them to 1.6e-4 / 3.9e-4 absolute (test_mesa_builtin_accuracy); θ enters
#: the Oren-Nayar terms through sin, tan and products, measured ≤ 4.6e-4 relative in f
#: (sigma ≤ 30°, θ ≤ 87°) against NumPy's float64 and against brdfkit.
ACOS_RTOL = 1e-3

#: Multiple of :func:`perturbation_spread` added to the bound: rounding the directions to
#: float32 moves the value by at most about half a spread, the intermediate roundings of
#: O(1) quantities (dot products, H, R) by a few ulps of the same quantities; 8 leaves a
#: margin. Where the shader
#: is ill-conditioned (a pow with a large exponent, exp of a large argument, a sharp lobe)
#: the spread is what float32 precision means there; elsewhere it is ~1e-7 relative.
SPREAD_FACTOR = 8.0
#: Absolute floor: float32's smallest normal number (values below are subnormal on a GPU).
ATOL = 1.2e-38


def float32_bound(a, b, spread, *, rtol: float = RTOL) -> np.ndarray:
    """The allowed |a − b| of a float64 value *a* and its float32 (Mesa) value *b*."""
    a, b = np.asarray(a, dtype=np.float64), np.asarray(b, dtype=np.float64)
    return rtol * np.maximum(np.abs(a), np.abs(b)) + SPREAD_FACTOR * np.asarray(spread) + ATOL


def worst_ratio(a, b, spread, *, rtol: float = RTOL) -> float:
    """max |a − b| / :func:`float32_bound` (≤ 1: agreement to float32 precision); NaN
    anywhere in either gives inf (compare NaN positions separately)."""
    a, b = np.asarray(a, dtype=np.float64), np.asarray(b, dtype=np.float64)
    if not (np.all(np.isfinite(a)) and np.all(np.isfinite(b))):
        return math.inf
    return float(np.max(np.abs(a - b) / float32_bound(a, b, spread, rtol=rtol), initial=0.0))
