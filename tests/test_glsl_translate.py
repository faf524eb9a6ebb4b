"""The GLSL translator (brdfkit.glsl) and the .brdf reader (brdfkit.user.brdf_file).

Reference values are GLSL's meaning written out by hand in NumPy in each test (the
GLSL 4.60 specification's definitions: §5.9 integer division truncates, §6.1 a user
function hides the built-ins of its name, §8 the built-ins), evaluated at the same
directions; agreement with real GLSL run by Mesa is tests/test_brdf_files.py's. The
kernels are called through their Python code (``kernel.py_func``: the very source Numba
compiles), so these tests compile nothing.
"""

import math
import textwrap

import numpy as np
import pytest

from brdfkit.errors import BrdfkitError, DataFileError
from brdfkit.glsl import Uniform, translate
from brdfkit.user.brdf_file import definition, read_brdf_file

PI = math.pi
L0 = (0.3, -0.2, math.sqrt(1 - 0.13))  # a generic pair in the upper hemisphere
V0 = (-0.4, 0.5, math.sqrt(1 - 0.41))


def kernel_of(shader: str, uniforms=(), path="t.brdf"):
    tr = translate(textwrap.dedent(shader), list(uniforms), path=path, first_line=10)
    ns: dict = {}
    exec(compile(tr.source, path, "exec"), ns)
    return tr, ns["kernel"].py_func


def value(shader, p=(), L=L0, V=V0, uniforms=()):
    tr, k = kernel_of(shader, uniforms)
    row = list(p) + [0.0] * 4
    if tr.grey:
        return k(*L, *V, row)
    return [k(*L, *V, row[:tr.channel_offset] + [float(c)]) for c in range(3)]


def brdf(body: str, helpers: str = "") -> str:
    return helpers + "\nvec3 BRDF(vec3 L, vec3 V, vec3 N, vec3 X, vec3 Y) {\n" + body + "\n}\n"


# --------------------------------------------------------------------------- semantics
def test_integer_division_truncates_and_int_promotes_to_float():
    # GLSL §5.9: int / int is an int (truncated toward 0); 1/2.0 promotes to float
    assert value(brdf("return vec3(float(7/2) + float(-7/2));")) == 3.0 - 3.0
    assert value(brdf("return vec3(1/2.0 + 3);")) == 3.5


def test_user_function_hides_the_builtin_of_its_name():
    # GLSL >= 1.30 (§6.1 scoping): the file's own reflect (opposite sign) is the one called
    helpers = "vec3 reflect(vec3 I, vec3 N) { return 2.0*dot(N, I)*N - I; }"
    got = value(brdf("return vec3(reflect(L, N).z);", helpers))
    assert got == pytest.approx(2 * L0[2] * 1.0 - L0[2])
    got = value(brdf("return vec3(reflect(L, N).x);", helpers))
    assert got == pytest.approx(-L0[0])  # the built-in would give +L.x


def test_swizzles_indexing_constructors_and_component_writes():
    body = """
        vec4 a = vec4(L, 1);            // vec4(vec3, float)
        vec2 b = vec2(a);               // the first two components
        vec3 c = vec3(0);               // one scalar fills all
        c.zx = b;                       // a swizzle written
        c[1] = a.w + V.y;               // an index written
        return vec3(c.x * 100.0 + c.y * 10.0 + c.z);
    """
    ref = L0[1] * 100 + (1 + V0[1]) * 10 + L0[0]
    assert value(brdf(body)) == pytest.approx(ref)


def test_early_returns_nested_if_else_and_reassignment():
    body = """
        float x = dot(L, V);
        if (x > 0.0) {
            if (L.z > 0.9) return vec3(1.0);
            x *= 2.0;
        } else if (x > -0.5) {
            x -= 1.0;
        } else {
            return vec3(-1.0);
        }
        x += 10.0;
        return vec3(x);
    """

    def ref(L, V):
        x = float(np.dot(L, V))
        if x > 0:
            if L[2] > 0.9:
                return 1.0
            x *= 2
        elif x > -0.5:
            x -= 1
        else:
            return -1.0
        return x + 10

    rng = np.random.default_rng(3)
    tr, k = kernel_of(brdf(body))
    for _ in range(200):
        L, V = rng.normal(size=3), rng.normal(size=3)
        L[2], V[2] = abs(L[2]), abs(V[2])
        L, V = L / np.linalg.norm(L), V / np.linalg.norm(V)
        assert k(*L, *V, [0.0]) == pytest.approx(ref(L, V)), (L, V)


def test_loops_unrolled_with_data_dependent_break_and_continue():
    body = """
        float s = 0.0;
        for (int i = 0; i < 6; ++i) {
            if (i == 1) continue;
            s += float(i) * L.z;
            if (s > V.z * 3.0) break;
        }
        int j = 0;
        while (j < 3) { s += 0.5; j++; }
        return vec3(s);
    """

    def ref(lz, vz):
        s = 0.0
        for i in range(6):
            if i == 1:
                continue
            s += i * lz
            if s > vz * 3:
                break
        return s + 1.5

    for lz, vz in ((0.9, 0.2), (0.2, 0.9), (0.5, 0.5)):
        L = (math.sqrt(1 - lz * lz), 0.0, lz)
        V = (0.0, math.sqrt(1 - vz * vz), vz)
        assert value(brdf(body), L=L, V=V) == pytest.approx(ref(lz, vz))


def test_ternary_logic_and_builtins_against_numpy():
    body = """
        float a = clamp(dot(L, V), 0, 1);
        float b = mix(0.25, 2.0, smoothstep(0.1, 0.9, L.z)) + step(0.5, V.z);
        float c = mod(7.5, 2.0) + fract(-1.25) + sign(-3.0) + abs(-2.0);
        float d = atan(L.y, L.x) + atan(0.5) + asin(0.5) + acos(0.25) + tan(0.3);
        float e = pow(2.0, 0.5) * inversesqrt(4.0) + exp(0.5) * log(3.0) + sqrt(2.0);
        float f = radians(90.0) + degrees(1.0) + min(1, 2) + max(1.0, 2);
        bool g = (a > 0.1 && !(b < 0.0)) || V.z < 0.0;
        vec3 h = g ? vec3(1, 2, 3) : vec3(0);
        return vec3(a + b + c + d + e + f + h.y + length(vec2(3, 4)) + distance(L, L));
    """
    L, V = np.array(L0), np.array(V0)
    a = min(max(L @ V, 0), 1)
    t = min(max((L[2] - 0.1) / 0.8, 0), 1)
    b = 0.25 * (1 - t * t * (3 - 2 * t)) + 2.0 * t * t * (3 - 2 * t) + (V[2] >= 0.5)
    c = (7.5 - 2 * math.floor(7.5 / 2)) + (-1.25 - math.floor(-1.25)) - 1 + 2
    d = math.atan2(L[1], L[0]) + math.atan(0.5) + math.asin(0.5) + math.acos(0.25) + \
        math.tan(0.3)
    e = 2 ** 0.5 / 2 + math.exp(0.5) * math.log(3) + math.sqrt(2)
    f = PI / 2 + 180 / PI + 1 + 2
    g = (a > 0.1 and not b < 0) or V[2] < 0
    ref = a + b + c + d + e + f + (2 if g else 0) + 5 + 0
    assert value(brdf(body)) == pytest.approx(ref, rel=1e-13)


def test_const_globals_helpers_calling_helpers_and_overloads():
    helpers = """
        const float K = 2.0;
        const vec3 W = vec3(1, 2, 3);
        float sq(float x) { return x * x; }
        vec3 sq(vec3 v) { return v * v; }
        float quad(float x) { return sq(sq(x)) * K; }
    """
    got = value(brdf("return vec3(quad(L.z) + dot(sq(W), vec3(1)));", helpers))
    assert got == pytest.approx(L0[2] ** 4 * 2 + 14)


def test_uniforms_colour_channels_and_grey():
    shader = brdf("return base * rho + vec3(k ? 1.0 : 0.0);")
    u = [Uniform("rho", "float", 0), Uniform("k", "bool", value=True),
         Uniform("base", "vec3", 1)]
    tr, _ = kernel_of(shader, u)
    assert not tr.grey and tr.channel_offset == 4
    assert value(shader, p=[0.5, 0.2, 0.4, 0.8], uniforms=u) == pytest.approx(
        [1.1, 1.2, 1.4])
    tr, _ = kernel_of(brdf("return vec3(rho);"), [Uniform("rho", "float", 0)])
    assert tr.grey


def compiled(shader):
    tr = translate(shader, [], path="t.brdf")
    ns: dict = {}
    exec(compile(tr.source, "t.brdf", "exec"), ns)
    return ns["kernel"]  # the Numba version (IEEE division: Python's raises)


def test_zero_below_the_horizon_and_nan_kept():
    _, k = kernel_of(brdf("return vec3(1.0);"))
    assert k(*L0, 0.3, 0.0, -math.sqrt(0.91), [0.0]) == 0.0  # V below: 0 whatever the shader
    assert k(0.0, 0.0, 1.0, 0.0, 0.0, 1.0, [0.0]) == 1.0
    # normalize of a zero vector (L = V mirrored about N: L − reflect(V) = 0 at L = R(V))
    k = compiled(brdf("return vec3(normalize(L - reflect(-V, N)).z);"))
    mirror = (-V0[0], -V0[1], V0[2])
    assert math.isnan(k(*mirror, *V0, np.zeros(1)))


# --------------------------------------------------------------------------- isotropy
@pytest.mark.parametrize("expr", [
    "dot(N, normalize(L + V))",
    "dot(normalize(V - N*dot(N, V)), normalize(L - N*dot(N, L)))",  # cos φ (Oren–Nayar)
    "dot(reflect(-L, N), V) * L.z",
    "length(cross(L, V))",  # |L × V|: a pseudo-vector's length is even
    "dot(cross(N, L), cross(N, V))",  # pseudo · pseudo
])
def test_isotropic_formulas_detected(expr):
    tr, _ = kernel_of(brdf(f"return vec3({expr});"))
    assert tr.isotropic, tr.isotropy_reason


@pytest.mark.parametrize("expr, why", [
    ("dot(normalize(L + V), X)", "tangent X"),
    ("L.x * V.z", "component .x"),
    ("dot(N, cross(L, V))", "changes sign"),  # mirror-odd: f(φ) ≠ f(−φ)
    ("(L * V).z", "component-wise"),
])
def test_anisotropic_formulas_detected_with_a_located_reason(expr, why):
    tr, _ = kernel_of(brdf(f"float q = 1.0;\n    return vec3({expr});"), path="a.brdf")
    assert not tr.isotropic
    assert why in tr.isotropy_reason and "a.brdf:" in tr.isotropy_reason


def test_isotropy_detection_is_never_wrong_when_it_says_isotropic():
    # the claim checked numerically: rotating both directions about N and mirroring them
    # in the xz-plane leaves the value unchanged
    rng = np.random.default_rng(7)
    for expr in ("dot(N, normalize(L + V))",
                 "dot(normalize(V - N*dot(N, V)), normalize(L - N*dot(N, L)))",
                 "dot(cross(N, L), cross(N, V))"):
        tr, k = kernel_of(brdf(f"return vec3({expr});"))
        assert tr.isotropic
        for _ in range(50):
            L, V = rng.normal(size=3), rng.normal(size=3)
            L[2], V[2] = abs(L[2]), abs(V[2])
            L, V = L / np.linalg.norm(L), V / np.linalg.norm(V)
            a = rng.uniform(0, 2 * PI)
            R = np.array([[math.cos(a), -math.sin(a), 0], [math.sin(a), math.cos(a), 0],
                          [0, 0, 1]])
            M = np.diag([1.0, -1.0, 1.0])
            f0 = k(*L, *V, [0.0])
            assert k(*(R @ L), *(R @ V), [0.0]) == pytest.approx(f0, abs=1e-12)
            assert k(*(M @ L), *(M @ V), [0.0]) == pytest.approx(f0, abs=1e-12)


# --------------------------------------------------------------------------- errors
@pytest.mark.parametrize("body, col, words", [
    ("return vec3(nosuch);", 13, "unknown identifier 'nosuch'"),
    ("return vec3(nofn(1.0));", 13, "unknown function 'nofn'"),
    ("return vec3(texture(s, vec2(0)).x);", 13, "texture"),
    ("float a[3]; return vec3(0);", 7, "array"),
    ("for (int i = 0; i < int(L.z * 9.0); i++) {} return vec3(0);", 17,
     "bound is not a constant"),
    ("mat3 m; return vec3(0);", 1, "matrix"),
    ("discard; return vec3(0);", 1, "discard"),
    ("switch (1) { default: break; } return vec3(0);", 1, "switch"),
    ("return vec3(1) + vec2(1);", 8, "cannot combine vec3 and vec2"),
])
def test_unsupported_and_wrong_code_is_one_located_error(body, col, words):
    # the BRDF's body is on line 14 of the file: first_line 10 (the section's line), two
    # blank lines (rows 0, 1), the signature on line 13; columns count from 1
    with pytest.raises(BrdfkitError) as e:
        translate("\n" + brdf(body), [], path="bad.brdf", first_line=10)
    msg = str(e.value)
    assert msg.startswith(f"bad.brdf:14:{col}: "), msg
    assert words in msg and "\n" not in msg


@pytest.mark.parametrize("shader, words", [
    ("float f(float x) { return f(x); }\n" + brdf("return vec3(f(1.0));"), "recursion"),
    ("float f(out float x) { x = 1.0; return 1.0; }\n" + brdf("return vec3(0);"),
     "out parameters"),
    ("uniform float k;\n" + brdf("return vec3(k);"), "parameters belong"),
    ("#define K 2.0\n" + brdf("return vec3(K);"), "#define"),
    ("vec3 brdf(vec3 L) { return L; }", "no function 'vec3 BRDF("),
    (brdf("return vec3(1.0)"), "syntax error"),
    (brdf("float x = ;"), "syntax error"),
])
def test_file_level_errors(shader, words):
    with pytest.raises(BrdfkitError) as e:
        translate(shader, [], path="bad.brdf")
    assert words in str(e.value) and str(e.value).startswith("bad.brdf:")


# --------------------------------------------------------------------------- the file
LAMBERT = """analytic
# a comment
::begin parameters
float rho 0 1 .5   # trailing comments are allowed
color tint 1 .5 .25
bool on 1
::end parameters

::begin shader
const float PI = 3.14159265358979323846;
vec3 BRDF(vec3 L, vec3 V, vec3 N, vec3 X, vec3 Y) { return on ? tint * rho / PI : vec3(0); }
::end shader
::begin isFunc
vec3 sample(vec3 V) { return V; }
::end isFunc
"""


def test_reader_parameters_sections_and_notes(tmp_path):
    path = tmp_path / "lambert.brdf"
    path.write_text(LAMBERT)
    f = read_brdf_file(path)
    assert [(p.kind, p.name) for p in f.params] == [("float", "rho"), ("color", "tint"),
                                                   ("bool", "on")]
    assert f.params[0].lower == 0 and f.params[0].upper == 1 and f.params[0].default == 0.5
    assert f.params[1].default == (1.0, 0.5, 0.25) and f.params[2].default is True
    assert f.shader_line == 9 and "isFunc section ignored" in f.notes[0]
    d = definition(path)
    assert d.n_channels == 3 and d.isotropic
    P = d.pack({"rho": 0.5, "tint": [1.0, 0.5, 0.25], "on": True})
    assert P.shape == (3, 5) and P[:, -1].tolist() == [0.0, 1.0, 2.0]
    k = d.kernel.py_func
    got = [k(0.0, 0.0, 1.0, 0.0, 0.0, 1.0, row) for row in P]
    assert got == pytest.approx([0.5 / PI, 0.25 / PI, 0.125 / PI])
    off = definition(path, bools={"on": False})
    assert off.kernel.py_func(0.0, 0.0, 1.0, 0.0, 0.0, 1.0, P[0]) == 0.0


@pytest.mark.parametrize("text, where, words", [
    ("bparam\n", ":1:1:", "expected 'analytic'"),
    ("analytic\n::begin parameters\nfloat rho 0 1\n::end parameters\n", ":3:",
     "expected 'float NAME MIN MAX DEFAULT'"),
    ("analytic\n::begin parameters\nfloat rho 0 1 x\n::end parameters\n", ":3:15:",
     "DEFAULT must be a number; found 'x'"),
    ("analytic\n::begin parameters\nfloat rho 0 1 2\n::end parameters\n", ":3:15:",
     "outside [0, 1]"),
    ("analytic\n::begin parameters\nint rho 0 1 2\n::end parameters\n", ":3:1:",
     "must start with float, bool or color"),
    ("analytic\n::begin parameters\nbool b yes\n::end parameters\n", ":3:8:",
     "DEFAULT must be 0 or 1"),
    ("analytic\n::begin parameters\nfloat a 0 1 0\nfloat a 0 1 0\n::end parameters\n", ":4:",
     "declared twice"),
    ("analytic\n::begin shader\n", ":2:1:", "is not closed"),
    ("analytic\n::begin parameters\n::begin shader\n", ":3:1:", "do not nest"),
    ("analytic\n::begin parameters\n::end parameters\n", "", "no '::begin shader'"),
])
def test_reader_errors_name_file_line_and_column(tmp_path, text, where, words):
    path = tmp_path / "bad.brdf"
    path.write_text(text)
    with pytest.raises(DataFileError) as e:
        read_brdf_file(path)
    msg = str(e.value)
    assert msg.startswith(str(path)) and where in msg and words in msg, msg


def test_shader_errors_carry_the_file_line(tmp_path):
    path = tmp_path / "bad.brdf"
    path.write_text("analytic\n::begin shader\n\n# dropped\n"
                    "vec3 BRDF(vec3 L, vec3 V, vec3 N, vec3 X, vec3 Y) {\n"
                    "    return vec3(oops);\n}\n::end shader\n")
    with pytest.raises(BrdfkitError, match=rf"^{path}:6:17: unknown identifier 'oops'"):
        definition(path)
