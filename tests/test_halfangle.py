"""Half-angle conversions, checked against their DEFINITION (Lewis 1993 §3.1-3.4).

The reference for every conversion is the definition itself: "the lobe drops
to half its peak at β". Each test evaluates the lobe (the registered model or
the distribution written out from Lewis §3.2) at the peak and at β and checks
the ratio is 1/2; round trips check the inverses. Nothing is compared with a
number printed by the code.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

import brdfkit
from brdfkit import halfangle as ha
from brdfkit.errors import ParameterError
from brdfkit.geometry import spherical_to_cartesian

BETAS = np.array([0.01, 0.1, 0.3, 0.6, 0.9, 1.2, 1.5])
NORMAL = np.array([0.0, 0.0, 1.0])


def tilted(beta):
    """V tilted from the normal by beta in the xz-plane."""
    return spherical_to_cartesian(beta, 0.0)


# ----------------------------------------------------------------- distributions (Lewis §3.2)
def d1(cos_a, n):
    return cos_a**n  # Lewis D1 with b = 1


def d2(alpha, c):
    return np.exp(-((c * alpha) ** 2))  # Lewis D2 with b = 1


def d3(cos_a, c):
    return (c * c / (cos_a**2 * (c * c - 1.0) + 1.0)) ** 2  # Lewis D3 with b = 1


def d4(cos_a, m):
    t2 = (1.0 - cos_a**2) / cos_a**2
    return np.exp(-t2 / m**2) / (4.0 * m**2 * cos_a**4)  # Lewis D4


@pytest.mark.parametrize("beta", BETAS)
def test_phong_exponent_definition(beta):
    n = ha.exponent_from_beta(beta)
    assert d1(math.cos(beta), n) / d1(1.0, n) == pytest.approx(0.5, rel=1e-12)


@pytest.mark.parametrize("beta", BETAS)
def test_gaussian_c2_definition(beta):
    c = ha.gaussian_c_from_beta(beta)
    assert d2(beta, c) / d2(0.0, c) == pytest.approx(0.5, rel=1e-12)


@pytest.mark.parametrize("beta", BETAS)
def test_trowbridge_reitz_c3_definition(beta):
    c = ha.trowbridge_reitz_c_from_beta(beta)
    assert d3(math.cos(beta), c) / d3(1.0, c) == pytest.approx(0.5, rel=1e-10)
    # Lewis's printed formula, c3 = sqrt((cos^2 b - 1)/(cos^2 b - sqrt 2)), typed from §3.2:
    cb2 = math.cos(beta) ** 2
    assert c == pytest.approx(math.sqrt((cb2 - 1.0) / (cb2 - math.sqrt(2.0))), rel=1e-14)


@pytest.mark.parametrize("beta", BETAS)
def test_beckmann_m_definition(beta):
    m = ha.beckmann_m_from_beta(beta)
    assert d4(math.cos(beta), m) / d4(1.0, m) == pytest.approx(0.5, rel=1e-10)
    # Lewis's printed m = tan b / sqrt(ln 2 - 4 ln cos b) (§3.2) agrees with the definition.
    printed = math.tan(beta) / math.sqrt(math.log(2) - 4 * math.log(math.cos(beta)))
    assert m == pytest.approx(printed)


def test_beckmann_peak_caveat():
    # D4 peaks at alpha = 0 only for m <= 1/sqrt(2) (slope of ln D4 in tan^2 at 0 is 2 - 1/m^2).
    m = ha.beckmann_m_from_beta(1.4)
    assert m > 1 / math.sqrt(2)
    cos_a = np.cos(np.linspace(0.0, 1.0, 50))
    assert np.max(d4(cos_a, m)) > d4(1.0, m)  # the "peak" at 0 is not the maximum


@pytest.mark.parametrize("beta", BETAS)
def test_neumann_neumann_s_definition_with_model(beta):
    # Lewis §3.3: keep S = N, tilt V by beta until f_r drops to half its value at V = N.
    model = brdfkit.model("neumann-neumann", b_N=1.0, beta=beta)
    ratio = model.eval(NORMAL, tilted(beta)) / model.eval(NORMAL, NORMAL)
    assert ratio == pytest.approx(0.5, rel=1e-10)


@pytest.mark.parametrize("beta", BETAS)
def test_neumann_neumann_printed_formula_is_wrong(beta):
    # Lewis §3.3 prints s = -ln 2/(1 + cos beta): negative for every beta, so the lobe would
    # grow away from the normal; with it the ratio at beta is > 1, not 1/2.
    s_printed = -math.log(2.0) / (1.0 + math.cos(beta))
    assert s_printed < 0.0
    f = lambda cos_v, s: math.exp(-s * (1.0 + 1.0 / cos_v - 2.0))  # noqa: E731 - f_r/b_N, S = N
    assert f(math.cos(beta), s_printed) / f(1.0, s_printed) > 1.0
    s = ha.neumann_s_from_beta(beta)
    # rel 1e-9: 1/cos b - 1 cancels digits at b = 0.01
    assert f(math.cos(beta), s) / f(1.0, s) == pytest.approx(0.5, rel=1e-9)


@pytest.mark.parametrize(
    "name,scale", [("minnaert", "b_M"), ("minnaert-energy-conserving", "k_rho")]
)
@pytest.mark.parametrize("beta", BETAS)
def test_minnaert_k_definition_with_model(name, scale, beta):
    model = brdfkit.model(name, **{scale: 0.5}, beta=beta)
    ratio = model.eval(NORMAL, tilted(beta)) / model.eval(NORMAL, NORMAL)
    assert ratio == pytest.approx(0.5, rel=1e-10)
    # Lewis §3.4's printed k = 1 - ln 2/ln cos beta is right:
    assert model.values["k"] == pytest.approx(1.0 - math.log(2) / math.log(math.cos(beta)))


@pytest.mark.parametrize("beta", BETAS)
def test_ward_m_definition_with_model(beta):
    # The N.H lobe exp(-tan^2 d/m^2) of Neumann eq. (8); with S = V the half vector is S, so
    # tilting both by beta puts delta = beta while sqrt(N.S N.V) = cos beta is divided out.
    model = brdfkit.model("ward", rho_d=0.0, rho_s=1.0, beta=beta)
    v = tilted(beta)
    ratio = (model.eval(v, v) * math.cos(beta)) / model.eval(NORMAL, NORMAL)
    assert ratio == pytest.approx(0.5, rel=1e-10)


@pytest.mark.parametrize(
    "distribution,cos_form",
    [("phong", d1), ("trowbridge-reitz", d3), ("beckmann", d4)],
)
@pytest.mark.parametrize("beta", [0.05, 0.3, 0.7])
def test_torrance_sparrow_beta_sets_the_chosen_distribution(distribution, cos_form, beta):
    model = brdfkit.model("torrance-sparrow", distribution=distribution, beta=beta)
    width = {"phong": "n", "trowbridge-reitz": "c", "beckmann": "m"}[distribution]
    assert model.width_param == width
    w = model.values[width]
    assert cos_form(math.cos(beta), w) / cos_form(1.0, w) == pytest.approx(0.5, rel=1e-10)


def test_torrance_sparrow_gaussian_beta():
    model = brdfkit.model("torrance-sparrow", distribution="gaussian", beta=0.2)
    c = model.values["c"]
    assert d2(0.2, c) / d2(0.0, c) == pytest.approx(0.5, rel=1e-12)


ROUND_TRIPS = [
    (ha.exponent_from_beta, ha.beta_from_exponent),
    (ha.gaussian_c_from_beta, ha.beta_from_gaussian_c),
    (ha.trowbridge_reitz_c_from_beta, ha.beta_from_trowbridge_reitz_c),
    (ha.beckmann_m_from_beta, ha.beta_from_beckmann_m),
    (ha.neumann_s_from_beta, ha.beta_from_neumann_s),
    (ha.minnaert_k_from_beta, ha.beta_from_minnaert_k),
    (ha.ward_m_from_beta, ha.beta_from_ward_m),
]


@pytest.mark.parametrize("forward,inverse", ROUND_TRIPS)
def test_round_trips(forward, inverse):
    back = inverse(forward(BETAS))
    np.testing.assert_allclose(back, BETAS, rtol=1e-9, atol=1e-12)
    for b in (0.05, 1.0):  # scalars come back as floats
        assert isinstance(inverse(forward(b)), float)


def test_beckmann_inverse_is_monotone_and_small_m_limit():
    # For small beta, tan^2 b/m^2 ~ ln 2 (the 1/cos^4 factor is ~1): beta ~ m sqrt(ln 2).
    assert ha.beta_from_beckmann_m(1e-4) == pytest.approx(1e-4 * math.sqrt(math.log(2)), rel=1e-6)
    ms = np.geomspace(1e-3, 10.0, 40)
    assert np.all(np.diff(ha.beta_from_beckmann_m(ms)) > 0)


@pytest.mark.parametrize("bad", [0.0, -0.1, math.pi / 2, 2.0, float("nan")])
def test_bad_beta(bad):
    with pytest.raises(ParameterError, match="beta"):
        ha.neumann_s_from_beta(bad)


def test_inverse_domains():
    with pytest.raises(ParameterError, match=r"k \(Minnaert\).*\(1, inf\)"):
        ha.beta_from_minnaert_k(0.8)  # k <= 1 has no half-angle: the lobe does not peak at N
    with pytest.raises(ParameterError, match="Trowbridge"):
        ha.beta_from_trowbridge_reitz_c(0.9)
    with pytest.raises(ParameterError, match="Gaussian"):
        ha.beta_from_gaussian_c(0.5)
    with pytest.raises(ParameterError, match="'beta'"):
        brdfkit.model("neumann-neumann", beta=0.3, s=1.0)


@pytest.mark.parametrize("distribution", ["beckmann", "ggx"])
@pytest.mark.parametrize("beta", [0.02, 0.3, 0.9])
def test_microfacet_beta_definition(distribution, beta):
    # D(beta) = D(0)/2 for Walter's normalised NDFs (normalisation cancels in the ratio).
    from brdfkit.models.microfacet import d_beckmann, d_ggx

    d = {"beckmann": d_beckmann, "ggx": d_ggx}[distribution]
    model = brdfkit.model("microfacet", distribution=distribution, beta=beta)
    alpha = model.values["alpha"]
    assert d(math.cos(beta), alpha) / d(1.0, alpha) == pytest.approx(0.5, rel=1e-10)


def test_with_params_beta_follows_distribution():
    m = brdfkit.model("torrance-sparrow", distribution="phong", n=10.0).with_params(beta=0.2)
    assert m.values["n"] == pytest.approx(ha.exponent_from_beta(0.2))
    d = brdfkit.MODELS["torrance-sparrow"].describe()
    assert "phong" in d["beta"] and "beckmann" in d["beta"]
