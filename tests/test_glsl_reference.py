"""The real-GLSL reference itself is right (tests/glsl_reference.py, issue 21 §5).

Before the ``.brdf`` corpus can judge brdfkit's translator, the harness that runs it in
Mesa must be shown to compute what the files say: each file here, compiled by Mesa's GLSL
compiler and run by llvmpipe, against an independent float64 evaluation of the same
formula — a NumPy closed form written in this test, or brdfkit's registered model for
the files written from papers (modified Phong, Walter GGX) — to float32 precision
(glsl_reference.float32_bound: 1e-5 relative plus 8 one-ulp perturbation spreads).

It also records what Mesa's compiler accepts and rejects among the constructs of the
corpus (the rule the translator follows for a user function with a built-in's name; the
bad files that are valid GLSL and those that are not), and that a harness parse of a
malformed file names the file and the line.
"""

from __future__ import annotations

import math
import re

import glsl_reference as ref
import numpy as np
import pytest
from glsl_reference import CORPUS, GlslBRDF

import brdfkit

N_PAIRS = 4000


@pytest.fixture(scope="module")
def mesa():
    """Mesa's headless context; the test is skipped, saying why, when there is none."""
    return ref.require_mesa()


def _pairs(rng, n=N_PAIRS):
    return (ref.as_float32(ref.random_directions(rng, n)),
            ref.as_float32(ref.random_directions(rng, n)))


def _check(model, wi, wo, expected, rng, *, rtol=ref.RTOL, **params):
    """Mesa's value of *model* agrees with the float64 *expected* to float32 precision."""
    got = model(wi, wo, **params)
    assert got.dtype == np.float32 and got.shape == (wi.shape[0], 3)
    expected = np.broadcast_to(np.asarray(expected, dtype=np.float64).reshape(len(wi), -1),
                               got.shape)
    spread = ref.perturbation_spread(model, wi, wo, **params)
    ratio = ref.worst_ratio(expected, got, spread, rtol=rtol)
    assert ratio <= 1.0, f"{model.path.name} {params}: worst |diff|/bound = {ratio:.3g}"
    return got


def _dot(a, b):
    return np.sum(a * b, axis=-1)


def _mirror(w):
    """The mirror of w about N = +z."""
    return w * np.array([-1.0, -1.0, 1.0])


# --------------------------------------------------------------------------- the parser
def test_read_brdf_parameters_and_sections():
    src = ref.read_brdf(CORPUS / "oren_nayar.brdf")
    assert [(p.kind, p.name) for p in src.params] == [
        ("float", "sigma"), ("bool", "qualitative"), ("color", "albedo")]
    assert src.param("sigma") == ref.Parameter("float", "sigma", 20.0, 0.0, 60.0)
    assert src.param("qualitative").default is False
    assert src.param("albedo").default == (0.75, 0.75, 0.75)
    lines = (CORPUS / "oren_nayar.brdf").read_text().splitlines()
    # shader_line is the file line of the shader's first line (1-based)
    assert lines[src.shader_line - 2].strip() == "::begin shader"
    assert "vec3 BRDF(" in src.shader and "::end" not in src.shader


def test_read_brdf_malformed_parameter_names_file_and_line():
    path = CORPUS / "bad" / "malformed_parameter.brdf"
    with pytest.raises(ValueError, match=r"malformed_parameter\.brdf:7: float ks"):
        ref.read_brdf(path)


def test_uniforms_prepended_as_brdf_explorer_does(tmp_path):
    # loadShaderFromFile: every float, then every bool, then every colour, each in file order
    path = tmp_path / "order.brdf"
    path.write_text("analytic\n::begin parameters\ncolor c1 1 1 1\nbool b1 1\nfloat f1 0 1 0\n"
                    "color c2 0 0 0\nfloat f2 0 1 1\nbool b2 0\n::end parameters\n"
                    "::begin shader\nvec3 BRDF(vec3 L, vec3 V, vec3 N, vec3 X, vec3 Y)\n"
                    "{ return b1 && !b2 ? f1 * c1 + f2 * c2 : vec3(0); }\n::end shader\n")
    text = ref.compute_source(ref.read_brdf(path))
    declared = [line for line in text.splitlines()
                if line.startswith("uniform ") and "brdfref_" not in line]
    assert declared == ["uniform float f1;", "uniform float f2;", "uniform bool b1;",
                        "uniform bool b2;", "uniform vec3 c1;", "uniform vec3 c2;"]


# --------------------------------------------------------------------------- values
def test_lambert_file_is_rho_over_pi(mesa, rng):
    model = GlslBRDF(CORPUS / "lambert.brdf")
    wi, wo = _pairs(rng, 500)
    for rho in (0.0, 0.25, 0.8, 1.0):
        rho32 = float(np.float32(rho))
        got = _check(model, wi, wo, np.full(len(wi), rho32 / math.pi), rng, rho=rho32)
        assert np.all(got == got[0, 0])  # a constant: exactly the same value everywhere
    # the default (file) value is used when a parameter is not given
    assert model(wi[:1], wo[:1])[0, 0] == pytest.approx(0.8 / math.pi, rel=1e-7)


def test_modified_phong_file_is_the_registered_model(mesa, rng):
    # reference: brdfkit's registered modified-phong (float64, its own kernel), and the
    # closed form in NumPy; the exponent range keeps pow's amplification n·δx/x of
    # float32's rounding of R·V moderate (the spread term covers the rest)
    model = GlslBRDF(CORPUS / "modified_phong.brdf")
    wi, wo = _pairs(rng)
    # n > 0: GLSL's pow(x, y) is undefined for x = 0, y <= 0 (Mesa's llvmpipe gives
    # pow(0, 0) = 0 at run time, 1 when it folds constants); brdfkit's 0^0 is 1
    # n <= 20: Mesa's pow is exp2(y log2 x), relative error ~|y|·1.3e-7 (measured 2.5e-5 at
    # y = 200, test_mesa_builtin_accuracy), which the direction perturbations do not see
    for rho_d, rho_s, n in ((0.2, 0.5, 20.0), (0.0, 1.0, 3.0), (0.7, 0.3, 0.5),
                            (0.05, 0.9, 12.5)):
        p = {"rho_d": rho_d, "rho_s": rho_s, "n": n}
        reg = brdfkit.model("modified-phong", **p).eval(wi, wo)
        cos_r = np.maximum(0.0, _dot(_mirror(wi), wo))
        closed = rho_d / math.pi + rho_s * (n + 2) / (2 * math.pi) * cos_r ** n
        np.testing.assert_allclose(reg, closed, rtol=1e-12)
        _check(model, wi, wo, reg, rng, **p)


def test_walter_ggx_file_is_the_registered_model(mesa, rng):
    # reference: brdfkit's registered microfacet (distribution=ggx, no Fresnel), whose
    # kernel writes D and G1 differently (from s = wi + wo, G1/cos)
    model = GlslBRDF(CORPUS / "walter_ggx.brdf")
    wi, wo = _pairs(rng)
    for alpha, rho_s in ((0.1, 1.0), (0.05, 0.5), (0.5, 0.8), (2.0, 1.0)):
        reg = brdfkit.model("microfacet", distribution="ggx", alpha=alpha,
                            rho_s=rho_s).eval(wi, wo)
        _check(model, wi, wo, reg, rng, alpha=alpha, rho_s=rho_s)


def _ward(wi, wo, ax, ay, rho_d, rho_s):
    h = wi + wo
    h = h / np.linalg.norm(h, axis=-1, keepdims=True)
    e = -((h[:, 0] / ax) ** 2 + (h[:, 1] / ay) ** 2) / h[:, 2] ** 2
    return rho_d / math.pi + rho_s * np.exp(e) / (4 * math.pi * ax * ay
                                                  * np.sqrt(wi[:, 2] * wo[:, 2]))


def test_anisotropic_ward_file_reads_the_tangents(mesa, rng):
    model = GlslBRDF(CORPUS / "ward_anisotropic.brdf")
    wi, wo = _pairs(rng)
    p = {"alpha_x": 0.4, "alpha_y": 0.15, "rho_d": 0.1, "rho_s": 0.6}
    got = _check(model, wi, wo, _ward(wi, wo, 0.4, 0.15, 0.1, 0.6), rng, **p)
    # rotating both directions by 90° about N swaps the roles of X and Y: not the same
    rot = np.array([[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]])
    turned = model(wi @ rot.T, wo @ rot.T, **p)
    assert np.max(np.abs(turned - got) / got) > 0.5


ACOS_RTOL = ref.ACOS_RTOL  # Mesa's coarse acos/asin (see glsl_reference)


def test_oren_nayar_file_bool_and_colour_uniforms(mesa, rng):
    # qualitative=1: A + B max(0, cos Δφ) sin α tan β (NumPy closed form); qualitative=0
    # is the full model: different values (the bool uniform reaches the shader both ways)
    model = GlslBRDF(CORPUS / "oren_nayar.brdf")
    wi, wo = _pairs(rng)
    sigma = math.radians(30.0)
    s2 = sigma * sigma
    ti, to = np.arccos(wi[:, 2]), np.arccos(wo[:, 2])
    alpha, beta = np.maximum(ti, to), np.minimum(ti, to)
    cos_phi = np.cos(np.arctan2(wi[:, 1], wi[:, 0]) - np.arctan2(wo[:, 1], wo[:, 0]))
    value = (1 - 0.5 * s2 / (s2 + 0.33)) + 0.45 * s2 / (s2 + 0.09) * np.maximum(0, cos_phi) \
        * np.sin(alpha) * np.tan(beta)
    colour = np.array([0.25, 0.5, 1.0])
    qual = _check(model, wi, wo, colour / math.pi * value[:, None], rng, rtol=ACOS_RTOL,
                  sigma=30.0, qualitative=True, albedo=colour)
    full = model(wi, wo, sigma=30.0, qualitative=False, albedo=colour)
    assert np.max(np.abs(full - qual) / qual) > 1e-2
    # the colour uniform scales the channels: exactly proportional (the same float32 path)
    np.testing.assert_allclose(qual[:, 0] * 2, qual[:, 1], rtol=1e-6)


def test_builtins_scalar_file_has_glsl_semantics(mesa, rng):
    # NumPy transcription of builtins_scalar.brdf. GLSL's mod is x − y·floor(x/y) (NumPy's
    # np.mod for y > 0, not C's fmod); atan(y, x) is NumPy's arctan2; sign(0) = 0
    model = GlslBRDF(CORPUS / "builtins_scalar.brdf")
    wi, wo = _pairs(rng)
    e, s = 2.5, 1.5
    cl, cv, u = wi[:, 2], wo[:, 2], _dot(wi, wo)
    w = 0.5 + 0.5 * u
    pi = math.pi
    a = (cl ** (1.5 + e) + np.exp(-2 * s * w) + np.log(2 + u) + np.sqrt(cl)
         + 1 / np.sqrt(1 + cv) + np.sin(w) + np.cos(w) + 0.01 * np.tan(0.5 * np.arccos(cl))
         + 0.01 * (np.arcsin(np.clip(0.9 * u, -1, 1)) + 1.2) + np.arctan(3 * u) + 1.3
         + np.arctan2(wi[:, 1], wi[:, 0] + 2) + 1.0)
    b = (np.abs(wi[:, 0] - wo[:, 1]) + np.sign(wi[:, 0] - wo[:, 0]) * (wi[:, 0] - wo[:, 0])
         + np.floor(3 * s * w) * np.sin(pi * 3 * s * w) ** 2
         + (2.5 * w - np.floor(2.5 * w)) * np.sin(pi * 2.5 * w) ** 2
         + np.mod(-1.5 * w - 0.1, 1.25) * np.sin(pi * (1.5 * w + 0.1) / 1.25) ** 2
         + (cl >= 0.3) * (cl - 0.3) + (0.6 >= cv) * (0.6 - cv))
    t = np.clip((w - 0.2) / 0.6, 0, 1)
    c = (np.minimum(cl, cv) + np.maximum(cl, cv) + np.clip(2 * u, 0, 1) + cl + (cv - cl) * w
         + t * t * (3 - 2 * t) + np.radians(30 * w) + np.degrees(0.01 * cl) + cl * cv
         + np.abs(cv) + 1 / pi)
    _check(model, wi, wo, 0.1 * np.stack([a, b, c], axis=-1), rng, e=e, s=s)


def test_glsl_mod_is_floored_not_truncated(mesa, tmp_path):
    # the reason builtins_scalar.brdf takes mod of negative numbers: C's fmod would differ
    path = tmp_path / "mod.brdf"
    path.write_text("analytic\n::begin parameters\nfloat x -5 5 -1.5\n::end parameters\n"
                    "::begin shader\nvec3 BRDF(vec3 L, vec3 V, vec3 N, vec3 X, vec3 Y)\n"
                    "{ return vec3(mod(x, 1.25), fract(x), sign(x - x)); }\n::end shader\n")
    got = GlslBRDF(path)(np.array([[0.0, 0.0, 1.0]]), np.array([[0.0, 0.0, 1.0]]))[0]
    assert got.tolist() == pytest.approx([1.0, 0.5, 0.0])  # fmod(-1.5, 1.25) = -0.25


# --------------------------------------------------------------------------- Mesa's rules
def test_user_function_hides_the_builtin_of_that_name(mesa, rng):
    # shadowed_reflect.brdf defines reflect(I, N) = 2(N.I)N − I before its call: Mesa calls
    # the file's function (the mirror of L), so the lobe is about the mirror of L
    model = GlslBRDF(CORPUS / "shadowed_reflect.brdf")
    wi, wo = _pairs(rng)
    kd, ks, sh = 0.3, 0.6, 10.0
    c = np.maximum(0.0, _dot(_mirror(wi), wo))
    _check(model, wi, wo, kd / math.pi + ks * (sh + 2) / (2 * math.pi) * c ** sh, rng,
           kd=kd, ks=ks, shininess=sh)


def test_call_before_the_user_declaration_is_the_builtin(mesa, rng):
    # shadowing_order.brdf: a call compiled before the file declares its reflect resolves
    # to GLSL's built-in; the calls after the declaration to the file's (opposite sign)
    model = GlslBRDF(CORPUS / "shadowing_order.brdf")
    wi, wo = _pairs(rng)
    m = _dot(_mirror(wi), wo)
    _check(model, wi, wo, np.stack([2 + m, 2 - m, np.full_like(m, 2.0)], axis=-1), rng, t=0.7)


def test_mesa_hides_every_overload_of_a_shadowed_builtin(mesa, tmp_path):
    # a user reflect(vec3, vec3) hides reflect(vec2, vec2) too (no overload resolution
    # against the built-ins once the name is the file's): Mesa rejects the vec2 call
    path = tmp_path / "overload.brdf"
    path.write_text("analytic\n::begin parameters\n::end parameters\n::begin shader\n"
                    "vec3 reflect(vec3 I, vec3 N) { return I; }\n"
                    "vec3 BRDF(vec3 L, vec3 V, vec3 N, vec3 X, vec3 Y)\n"
                    "{ return vec3(reflect(vec2(1.0), vec2(0.0, 1.0)), 0.0); }\n"
                    "::end shader\n")
    errors = ref.mesa_errors(path)
    assert errors and errors[0][:2] == (7, 15)
    assert "no matching function for call to `reflect(vec2, vec2)'" in errors[0][2]


@pytest.mark.parametrize("name, line, col, words", [
    ("syntax_error", 15, 26, "syntax error"),
    ("unknown_identifier", 14, 24, "`roughnes' undeclared"),
    ("recursion", 0, 0, "static recursion"),  # a link-time error: no position
])
def test_mesa_rejects(mesa, name, line, col, words):
    errors = ref.mesa_errors(CORPUS / "bad" / f"{name}.brdf")
    assert errors[0][:2] == (line, col) and words in errors[0][2]


def test_mesa_rejects_a_file_without_brdf():
    errors = ref.mesa_errors(CORPUS / "bad" / "no_brdf_function.brdf")
    assert any("no function with name 'BRDF'" in m for _, _, m in errors)


@pytest.mark.parametrize("name", ["texture_lookup", "data_dependent_loop", "out_parameter"])
def test_mesa_accepts_valid_glsl_that_brdfkit_does_not_support(mesa, name):
    # valid GLSL: brdfkit rejects them as unsupported constructs, not as GLSL errors
    assert ref.mesa_errors(CORPUS / "bad" / f"{name}.brdf") == []


def test_normalize_of_zero_is_nan_in_mesa(mesa):
    # nan_normalize.brdf at normal incidence: normalize(N x N) = normalize(0) → NaN
    model = GlslBRDF(CORPUS / "nan_normalize.brdf")
    wi = np.array([[0.0, 0.0, 1.0], [0.6, 0.0, 0.8]])
    wo = np.array([[0.0, 0.6, 0.8], [0.0, 0.6, 0.8]])
    got = model(wi, wo)
    assert np.all(np.isnan(got[0])) and np.all(np.isfinite(got[1]))


def test_every_good_corpus_file_compiles_in_mesa(mesa):
    files = sorted(CORPUS.glob("*.brdf"))
    assert len(files) >= 12
    for path in files:
        assert ref.mesa_errors(path) == [], path.name


# --------------------------------------------------------------------------- Mesa's accuracy
def _expression(tmp_path, expr):
    path = tmp_path / "expr.brdf"
    path.write_text("analytic\n::begin parameters\n::end parameters\n::begin shader\n"
                    "vec3 BRDF(vec3 L, vec3 V, vec3 N, vec3 X, vec3 Y)\n"
                    f"{{ return vec3({expr}); }}\n::end shader\n")
    return GlslBRDF(path)


# (GLSL expression of x = L.x, NumPy function, x range, kind of error, bound): measured on
# llvmpipe (LLVM 15, Mesa 22.3) over 200 001 float32 x, bound = the measured maximum with a
# margin of ~1.3-2. GLSL leaves most of these accuracies to the implementation.
_ACCURACY = [
    ("acos(x)", np.arccos, (-1.0, 1.0), "abs", 2.5e-4),      # measured 1.56e-4
    ("asin(x)", np.arcsin, (-1.0, 1.0), "abs", 5e-4),        # measured 3.90e-4
    ("atan(x)", np.arctan, (-10.0, 10.0), "abs", 5e-6),      # measured 3.32e-6
    ("sin(x)", np.sin, (-3.2, 3.2), "abs", 1.5e-7),          # measured 6.7e-8
    ("cos(x)", np.cos, (-3.2, 3.2), "abs", 1.5e-7),          # measured 7.3e-8
    ("tan(x)", np.tan, (-1.4, 1.4), "rel", 4e-7),            # measured 1.8e-7
    ("exp(x)", np.exp, (-20.0, 5.0), "rel", 2e-6),           # measured 1.16e-6
    ("sqrt(x)", np.sqrt, (0.0, 4.0), "rel", 1.2e-7),         # measured 5.9e-8
    ("inversesqrt(x)", lambda x: 1 / np.sqrt(x), (0.01, 4.0), "rel", 2e-7),  # 8.9e-8
    ("pow(x, 20.0)", lambda x: x ** 20, (0.5, 1.0), "rel", 5e-6),    # ~|y|·1.3e-7
    ("pow(x, 200.0)", lambda x: x ** 200, (0.9, 1.0), "rel", 4e-5),  # measured 2.54e-5
]


@pytest.mark.parametrize("expr, fn, bounds, kind, bound", _ACCURACY,
                         ids=[a[0] for a in _ACCURACY])
def test_mesa_builtin_accuracy(mesa, tmp_path, expr, fn, bounds, kind, bound):
    # what "float32 precision" of the reference means per built-in: the tolerances of the
    # comparisons (ACOS_RTOL, the asin/acos weights of builtins_*.brdf, the exponent
    # ranges of the pow files) rest on these measurements
    x = np.linspace(*bounds, 200_001).astype(np.float32).astype(np.float64)
    wi = np.stack([x, np.zeros_like(x), np.zeros_like(x)], axis=-1)
    got = _expression(tmp_path, expr.replace("(x", "(L.x"))(wi, wi)[:, 0].astype(np.float64)
    exact = fn(x)
    err = np.abs(got - exact)
    if kind == "rel":  # at exact zeros (sin, tan, sqrt at 0) the error must be 0 too
        err = np.where(exact == 0.0, np.where(err == 0.0, 0.0, np.inf), err)
        err = err / np.where(exact == 0.0, 1.0, np.abs(exact))
    worst = float(np.max(err))
    assert worst <= bound, f"{expr}: {kind} error {worst:.3g} > {bound:.3g}"


# --------------------------------------------------------------------------- the corpus
BUILTINS = ("dot cross normalize length reflect pow exp log sqrt inversesqrt sin cos tan asin "
            "acos atan abs sign floor fract mod min max clamp mix step smoothstep radians "
            "degrees").split()

# (construct of issue 21 §1, a pattern that shows it in a shader): a guard that the corpus
# keeps covering every construct the translator must handle (the files are compared with
# Mesa in test_brdf_files)
CONSTRUCTS = [
    ("int local", r"\bint \w+ ="), ("bool local", r"\bbool \w+ ="),
    ("vec2/vec3/vec4", r"\bvec2 \w+.*\n(.|\n)*\bvec4 \w+"),
    ("swizzle read", r"\.[xyzw]{2,4}\b|\.bgr\b"), ("swizzle write", r"\.\w{2} = "),
    ("component index", r"\w\[\d\]"), ("vec3(0)", r"vec3\(0\)"),
    ("vec4(v3, 1.0)", r"vec4\(\w+, 1\.0\)"), ("vec2(v4)", r"vec2\(hom\)"),
    ("implicit int -> float", r"1/PI|clamp\(1-u, 0, 1\)"),
    ("const global", r"^const (float|vec3|int) ", ), ("+=", r"\+= "), ("-=", r"-= "),
    ("*=", r"\*= "), ("/=", r"/= "), ("else if", r"else if"), ("early return", r"return .*;\n\s+}"),
    ("ternary", r" \? "), ("&&", r"&&"), ("||", r"\|\|"), ("!", r"\(!\w"),
    ("for loop", r"for \(int i = 1; i <= 5; i\+\+\)"), ("break", r"\bbreak;"),
    ("user function shadowing a built-in", r"^vec3 reflect\(vec3 I, vec3 N\)"),
    ("a prototype", r"\);\s+// from here on"),
]


def _shaders() -> str:
    return "\n".join(ref.read_brdf(p).shader for p in sorted(CORPUS.glob("*.brdf")))


@pytest.mark.parametrize("name", BUILTINS)
def test_corpus_calls_every_builtin(name):
    assert re.search(rf"(^|[^\w.]){name}\(", _shaders(), re.MULTILINE), name


@pytest.mark.parametrize("what, pattern", CONSTRUCTS, ids=[c[0] for c in CONSTRUCTS])
def test_corpus_has_every_construct(what, pattern):
    assert re.search(pattern, _shaders(), re.MULTILINE), what


def test_corpus_parameter_blocks_have_comments_blank_lines_bools_and_colours():
    texts = {p.name: p.read_text() for p in CORPUS.glob("*.brdf")}
    block = {n: t.split("::begin parameters")[1].split("::end parameters")[0]
             for n, t in texts.items()}
    assert any("\n#" in b for b in block.values())  # a comment inside a parameter block
    kinds = {p.kind for n in texts for p in ref.read_brdf(CORPUS / n).params}
    assert kinds == {"float", "bool", "color"}


def test_isfunc_section_runs_in_mesa(mesa, rng):
    # lambert_sampled.brdf's sampleBRDF (BRDF Explorer's isFunc signature, out parameters):
    # cosine-weighted directions, pdf = cos θ/π, value f cos θ/pdf = albedo (closed forms)
    model = GlslBRDF(CORPUS / "lambert_sampled.brdf")
    assert model.source.is_func and model.source.is_func_line > model.source.shader_line
    u = rng.random((2000, 2))
    value, wi, pdf = model.sample(u, albedo=[0.25, 0.5, 1.0])
    np.testing.assert_allclose(value, np.broadcast_to([0.25, 0.5, 1.0], value.shape), rtol=1e-7)
    np.testing.assert_allclose(np.linalg.norm(wi, axis=1), 1.0, rtol=1e-6)
    np.testing.assert_allclose(wi[:, 2], np.sqrt(1.0 - u[:, 0]), rtol=1e-5, atol=1e-6)
    np.testing.assert_allclose(pdf, wi[:, 2] / math.pi, rtol=1e-5, atol=1e-7)
    with pytest.raises(ValueError, match="no isFunc"):
        GlslBRDF(CORPUS / "lambert.brdf").sample(u)


# --------------------------------------------------------------------------- skipping
def test_skip_reason_names_what_is_missing(monkeypatch):
    monkeypatch.setattr(ref, "_context", lambda: ImportError("No module named 'moderngl'"))
    reason = ref.unavailable_reason()
    assert "moderngl is not installed" in reason and "setup.sh --test" in reason
    monkeypatch.setattr(ref, "_context", lambda: RuntimeError("eglInitialize failed"))
    reason = ref.unavailable_reason()
    assert "EGL" in reason and "eglInitialize failed" in reason
    assert "libegl-mesa0 libgl1-mesa-dri libegl1" in reason
    with pytest.raises(pytest.skip.Exception, match="eglInitialize failed"):
        ref.require_mesa()


def test_mesa_is_used_where_it_is_installed():
    # the reference tests may skip only when a part is missing: on a machine with the
    # Debian packages and moderngl, there must be a context (no silent skip)
    import importlib.util
    import shutil
    import subprocess

    if shutil.which("dpkg-query") is None:
        pytest.skip("not a Debian system: cannot tell whether the Mesa packages are installed")
    packages = ("libegl1", "libegl-mesa0", "libgl1-mesa-dri")
    status = [subprocess.run(["dpkg-query", "-W", "-f=${Status}", p], capture_output=True,
                             text=True).stdout for p in packages]
    if not all(s.endswith("ok installed") for s in status) \
            or importlib.util.find_spec("moderngl") is None:
        pytest.skip("the Mesa packages or moderngl are not installed here")
    assert ref.unavailable_reason() is None
    assert "llvmpipe" in ref.renderer() or "Mesa" in ref._context().info["GL_VERSION"]
