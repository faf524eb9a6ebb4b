"""Anisotropic models everywhere: the incidence azimuth φ_i of ``albedo`` and ``check``.

The model under test is written here: Ward's anisotropic BRDF (G. J. Ward, *Measuring
and modeling anisotropic reflection*, SIGGRAPH 1992, eq. 5a),

    f_r = ρ_d/π + ρ_s/(4π α_x α_y √(cos θ_i cos θ_o)) · exp(−tan²δ (cos²φ_h/α_x² + sin²φ_h/α_y²)),

with tan²δ (cos²φ_h/α_x² + sin²φ_h/α_y²) = ((h_x/α_x)² + (h_y/α_y)²)/h_z² for the unit half
vector h, and its tangent frame turned by γ about the normal (h_x, h_y read in the frame
(cos γ, sin γ), (−sin γ, cos γ)) so that a model is not mirror-symmetric about the plane
of incidence at φ_i = 0, and an optional non-reciprocal term k L_y V_y (L_x − V_x) (0 by
default). A ``DerivedBRDF`` with a Numba kernel, ``isotropic=False``.

Reference values, each independent of the albedo engine:

- a brute-force quadrature written here: a product of composite Gauss–Legendre rules in
  (u, φ_o) over the whole hemisphere, u = √cos θ_o (so that Ward's 1/√cos θ_o becomes
  smooth: μ dμ = 2u³ du), no lobe frame, no kinks, no symmetry; its convergence is
  checked by halving its panels;
- identities of the formula: period π in φ_i (f depends on h_x², h_y²), α_x ↔ α_y equals
  φ_i + π/2, a tangent frame turned by γ equals φ_i − γ, and α_x = α_y = m equals the
  registered isotropic ``ward`` (Neumann et al. 1999 eq. 8: the same normalisation,
  ρ_s e^{−tan²δ/m²}/(4π m² √(cos θ_i cos θ_o)), checked value for value below).
"""

from __future__ import annotations

import json
import math

import numba
import numpy as np
import pytest
from click.testing import CliRunner
from test_cli_inputs import assert_one_line_error  # the CLI's error contract

import brdfkit
from brdfkit._kern import INV_PI, below_horizon, half
from brdfkit.analysis import albedo, check, hemispherical_albedo
from brdfkit.analysis.monte_carlo import albedo_mc
from brdfkit.cli import main
from brdfkit.errors import BrdfkitError, ParameterError
from brdfkit.halfangle import beta_from_ward_m
from brdfkit.models._base import DerivedBRDF
from brdfkit.models._param import Lobe, Param
from brdfkit.models._params import packed_indices

# --------------------------------------------------------------------------- the model
PARAMS = (
    Param("rho_d", 0.1, 0.0, 1.0, "", "diffuse albedo"),
    Param("rho_s", 0.8, 0.0, 1.0, "", "specular albedo scale"),
    Param("alpha_x", 0.15, 1e-3, 1.0, "", "RMS slope along the tangent X"),
    Param("alpha_y", 0.4, 1e-3, 1.0, "", "RMS slope along the tangent Y"),
    Param("gamma", 0.0, -10.0, 10.0, "rad", "turn of the tangent frame about the normal"),
    Param("k", 0.0, -0.01, 0.01, "1/sr", "weight of a non-reciprocal term (0: Ward)"),
)
P_RD, P_RS, P_AX, P_AY, P_G, P_K = packed_indices(PARAMS, "rho_d", "rho_s", "alpha_x",
                                                  "alpha_y", "gamma", "k")


@numba.njit(cache=True)
def ward_anisotropic_kernel(ix, iy, iz, ox, oy, oz, p):
    if below_horizon(iz, oz):
        return 0.0
    hx, hy, hz, _ = half(ix, iy, iz, ox, oy, oz)
    c, s = math.cos(p[P_G]), math.sin(p[P_G])
    tx = (c * hx + s * hy) / p[P_AX]  # h along the turned tangents X, Y
    ty = (-s * hx + c * hy) / p[P_AY]
    lobe = math.exp(-(tx * tx + ty * ty) / (hz * hz))
    return (p[P_RD] * INV_PI
            + p[P_RS] * lobe / (4.0 * math.pi * p[P_AX] * p[P_AY] * math.sqrt(iz * oz))
            + p[P_K] * iy * oy * (ix - ox))  # |.| <= 2k < ρ_d/π: f stays positive


class WardAnisotropic(DerivedBRDF):
    """Ward 1992 eq. 5a, anisotropic (the model of this file)."""

    def __init__(self, isotropic: bool = False, **values):
        super().__init__(name="ward-anisotropic-test", params=PARAMS, values=values,
                         citation="Ward 1992 eq. 5a", reciprocal=True, isotropic=isotropic,
                         kernel=ward_anisotropic_kernel)

    def lobes(self):
        v = self._values
        sharpest = float(min(v["alpha_x"], v["alpha_y"]))
        return [Lobe("diffuse", math.pi / 2), Lobe("half", float(beta_from_ward_m(sharpest)))]


def brute_force(model, theta, phi, *, panels=64, order=16):
    """a(θ_i, φ_i) by a product of composite Gauss–Legendre rules in (u = √cos θ_o, φ_o)."""
    x, w = np.polynomial.legendre.leggauss(order)

    def composite(lo, hi, n):
        e = np.linspace(lo, hi, n + 1)
        half_width = (e[1:] - e[:-1])[:, None] / 2
        return ((e[:-1, None] + half_width) + half_width * x).ravel(), (half_width * w).ravel()

    u, wu = composite(0.0, 1.0, panels)
    p, wp = composite(0.0, 2.0 * math.pi, 2 * panels)
    U, PH = np.meshgrid(u, p, indexing="ij")
    mu = U * U
    st = np.sqrt(1.0 - mu * mu)
    wo = np.stack([st * np.cos(PH), st * np.sin(PH), mu], axis=-1).reshape(-1, 3)
    wi = np.array([math.sin(theta) * math.cos(phi), math.sin(theta) * math.sin(phi),
                   math.cos(theta)])
    f = np.asarray(model.eval(np.broadcast_to(wi, wo.shape), wo)).reshape(U.shape)
    return float(np.einsum("ij,i,j->", f * 2.0 * U ** 3, wu, wp))  # μ dμ dφ = 2u³ du dφ


ANGLES = [(0.0, 0.0), (30.0, 0.0), (30.0, 90.0), (60.0, 30.0), (60.0, 135.0),
          (75.0, 250.0), (80.0, -40.0)]


@pytest.fixture(scope="module")
def model():
    return WardAnisotropic()


# --------------------------------------------------------------------------- albedo
def test_albedo_matches_the_brute_force_quadrature(model):
    worst = 0.0
    for th, ph in ANGLES:
        t, p = math.radians(th), math.radians(ph)
        ref = brute_force(model, t, p)
        coarse = brute_force(model, t, p, panels=32)
        assert abs(coarse - ref) < 1e-10, (th, ph, coarse, ref)  # the reference converged
        r = albedo(model, t, phi=p)
        assert r.success, r.message
        assert abs(float(r.albedo) - ref) <= 1e-6, (th, ph, float(r.albedo), ref)
        assert float(r.error) <= 1e-6
        worst = max(worst, abs(float(r.albedo) - ref))
    # measured when written: 2e-11 worst over these angles (the engine's goal is 1e-7)
    assert worst < 1e-9


def test_a_turned_tangent_frame_matches_the_brute_force_quadrature():
    # not mirror-symmetric about the plane of incidence: the half-azimuth shortcut would be
    # wrong here, so this also tests that an anisotropic model is integrated over all φ_o
    m = WardAnisotropic(gamma=0.6, alpha_x=0.1, alpha_y=0.35)
    for th, ph in ((45.0, 0.0), (70.0, 10.0)):
        t, p = math.radians(th), math.radians(ph)
        ref = brute_force(m, t, p)
        assert abs(float(albedo(m, t, phi=p).albedo) - ref) <= 1e-6, (th, ph)
    # the same model claiming isotropy is integrated over half the azimuths and doubled,
    # at φ_i = 0 whatever phi says: wrong for this anisotropic formula (what `isotropic`
    # means is the engine's licence for the shortcut)
    liar = WardAnisotropic(isotropic=True, gamma=0.6, alpha_x=0.1, alpha_y=0.35)
    t = math.radians(45.0)
    assert abs(float(albedo(liar, t).albedo) - brute_force(m, t, 0.0)) > 1e-3


class _AsAnisotropic(DerivedBRDF):
    """A registered isotropic model with the same kernel, lobes and kinks, declared
    anisotropic: the engine then integrates all azimuths with the nodes rotated by φ_i."""

    def __init__(self, base):
        super().__init__(name=f"{base.name}-as-anisotropic", params=base.params,
                         values=base.to_dict()["params"], reciprocal=True, isotropic=False,
                         kernel=base.kernel, packed=base.packed)
        self._base = base
        self.albedo_kinks = base.albedo_kinks

    def lobes(self):
        return self._base.lobes()


@pytest.mark.parametrize("name, params", [
    ("modified-phong", {"n": 200.0}),  # mirror frame
    ("ward", {"m": 0.05}),  # half-vector frame
    ("cook-torrance", {"m": 0.2}),  # half-vector frame with the V-groove kinks
    ("minnaert", {"k": 1.5}),  # normal frame
])
def test_rotated_nodes_in_every_frame(name, params):
    # rotation invariance of an isotropic formula: a(θ_i, φ_i) = a(θ_i) for every φ_i,
    # integrated over all azimuths in the rotated frame against the registered model's
    # half-azimuth integral (two different node sets)
    base = brdfkit.model(name, **params)
    wrapped = _AsAnisotropic(base)
    th = np.radians([0.0, 35.0, 70.0, 88.0])
    ref = np.asarray(albedo(base, th).albedo)
    for ph in (0.0, 0.3, 2.0, -4.0):
        r = albedo(wrapped, th, phi=ph)
        assert r.success, r.message
        np.testing.assert_allclose(np.asarray(r.albedo), ref, rtol=0, atol=1e-8)


def test_albedo_changes_with_phi_and_has_period_pi(model):
    th = np.radians([30.0, 60.0, 80.0])
    phis = np.radians([0.0, 30.0, 60.0, 90.0])
    r = albedo(model, th[:, None], phi=phis[None, :])
    a = np.asarray(r.albedo)
    assert a.shape == (3, 4) and r.phi.shape == (3, 4)
    # α_x < α_y: measured, a grows from φ_i = 0 to 90° at each θ_i, more towards grazing
    assert np.all(np.diff(a, axis=1) > 0.0)
    assert np.all(np.diff(a[:, 3] - a[:, 0]) > 0.0) and a[0, 3] - a[0, 0] > 1e-3
    shifted = np.asarray(albedo(model, th[:, None], phi=phis[None, :] + math.pi).albedo)
    np.testing.assert_allclose(shifted, a, rtol=0, atol=1e-9)
    back = np.asarray(albedo(model, th[:, None], phi=phis[None, :] - 3 * math.pi).albedo)
    np.testing.assert_allclose(back, a, rtol=0, atol=1e-9)
    # at normal incidence there is no azimuth
    a0 = np.asarray(albedo(model, 0.0, phi=phis).albedo)
    np.testing.assert_allclose(a0, a0[0], rtol=0, atol=1e-9)


def test_swapping_alpha_x_and_alpha_y_is_a_quarter_turn():
    m = WardAnisotropic(alpha_x=0.12, alpha_y=0.3)
    swapped = WardAnisotropic(alpha_x=0.3, alpha_y=0.12)
    th = np.radians([20.0, 55.0, 78.0])
    for ph in (0.0, 0.4, 2.0):
        a = np.asarray(albedo(swapped, th, phi=ph).albedo)
        b = np.asarray(albedo(m, th, phi=ph + math.pi / 2).albedo)
        np.testing.assert_allclose(a, b, rtol=0, atol=1e-9)


def test_a_turned_tangent_frame_is_a_turned_incidence():
    gamma = 0.6
    turned = WardAnisotropic(gamma=gamma)
    m = WardAnisotropic()
    th = np.radians([35.0, 70.0])
    for ph in (0.0, 1.1):
        np.testing.assert_allclose(np.asarray(albedo(turned, th, phi=ph).albedo),
                                   np.asarray(albedo(m, th, phi=ph - gamma).albedo),
                                   rtol=0, atol=1e-9)


def test_equal_slopes_give_the_registered_isotropic_ward():
    # the registered ward (Neumann eq. 8) is eq. 5a with α_x = α_y = m, same normalisation:
    # first value for value, then the albedo at any azimuth
    m_iso = brdfkit.model("ward", rho_d=0.1, rho_s=0.8, m=0.2)
    m_an = WardAnisotropic(alpha_x=0.2, alpha_y=0.2)
    rng = np.random.default_rng(3)
    v = rng.normal(size=(2, 500, 3))
    v[..., 2] = np.abs(v[..., 2])
    wi, wo = v / np.linalg.norm(v, axis=-1, keepdims=True)
    np.testing.assert_allclose(m_an.eval(wi, wo), m_iso.eval(wi, wo), rtol=1e-13, atol=0)
    th = np.radians([0.0, 40.0, 70.0, 85.0])
    iso = np.asarray(albedo(m_iso, th).albedo)
    for ph in (0.0, 0.7, 2.5):
        np.testing.assert_allclose(np.asarray(albedo(m_an, th, phi=ph).albedo), iso,
                                   rtol=0, atol=1e-8)


def test_phi_is_recorded_and_validated(model):
    r = albedo(model, math.radians(40.0), phi=math.radians(30.0))
    d = r.to_dict()
    assert d["phi_deg"] == pytest.approx(30.0) and r.anisotropic
    assert "phi_deg" in albedo(model, 0.3).to_dict()  # an anisotropic model: always recorded
    iso = brdfkit.model("lambert", rho_d=0.5)
    assert "phi_deg" not in albedo(iso, 0.3).to_dict()  # isotropic JSON as before
    at = albedo(iso, np.radians([10.0, 50.0]), phi=1.0)
    assert at.to_dict()["phi_deg"] == pytest.approx([math.degrees(1.0)] * 2)
    # isotropic: φ_i is recorded, not applied (bit for bit the numbers at 0)
    ward = brdfkit.model("ward", m=0.1)
    th = np.radians([10.0, 60.0, 85.0])
    assert np.array_equal(albedo(ward, th, phi=2.0).albedo, albedo(ward, th).albedo)
    for bad in (float("nan"), float("inf"), "east", [0.0, None]):
        with pytest.raises(ParameterError, match="phi must be"):
            albedo(model, 0.3, phi=bad)
    with pytest.raises(ParameterError, match="broadcasts with theta_i"):
        albedo(model, [0.1, 0.2, 0.3], phi=[0.0, 1.0])


def test_monte_carlo_albedo_at_phi_agrees(model):
    # the second method (its own directions, cosine sampling: the model has no sampler)
    t, p = math.radians(75.0), math.radians(90.0)
    ref = float(albedo(model, t, phi=p).albedo)
    r = albedo_mc(model, t, phi=p, n_samples=1_000_000, rng=7)
    assert abs(float(r.albedo) - ref) < 4 * float(r.error)
    assert abs(float(albedo(model, t).albedo) - ref) > 20 * float(r.error)  # φ_i matters


def test_hemispherical_albedo_averages_the_incidence_azimuth(model):
    # ρ_hh = (1/π) ∫∫ a(θ, φ) cos θ sin θ dθ dφ, reference: the outer rule written here
    n, n_phi = 8, 8
    x, w = np.polynomial.legendre.leggauss(n)
    u = (x + 1) / 2
    th = np.arccos(u * u)
    phis = 2 * math.pi * np.arange(n_phi) / n_phi
    a = np.asarray(albedo(model, th[:, None], phi=phis[None, :]).albedo).mean(axis=1)
    ref = float(np.sum(w / 2 * 4 * u ** 3 * a))
    r = hemispherical_albedo(model, n=n, n_phi=n_phi)
    assert r.success, r.message
    assert float(r.value) == pytest.approx(ref, abs=1e-12)
    at_zero = float(np.sum(w / 2 * 4 * u ** 3 * np.asarray(albedo(model, th).albedo)))
    assert abs(at_zero - ref) > 1e-3  # the azimuth matters here
    with pytest.raises(ParameterError, match="n_phi must be"):
        hemispherical_albedo(model, n_phi=3)


# --------------------------------------------------------------------------- check
def test_check_of_the_anisotropic_model(model):
    v = check(model, phi=math.radians(90.0))
    assert v.reciprocity == "reciprocal" and v.max_asymmetry <= 1e-12
    # Ward's albedo diverges at grazing incidence (1/√cos θ_i), at every azimuth
    assert v.energy == "diverges"
    d = v.to_dict()
    assert d["phi_deg"] == pytest.approx(90.0)
    assert v.grazing[89.0] == pytest.approx(
        float(albedo(model, math.radians(89.0), phi=math.radians(90.0)).albedo), abs=1e-9)
    v0 = check(model)
    assert v0.to_dict()["phi_deg"] == 0.0  # anisotropic: always recorded
    assert v0.grazing[89.0] != pytest.approx(v.grazing[89.0], abs=1e-3)


def test_reciprocity_is_tested_at_absolute_azimuths():
    # k L_y V_y (L_x − V_x) changes sign when L and V swap, and vanishes whenever L lies in
    # the xz-plane: pairs with L at azimuth 0 (the isotropic pair set) cannot see it
    m = WardAnisotropic(k=0.01)
    wi = np.array([[math.sin(1.0) * math.cos(0.8), math.sin(1.0) * math.sin(0.8), math.cos(1.0)]])
    wo = np.array([[-0.5, 0.5, math.sqrt(0.5)]])
    extra = 0.01 * wi[0, 1] * wo[0, 1] * (wi[0, 0] - wo[0, 0])
    np.testing.assert_allclose(m.eval(wi, wo) - m.eval(wo, wi), 2 * extra, rtol=1e-12)
    v = check(m, tol=1e-5)
    assert v.reciprocity == "not reciprocal" and v.max_asymmetry > 1e-2
    # the same formula declaring itself isotropic is judged on relative azimuths only
    liar = WardAnisotropic(isotropic=True, k=0.01)
    assert check(liar, tol=1e-5).max_asymmetry <= 1e-12


# --------------------------------------------------------------------------- engines that refuse
def test_pumping_refuses_an_anisotropic_model(model):
    from brdfkit.pumping import pump

    with pytest.raises(BrdfkitError) as exc:
        pump(model, g="max")
    msg = str(exc.value)
    assert "\n" not in msg and "anisotropic" in msg and model.name in msg


def test_the_ambient_table_refuses_an_anisotropic_model(model):
    from brdfkit.render import render_sphere

    with pytest.raises(BrdfkitError) as exc:
        render_sphere(model, phi_l=0.5, ambient=0.2, size=16)
    msg = str(exc.value)
    assert "\n" not in msg and "anisotropic" in msg


# --------------------------------------------------------------------------- the CLI
def run(*args: str):
    return CliRunner().invoke(main, list(args))


@pytest.fixture()
def cli_model(monkeypatch, model):
    """The CLI's model builder returning the test's model for the name 'ward-aniso'."""
    import brdfkit.cli.analysis as cli_analysis

    real = cli_analysis.build_model

    def build(name, params=(), **operators):  # pump, times, compensate: passed on
        if name == "ward-aniso":
            return model
        return real(name, params, **operators)

    monkeypatch.setattr(cli_analysis, "build_model", build)
    return model


def test_cli_albedo_phi_json_csv_and_text(cli_model):
    r = run("albedo", "ward-aniso", "--theta", "30,60", "--phi", "90", "--json")
    assert r.exit_code == 0, r.output
    d = json.loads(r.stdout)
    assert d["phi_deg"] == 90.0
    ref = np.asarray(albedo(cli_model, np.radians([30.0, 60.0]), phi=math.pi / 2).albedo)
    np.testing.assert_allclose(d["albedo"], ref, rtol=0, atol=1e-12)
    r0 = json.loads(run("albedo", "ward-aniso", "--theta", "30,60", "--json").stdout)
    assert r0["phi_deg"] == 0.0 and abs(r0["albedo"][1] - d["albedo"][1]) > 1e-2
    neg = json.loads(run("albedo", "ward-aniso", "--theta", "60", "--phi", "-90",
                         "--json").stdout)
    assert neg["albedo"][0] == pytest.approx(d["albedo"][1], abs=1e-9)  # period π
    csv = run("albedo", "ward-aniso", "--theta", "30,60", "--phi", "90", "--csv").stdout
    lines = csv.strip().splitlines()
    assert lines[0] == "theta_deg,phi_deg,albedo,error"
    assert float(lines[2].split(",")[2]) == pytest.approx(ref[1], abs=1e-11)
    text = run("albedo", "ward-aniso", "--theta", "60", "--phi", "90").stdout
    assert "at phi = 90 deg" in text and f"{ref[1]:.9f}" in text


def test_cli_albedo_phi_of_an_isotropic_model():
    base = run("albedo", "ward", "-p", "m=0.1", "--theta", "20,70", "--json")
    turned = run("albedo", "ward", "-p", "m=0.1", "--theta", "20,70", "--phi", "33", "--json")
    assert base.exit_code == 0 and turned.exit_code == 0
    b, t = json.loads(base.stdout), json.loads(turned.stdout)
    assert "phi_deg" not in b and t["phi_deg"] == 33.0  # asked for: recorded
    assert t["albedo"] == b["albedo"]  # rotation invariant: the same numbers
    text = run("albedo", "ward", "-p", "m=0.1", "--theta", "20", "--phi", "33").stdout
    notes = [line for line in text.splitlines() if "no effect" in line]
    assert len(notes) == 1 and "isotropic" in notes[0]
    assert "no effect" not in run("albedo", "ward", "--theta", "20").stdout


def test_cli_check_phi(cli_model):
    r = run("check", "ward-aniso", "--phi", "90", "--json")
    assert r.exit_code == 0, r.output
    d = json.loads(r.stdout)
    assert d["phi_deg"] == 90.0 and d["reciprocity"] == "reciprocal"
    assert d["energy"] == "diverges"
    text = run("check", "ward-aniso", "--phi", "90").stdout
    assert "phi = 90 deg" in text and "reciprocal:   yes" in text
    iso = run("check", "lambert", "--phi", "45")
    assert iso.exit_code == 0
    assert sum("no effect" in line for line in iso.stdout.splitlines()) == 1
    iso_json = json.loads(run("check", "lambert", "--json").stdout)
    assert "phi_deg" not in iso_json


@pytest.mark.parametrize("command", ["albedo", "check"])
@pytest.mark.parametrize("value", ["nan", "inf", "-inf", "east", "", "1e999"])
def test_cli_bad_phi_is_one_error_line(command, value):
    assert_one_line_error(run(command, "lambert", "--phi", value), "--phi", "finite")


def test_figure_slices_at_phi(model):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from brdfkit.figures.models import _THETA_A_DEG, model_slices

    fig = model_slices(model, theta_i_deg=(60.0,), n_points=91, phi_deg=90.0)
    try:
        assert "90°" in fig._suptitle.get_text()
        ax_s, ax_a = fig.axes[:2]
        want = np.asarray(albedo(model, np.radians(_THETA_A_DEG), phi=math.pi / 2,
                                 tol=1e-4).albedo)
        np.testing.assert_allclose(ax_a.get_lines()[0].get_ydata(), want, rtol=0, atol=1e-12)
        # the slice lies in the plane at azimuth 90°: the mirror direction of L at
        # (60°, 90° + 180°) is V at (60°, 90°), where the plotted f is Ward's value there
        x, y = ax_s.get_lines()[0].get_data()
        k = int(np.argmin(np.abs(x - 60.0)))
        t, to = math.radians(60.0), math.radians(x[k])
        wi = np.array([0.0, -math.sin(t), math.cos(t)])
        wo = np.array([0.0, math.sin(to), math.cos(to)])
        assert y[k] == pytest.approx(float(model.eval(wi, wo)), rel=1e-12)
    finally:
        plt.close(fig)
    with pytest.raises(ParameterError, match="phi_deg"):
        model_slices(model, phi_deg=float("nan"))
