"""Models written in Python (issue 21 §2): ``brdfkit.formula``, the ``.py`` loader,
:class:`~brdfkit.user.model.FormulaBRDF`, the ``bool`` parameter kind, the spec kinds and
``brdfkit models FILE``.

References, independent of the code under test:
- the registered models written by the package's contributors: modified Phong (Nielsen
  eq. 1) and Walter's GGX with Smith G₁ (``microfacet``, distribution ggx, F = 1) — the
  file's formulas are the papers' written again by a user, in the formula language;
  values agree to rounding (1e-12 relative), albedos (the same engine, another kernel) to
  1e-6, fits to the same MERL surrogate to the optimiser's tolerance;
- closed forms: Lambert's albedo is ρ at every incidence; the half-angle of a cosⁿ lobe,
  acos(2^(-1/n)) (the lobe estimate);
- the χ² helpers of the project (:func:`brdfkit.analysis.chi2.chi2_test`, as
  ``tests/test_sampling_chi2.py``), with a wrong pdf that must fail.
"""

from __future__ import annotations

import math
import re
import textwrap

import numpy as np
import pytest
from click.testing import CliRunner

import brdfkit
from brdfkit.analysis.albedo_engine import NONFINITE, albedo
from brdfkit.analysis.chi2 import chi2_test
from brdfkit.cli import main
from brdfkit.errors import DataFileError, ParameterError, UnknownModelError
from brdfkit.fitting import fit
from brdfkit.fitting._space import ParameterSpace
from brdfkit.models import Param
from brdfkit.pumping import pump
from brdfkit.spec import ModelSpec
from brdfkit.user.python_file import definitions

MODELS_PY = '''\
"""A user's own models (written for the tests of issue 21)."""
from brdfkit.formula import (Param, cos, define, exp, formula, log, maximum, pos_pow,
                             select, sin, sqrt)

PI = 3.141592653589793
INV_PI = 1.0 / PI
INV_TWO_PI = 1.0 / (2.0 * PI)


@formula
def modified_phong(ix, iy, iz, ox, oy, oz, rho_d, rho_s, n):
    """Nielsen et al. eq. (1): rho_d/pi + rho_s (n + 2)/(2 pi) max(0, R.V)^n."""
    rv = 2.0 * iz * oz - (ix * ox + iy * oy + iz * oz)
    return rho_d * INV_PI + rho_s * (n + 2.0) * INV_TWO_PI * pos_pow(rv, n)


@formula
def exp_log_pow(c, n):
    """max(0, c)^n (0 for c <= 0) as exp(n log c)."""
    return select(c > 0.0, exp(n * log(select(c > 0.0, c, 1.0))), 0.0)


@formula
def phong_exp_log(ix, iy, iz, ox, oy, oz, rho_d, rho_s, n):
    rv = 2.0 * iz * oz - (ix * ox + iy * oy + iz * oz)
    return rho_d / PI + rho_s * (n + 2.0) / (2.0 * PI) * exp_log_pow(rv, n)


@formula
def g1(c, a2):
    """Smith G1 of GGX for a direction at cos(theta) = c (Walter eq. 34)."""
    c2 = c * c
    return 2.0 / (1.0 + sqrt(1.0 + a2 * (1.0 - c2) / c2))


@formula
def walter_ggx(ix, iy, iz, ox, oy, oz, alpha):
    """Walter et al. eq. (20), GGX D (eq. 33), F = 1."""
    hx, hy, hz = ix + ox, iy + oy, iz + oz
    hz = hz / sqrt(hx * hx + hy * hy + hz * hz)
    a2 = alpha * alpha
    t = (a2 - 1.0) * hz * hz + 1.0
    d = a2 / (PI * t * t)
    return d * g1(iz, a2) * g1(oz, a2) / (4.0 * iz * oz)


@formula
def lambert(ix, iy, iz, ox, oy, oz, rho, off):
    return select(off, 0.0, rho / PI)


@formula
def hole(ix, iy, iz, ox, oy, oz, rho):
    """Lambert where cos(theta_o) > 0.5, 0/0 elsewhere."""
    return rho / PI * select(oz > 0.5, 1.0, (oz - oz) / (oz - oz))


@formula
def lopsided(ix, iy, iz, ox, oy, oz, rho):
    """Not reciprocal: brighter toward the light's elevation only."""
    return rho / PI * (1.0 + 0.5 * iz * iz)


@formula
def stretched(ix, iy, iz, ox, oy, oz, rho, a):
    """Reciprocal but anisotropic for a != 0."""
    return rho / PI * (1.0 + a * (ix * ox - iy * oy))


@formula
def cos_power_sample(ox, oy, oz, u0, u1, k):
    """cos^k(theta) about the normal: cos(theta) = u0^(1/(k+1))."""
    c = exp(log(maximum(u0, 1e-300)) / (k + 1.0))
    s = sqrt(maximum(1.0 - c * c, 0.0))
    return s * cos(2.0 * PI * u1), s * sin(2.0 * PI * u1), c


@formula
def cos_power_pdf(ix, iy, iz, ox, oy, oz, k):
    return select(iz > 0.0, (k + 1.0) / (2.0 * PI) * exp(k * log(select(iz > 0.0, iz, 1.0))),
                  0.0)


@formula
def wrong_pdf(ix, iy, iz, ox, oy, oz, k):
    """cos^k normalised for cos^(k+1): integrates to (k+2)/(k+1) != 1."""
    return select(iz > 0.0, (k + 2.0) / (2.0 * PI) * exp(k * log(select(iz > 0.0, iz, 1.0))),
                  0.0)


@formula
def lambert_plain(ix, iy, iz, ox, oy, oz, rho):
    return rho / PI


RHO = Param("rho", 0.8, 0.0, 1.0, doc="albedo")
K = Param("k", 3.0, 0.0, 100.0, doc="exponent of the sampler")
MODELS = [
    define("modified_phong", eval=modified_phong, reciprocal=True, params=[
        Param("rho_d", 0.2, 0.0, 1.0, doc="diffuse albedo", kind="colour"),
        Param("rho_s", 0.5, 0.0, 1.0, doc="specular albedo", kind="colour"),
        Param("n", 20.0, 0.0, 1e6, doc="exponent")],
        citation="Nielsen et al. eq. (1)", summary="modified Phong, as a user writes it"),
    define("phong_exp_log", eval=phong_exp_log, params=[
        Param("rho_d", 0.2, 0.0, 1.0), Param("rho_s", 0.5, 0.0, 1.0), Param("n", 20.0, 0.0, 1e6)]),
    define("walter_ggx", eval=walter_ggx, reciprocal=True,
           params=[Param("alpha", 0.2, 1e-4, 4.0, doc="GGX roughness")]),
    define("lambert", eval=lambert, params=[RHO, Param("off", False, kind="bool",
                                                       doc="switch it off")]),
    define("hole", eval=hole, params=[RHO]),
    define("lopsided", eval=lopsided, params=[RHO]),
    define("stretched", eval=stretched, params=[Param("rho", 0.5, 0.0, 1.0),
                                                Param("a", 0.5, -0.5, 0.5)]),
    define("sampled", eval=lambert_plain, params=[RHO, K], sample=cos_power_sample,
           pdf=cos_power_pdf, reciprocal=True, isotropic=True),
    define("badly_sampled", eval=lambert_plain, params=[RHO, K], sample=cos_power_sample,
           pdf=wrong_pdf, reciprocal=True, isotropic=True),
]
'''

ONE_PY = '''\
from brdfkit.formula import Param, define, formula

@formula
def grey(ix, iy, iz, ox, oy, oz, rho):
    return rho / 3.141592653589793

MODEL = define("grey", eval=grey, params=[Param("rho", 0.5, 0.0, 1.0)])
'''


@pytest.fixture(scope="module")
def files(tmp_path_factory):
    d = tmp_path_factory.mktemp("user_models")
    (d / "models.py").write_text(MODELS_PY)
    (d / "one.py").write_text(ONE_PY)
    return d


def spec(files, name: str) -> str:
    return f"{files / 'models.py'}:{name}"


def directions(n: int, seed: int) -> np.ndarray:
    rng = np.random.default_rng(seed)
    v = rng.normal(size=(n, 3))
    v /= np.linalg.norm(v, axis=-1, keepdims=True)
    v[:, 2] = np.abs(v[:, 2])
    return v


# --------------------------------------------------------------------------- values
@pytest.mark.parametrize("values", [{}, {"n": 500.0, "rho_d": 0.0, "rho_s": 1.0},
                                    {"rho_d": [0.1, 0.2, 0.3], "rho_s": [0.5, 0.4, 0.3],
                                     "n": 7.0}])
def test_python_modified_phong_equals_the_registered_one(files, values):
    mine = brdfkit.model(spec(files, "modified_phong"), **values)
    ref = brdfkit.model("modified-phong", **values)
    wi, wo = directions(20_000, 1), directions(20_000, 2)
    a, b = mine.eval(wi, wo), ref.eval(wi, wo)
    assert a.shape == b.shape
    np.testing.assert_array_equal(a, b)  # the same arithmetic in the same order: bit-equal
    below = wo * np.array([1.0, 1.0, -1.0])
    assert np.all(mine.eval(wi, below) == 0.0)  # 0 below the horizon, whatever the formula
    if "rho_d" in values and np.ndim(values["rho_d"]):
        return
    # the power as exp(n log c) against the built-in's binary powers: rounding only
    other = brdfkit.model(spec(files, "phong_exp_log"), **values)
    np.testing.assert_allclose(other.eval(wi, wo), b, rtol=1e-12, atol=1e-300)


def test_python_walter_ggx_equals_the_registered_microfacet(files):
    mine = brdfkit.model(spec(files, "walter_ggx"), alpha=0.3)
    ref = brdfkit.model("microfacet", distribution="ggx", alpha=0.3)
    wi, wo = directions(20_000, 3), directions(20_000, 4)
    np.testing.assert_allclose(mine.eval(wi, wo), ref.eval(wi, wo), rtol=1e-9)


def test_albedo_matches_the_registered_model(files):
    theta = np.radians([0.0, 30.0, 60.0, 80.0, 89.0])
    for values in ({"n": 20.0}, {"rho_d": 0.0, "rho_s": 1.0, "n": 2000.0}):
        a = albedo(brdfkit.model(spec(files, "modified_phong"), **values), theta)
        b = albedo(brdfkit.model("modified-phong", **values), theta)
        assert a.success and b.success
        np.testing.assert_allclose(a.albedo, b.albedo, atol=1e-6)


def test_lambert_albedo_is_rho(files):
    theta = np.radians([0.0, 45.0, 85.0, 89.9])
    r = albedo(brdfkit.model(spec(files, "lambert"), rho=0.37), theta)
    assert r.success
    np.testing.assert_allclose(r.albedo, 0.37, atol=1e-9)  # ∫ ρ/π cos θ dω = ρ


def test_nan_reaches_eval_and_the_albedo_status(files):
    m = brdfkit.model(spec(files, "hole"))
    s = math.sqrt(1.0 - 0.4 ** 2)
    f = m.eval([0.0, 0.0, 1.0], np.array([[0.0, 0.0, 1.0], [0.8, 0.0, 0.6], [s, 0.0, 0.4]]))
    assert f[0] == f[1] == pytest.approx(0.8 / math.pi)
    assert math.isnan(f[2])  # cos θ_o = 0.4: 0/0, kept
    r = albedo(m, np.radians([0.0, 40.0]))
    assert not r.success
    assert np.all(r.status == NONFINITE), r.status
    assert np.all(np.isnan(r.albedo))


# --------------------------------------------------------------------------- lobes, claims
def test_lobes_are_estimated_from_the_values(files):
    for n in (20.0, 800.0):
        lobe = brdfkit.model(spec(files, "modified_phong"), n=n).sharpest_lobe()
        assert lobe.kind == "mirror"
        assert lobe.width == pytest.approx(math.acos(2.0 ** (-1.0 / n)), rel=0.01)
    ggx = brdfkit.model(spec(files, "walter_ggx"), alpha=0.1).sharpest_lobe()
    assert ggx.kind == "half"
    # D(θ_h) = D(0)/2: ((α²−1)cos²θ + 1)² = 2α⁴ … solved for cos²θ (GGX half-width)
    a2 = 0.01
    c2 = (math.sqrt(2.0) * a2 - 1.0) / (a2 - 1.0)
    # the estimate sees D·G·1/cos terms too: within 15 % of D's own half-width
    assert ggx.width == pytest.approx(math.acos(math.sqrt(c2)), rel=0.15)
    assert brdfkit.model(spec(files, "lambert")).sharpest_lobe().kind == "diffuse"


def test_reciprocity_is_claimed_or_measured(files):
    assert brdfkit.model(spec(files, "lambert")).reciprocal  # measured: symmetric
    assert not brdfkit.model(spec(files, "lopsided")).reciprocal  # measured: not
    assert brdfkit.model(spec(files, "modified_phong")).reciprocal  # claimed


def test_isotropy_is_measured_when_not_declared(files):
    by_name = {d.name.rpartition(":")[2]: d for d in definitions(files / "models.py")}
    assert by_name["lambert"].isotropic and "measured" in by_name["lambert"].isotropy_reason
    assert not by_name["stretched"].isotropic
    assert by_name["sampled"].isotropy_reason.startswith("declared")


def test_pumping_a_python_model(files):
    mine = pump(brdfkit.model(spec(files, "modified_phong"), n=20.0), "max")
    ref = pump(brdfkit.model("modified-phong", n=20.0), "max")
    theta = np.radians([0.0, 60.0, 85.0])
    np.testing.assert_allclose(albedo(mine, theta).albedo, albedo(ref, theta).albedo,
                               atol=1e-6)
    with pytest.raises(ParameterError, match="is not reciprocal"):
        pump(brdfkit.model(spec(files, "lopsided")), "max")
    with pytest.raises(ParameterError, match="is anisotropic"):
        pump(brdfkit.model(spec(files, "stretched")), "max")


def test_fit_of_a_python_model_to_merl(files):
    target = brdfkit.model("merl:nickel")
    mine = fit(brdfkit.model(spec(files, "modified_phong")), target)
    ref = fit(brdfkit.model("modified-phong"), target)
    assert mine.value == pytest.approx(ref.value, rel=0.02)
    assert mine.params["n"] == pytest.approx(ref.params["n"], rel=0.05)


def test_bools_are_held_by_a_fit(files):
    m = brdfkit.model(spec(files, "lambert"))
    space, _ = ParameterSpace.of_model(m, {}, 1)
    assert [c.name for c in space.coords] == ["rho"]


# --------------------------------------------------------------------------- sampling
@pytest.mark.parametrize("theta", [0.0, 45.0, 80.0])
def test_tabulated_sampler_passes_chi2(files, theta):
    m = brdfkit.model(spec(files, "modified_phong"), n=50.0)
    t = math.radians(theta)
    wo = np.array([math.sin(t) * math.cos(0.4), math.sin(t) * math.sin(0.4), math.cos(t)])
    r = chi2_test(m, wo, n_samples=100_000, seed=11, alpha=0.01, n_tests=3)
    assert r.passed, r.message


def test_sampler_arguments_from_sampler_args(tmp_path):
    p = _write(tmp_path, """
        from brdfkit.formula import cos, maximum, select, sin

        PI = 3.141592653589793

        @formula
        def f(ix, iy, iz, ox, oy, oz, rho, spread):
            return rho / PI

        @formula
        def sample(ox, oy, oz, u0, u1, k):
            c = u0 ** (1.0 / (k + 1.0))
            s = sqrt(maximum(1.0 - c * c, 0.0))
            return s * cos(2.0 * PI * u1), s * sin(2.0 * PI * u1), c

        @formula
        def pdf(ix, iy, iz, ox, oy, oz, k):
            return select(iz > 0.0, (k + 1.0) / (2.0 * PI) * maximum(iz, 0.0) ** k, 0.0)

        MODEL = define("f", eval=f, sample=sample, pdf=pdf,
                       sampler_args=lambda v: (2.0 * v["spread"],),
                       params=[Param("rho", 0.5, 0.0, 1.0), Param("spread", 1.5, 0.0, 10.0)])
        """, "args.py")
    m = brdfkit.model(p, spread=2.0)
    assert m.formulas().args == (4.0,)
    _, pdf = m.sample([0.0, 0.0, 1.0], [0.5, 0.25])
    # k = 4: cos θ = 0.5^(1/5), pdf (k+1)/(2π) cos⁴ θ
    assert float(pdf) == pytest.approx(5.0 / (2.0 * math.pi) * 0.5 ** 0.8, rel=1e-12)


def test_the_users_sampler_is_used_and_chi2_tested(files):
    wo = np.array([0.5, 0.0, math.sqrt(0.75)])
    good = brdfkit.model(spec(files, "sampled"), k=5.0)
    r = chi2_test(good, wo, n_samples=100_000, seed=12, alpha=0.01, n_tests=2)
    assert r.passed, r.message
    wi, p = good.sample(np.broadcast_to(wo, (4, 3)), np.full((4, 2), 0.5))
    # cos θ = 0.5^(1/6) at u0 = 0.5; pdf (k+1)/(2π) cos^k θ
    c = 0.5 ** (1.0 / 6.0)
    np.testing.assert_allclose(wi[:, 2], c, rtol=1e-12)
    np.testing.assert_allclose(p, 6.0 / (2.0 * math.pi) * c ** 5, rtol=1e-12)
    bad = brdfkit.model(spec(files, "badly_sampled"), k=5.0)
    assert not chi2_test(bad, wo, n_samples=100_000, seed=12, alpha=0.01, n_tests=2).passed


def test_formulas_trace_with_drjit(files):
    pytest.importorskip("drjit")
    from brdfkit._dual import drjit_version

    m = brdfkit.model(spec(files, "sampled"), k=5.0)
    f = m.formulas()
    assert f.args == (5.0,)
    wi, wo = (0.3, 0.1, math.sqrt(0.9)), (-0.2, 0.4, math.sqrt(0.8))
    ev = drjit_version(f.eval)(*wi, *wo, tuple(float(x) for x in m.packed[0]))
    assert float(ev) == pytest.approx(float(m.eval(wi, wo)), rel=1e-12)
    pdf = drjit_version(f.pdf)(*wi, *wo, *f.args)
    assert float(pdf) == pytest.approx(float(m.pdf(wi, wo)), rel=1e-12)
    phong = brdfkit.model(spec(files, "modified_phong"), n=20.0)
    ev = drjit_version(phong.definition.kernel)(*wi, *wo, tuple(phong.packed[0].tolist()))
    assert float(ev) == pytest.approx(float(phong.eval(wi, wo)), rel=1e-12)  # dr.power
    flag = brdfkit.model(spec(files, "lambert"), off=True)
    off = drjit_version(flag.definition.kernel)(*wi, *wo, tuple(flag.packed[0].tolist()))
    assert float(off) == 0.0


# --------------------------------------------------------------------------- specs
def test_spec_round_trip(files):
    m = brdfkit.model(spec(files, "modified_phong"), rho_d=[0.1, 0.2, 0.3], n=33.0)
    d = m.to_dict()
    assert d["model"] == spec(files, "modified_phong")
    again = ModelSpec.of(m).build()
    np.testing.assert_array_equal(again.packed, m.packed)
    assert ModelSpec.from_dict(d).build().values["n"] == 33.0
    assert ModelSpec(files / "one.py").kind == "python-file"  # a path object too
    one = brdfkit.model(files / "one.py", rho=0.25)
    assert ModelSpec.of(one).build().values == {"rho": 0.25}
    assert repr(one) == f"brdfkit.model({str(files / 'one.py') + ':grey'!r}, rho=0.25)"


def test_definitions_are_cached_per_content(tmp_path):
    p = tmp_path / "grey.py"
    p.write_text(ONE_PY)
    first = definitions(p)
    assert definitions(p) is first
    p.write_text(ONE_PY.replace("0.5, 0.0, 1.0", "0.25, 0.0, 1.0"))
    assert definitions(p)[0].params[0].default == 0.25


# --------------------------------------------------------------------------- bool
def test_bool_parameter_kind():
    p = Param("off", False, kind="bool")
    for text, value in (("true", True), ("FALSE", False), ("1", True), ("0", False),
                        (1, True), (0, False), (True, True), (0.0, False)):
        assert p.validate(text, "m") is value
    for bad in ("yes", 2, 0.5, None, [1]):
        with pytest.raises(ParameterError, match="'off' must be true or false"):
            p.validate(bad, "m")
    assert p.bounds_text() == "true or false"
    assert p.to_dict()["bounds"] == "true or false" and p.to_dict()["default"] is False


def test_bool_packs_as_one_or_zero(files):
    on = brdfkit.model(spec(files, "lambert"), off="true")
    assert on.values["off"] is True and on.packed[0].tolist() == [0.8, 1.0]
    assert float(on.eval([0, 0, 1.0], [0, 0, 1.0])) == 0.0
    assert brdfkit.model(spec(files, "lambert"), off=0).packed[0].tolist() == [0.8, 0.0]


# --------------------------------------------------------------------------- errors
HEAD = "from brdfkit.formula import Param, define, formula, sqrt\n"


def _write(tmp_path, body: str, name: str) -> str:
    p = tmp_path / name
    p.write_text(HEAD + textwrap.dedent(body))
    return str(p)


def test_errors_of_the_file(tmp_path, files):
    with pytest.raises(DataFileError, match=r"nowhere\.py: no such file"):
        brdfkit.model(str(tmp_path / "nowhere.py"))
    p = _write(tmp_path, "X = 1\n", "empty.py")
    with pytest.raises(DataFileError, match=r"empty\.py: declares no model"):
        brdfkit.model(p)
    with pytest.raises(UnknownModelError, match=r"declares 9 models \(modified_phong, "
                                                r"phong_exp_log, walter_ggx, .*\); choose one"):
        brdfkit.model(files / "models.py")
    with pytest.raises(UnknownModelError, match="declares no model 'nope'; its models: "
                                                "modified_phong, phong_exp_log, walter_ggx"):
        brdfkit.model(spec(files, "nope"))
    p = _write(tmp_path, "\n\ndef f(:\n    pass\n", "syntax.py")
    with pytest.raises(DataFileError, match=r"syntax\.py:4:7: syntax error"):
        brdfkit.model(p)
    p = _write(tmp_path, "\nY = 1 / 0\n", "raises.py")
    with pytest.raises(DataFileError, match=r"raises\.py:3: ZeroDivisionError"):
        brdfkit.model(p)
    p = _write(tmp_path, """
        @formula
        def f(ix, iy, iz, ox, oy, oz, m):
            return m

        MODEL = define("f", eval=f, params=[Param("m", 1.0, kind="lobes")])
        """, "kind.py")
    with pytest.raises(DataFileError, match=r"kind\.py:7: define\('f'\): parameter 'm' has "
                                            "kind 'lobes'; a user model's kinds: scalar"):
        brdfkit.model(p)


def test_errors_of_the_formula(tmp_path):
    p = _write(tmp_path, """
        import math

        @formula
        def attr(ix, iy, iz, ox, oy, oz, rho):
            return rho * math.sqrt(iz)

        MODEL = define("attr", eval=attr, params=[Param("rho", 0.5, 0.0, 1.0)])
        """, "attr.py")
    with pytest.raises(DataFileError, match=r"attr\.py: model 'attr': formula attr uses "
                                            "LOAD_ATTR"):
        brdfkit.model(p)
    p = _write(tmp_path, """
        @formula
        def named(ix, iy, iz, ox, oy, oz, rho, sigma):
            return rho

        MODEL = define("named", eval=named, params=[Param("rho", 0.5, 0.0, 1.0)])
        """, "named.py")
    with pytest.raises(DataFileError, match="formula named takes 'sigma', which is not a "
                                            "declared parameter; declared: rho"):
        brdfkit.model(p)
    p = _write(tmp_path, """
        @formula
        def text(ix, iy, iz, ox, oy, oz, rho):
            return rho + "a"

        MODEL = define("text", eval=text, params=[Param("rho", 0.5, 0.0, 1.0)])
        """, "text.py")
    with pytest.raises(DataFileError, match=r"text\.py: model 'text': the eval formula does "
                                            "not compile"):
        brdfkit.model(p)


def test_errors_of_the_parameters(files):
    with pytest.raises(ParameterError, match="unknown parameter 'sigma'; valid parameters: "
                                             "rho_d, rho_s, n"):
        brdfkit.model(spec(files, "modified_phong"), sigma=1.0)
    with pytest.raises(ParameterError, match=r"'n' must lie in \[0, 1e\+06\]; got -1"):
        brdfkit.model(spec(files, "modified_phong"), n=-1.0)
    with pytest.raises(ParameterError, match="name must be a Python identifier"):
        from brdfkit.formula import define
        define("my model", eval=lambda *a: 0.0)


# --------------------------------------------------------------------------- the CLI
def run(*args: str):
    return CliRunner().invoke(main, [str(a) for a in args])


def test_cli_models_file_shows_isotropy_claims_and_parameters(files):
    r = run("models", files / "models.py")
    assert r.exit_code == 0, r.output
    assert "models.py:modified_phong" in r.output
    assert "isotropic: yes (measured: unchanged" in r.output
    assert "isotropic: no (measured: changed" in r.output  # stretched
    assert "reciprocal: claimed yes" in r.output
    assert "reciprocal: not claimed (measured at the defaults: no)" in r.output  # lopsided
    assert re.search(r"\n +off +False +true or false +bool +switch it off\n", r.output)
    r = run("models", spec(files, "sampled"), "--json")
    import json
    (d,) = json.loads(r.output)
    assert d["claims"] == {"reciprocal": True, "energy_conserving": None}
    assert d["own_sampler"] and d["isotropic"] and d["source"] == str(files / "models.py")
    r = run("models", "modified-phong")  # a registered name shows that model (issue 20)
    assert r.exit_code == 0 and r.output.startswith("modified-phong"), r.output


def test_cli_commands_take_a_python_model(files, tmp_path):
    m = spec(files, "modified_phong")
    r = run("eval", m, "-p", "n=10", "--wi", "0,0", "--wo", "0,0", "--json")
    assert r.exit_code == 0, r.output
    import json
    assert json.loads(r.output)["value"] == pytest.approx(0.2 / math.pi + 0.5 * 12 / (2 * math.pi))
    r = run("eval", spec(files, "lambert"), "-p", "off=false", "--wi", "0,0", "--wo", "0,0")
    assert float(r.output) == pytest.approx(0.8 / math.pi)
    r = run("albedo", spec(files, "lambert"), "--theta", "0,60", "--json")
    assert np.allclose(json.loads(r.output)["albedo"], 0.8, atol=1e-9)
    r = run("check", m, "--json")
    assert r.exit_code == 0 and json.loads(r.output)["reciprocity"] == "reciprocal"
    r = run("table2", m, "--json")
    assert r.exit_code == 0 and json.loads(r.output)[0]["row"].startswith("models.py:")
    r = run("figure", "slices", m, "--out", tmp_path / "s.png")
    assert r.exit_code == 0 and (tmp_path / "s.png").stat().st_size > 0, r.output
    r = run("export", spec(files, "lambert"), "--out", tmp_path / "l.binary")
    assert r.exit_code == 0, r.output
    back = brdfkit.model(str(tmp_path / "l.binary"))
    assert float(back.eval([0.0, 0.0, 1.0], [0.6, 0.0, 0.8])[0]) == pytest.approx(0.8 / math.pi,
                                                                              rel=1e-6)
    r = run("fit", m, "--to", "merl:nickel", "-p", "rho_d=0", "--json")
    assert r.exit_code == 0 and json.loads(r.output)["model"] == m, r.output
    r = run("render", "sphere", spec(files, "lambert"), "--phi-l", "0", "--size", "16",
            "--out", tmp_path / "s.npy")
    assert r.exit_code == 0, r.output
    img = np.load(tmp_path / "s.npy")
    # E ρ/π cos θ_i, the light behind the viewer: ρ/π at the centre, less elsewhere
    assert 0.95 * 0.8 / math.pi < np.nanmax(img) <= 0.8 / math.pi * (1 + 1e-12)


def test_cli_errors_are_one_line(files, tmp_path):
    r = run("eval", spec(files, "lambert"), "-p", "off=maybe", "--wi", "0,0", "--wo", "0,0")
    assert r.exit_code == 2
    assert r.stderr.strip().splitlines() == [
        "brdfkit: error: models.py:lambert: parameter 'off' must be true or false "
        "(true/false, 1/0); got 'maybe'"]
    r = run("eval", tmp_path / "none.py", "--wi", "0,0", "--wo", "0,0")
    assert r.exit_code == 2 and len(r.stderr.strip().splitlines()) == 1
    assert "none.py: no such file" in r.stderr


def test_mitsuba_traced_route_with_the_users_sampler(files):
    """The user's formulas traced into Mitsuba (llvm_ad_rgb): eval = f cos θ_o and pdf
    against the Numba compilation of the same formulas, to float32 rounding."""
    mi = pytest.importorskip("mitsuba")
    dr = pytest.importorskip("drjit")
    import warnings

    from brdfkit.render.mitsuba_bridge import mitsuba_bsdf, use_variant

    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)
        variant = use_variant("llvm_ad_rgb")
    if not variant.startswith("llvm"):
        pytest.skip(f"no LLVM variant here ({variant}): the traced route needs one")
    m = brdfkit.model(spec(files, "sampled"), rho=0.6, k=4.0)
    bsdf = mitsuba_bsdf(m)
    assert bsdf.traced
    view = directions(64, 21).astype(np.float32).astype(float)
    light = directions(64, 22).astype(np.float32).astype(float)
    si = dr.zeros(mi.SurfaceInteraction3f, 64)
    si.wi = mi.Vector3f(view.T.astype(np.float32))
    wo = mi.Vector3f(light.T.astype(np.float32))
    ctx = mi.BSDFContext()
    got = np.array(bsdf.eval(ctx, si, wo))[0]
    np.testing.assert_allclose(got, m.eval(light, view) * light[:, 2], rtol=1e-5, atol=1e-7)
    np.testing.assert_allclose(np.array(bsdf.pdf(ctx, si, wo)), m.pdf(light, view),
                               rtol=1e-4, atol=1e-7)
