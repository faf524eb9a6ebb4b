"""brdfkit.fitting: sample measure, linear solves, synthetic recovery, the ``fit`` command.

Reference values are independent of the code under test: closed-form measures of
direction-pair domains, closed-form albedos, SciPy's bounded least squares and
linear programming, and the parameters a synthetic target was made with.
"""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
from click.testing import CliRunner
from scipy.optimize import linprog, lsq_linear

import brdfkit
from brdfkit.cli import main
from brdfkit.data import MeasuredBRDF, table_from_function, write_binary
from brdfkit.errors import ParameterError
from brdfkit.fitting import fit
from brdfkit.fitting._linear import box_lstsq, solve_channel
from brdfkit.fitting.samples import (
    _edges,
    albedo_from_values,
    albedo_nodes,
    bin_measure,
    merl_samples,
)


def test_sample_weights_are_the_measure_of_the_pair_domain():
    # All MERL bins: θ_h ∈ [0, π/2] (quadratic spacing), θ_d ∈ [0, π/2], φ_d ∈ [0, π).
    # With dω_i dω_o = 4 cos θ_d dω_h dω_d this is 2π · 1 · ½ · π · 4 = 4π², the pairs with
    # h in the upper hemisphere (half of (4π)²) folded in φ_d (half again): closed form.
    h, d, p = _edges()
    assert bin_measure(h, d, p).sum() == pytest.approx(4 * math.pi ** 2, rel=1e-13)
    # Bins whose centre has both directions above the horizon: the pairs of two upper
    # hemispheres, (2π)², folded: 2π², up to the bins the horizon cuts (< 1e-3).
    s = merl_samples(strides=(1, 1))
    assert s.weight.sum() == pytest.approx(2 * math.pi ** 2, rel=1e-3)
    # merged cells keep the measure of their bins, with coarser horizon cells (< 1 %)
    assert merl_samples().weight.sum() == pytest.approx(2 * math.pi ** 2, rel=1e-2)
    # Ngan's 80° cut-off: both θ ≤ 80°: (2π(1 − cos 80°))², folded
    s80 = merl_samples(strides=(1, 1), theta_max=math.radians(80))
    ref = 0.5 * (2 * math.pi * (1 - math.cos(math.radians(80)))) ** 2
    assert s80.weight.sum() == pytest.approx(ref, rel=1e-2)


def test_albedo_quadrature_closed_forms():
    wi, wo, w, T = albedo_nodes((0.0, 30.0, 60.0, 80.0))
    # Lambertian ρ = 1: a(θ) = 1 for every θ
    lam = brdfkit.model("modified-phong", rho_d=1.0, rho_s=0.0)
    a = albedo_from_values(lam.eval(wi, wo)[:, None], w, T)[:, 0]
    np.testing.assert_allclose(a, 1.0, atol=2e-3)
    # the normalised Phong lobe (n + 2)/2π cosⁿ at normal incidence integrates to 1
    # (∫ (n+2)/2π cosⁿθ cosθ dω = 1), a sharp one included
    for n in (10.0, 3000.0):
        ph = brdfkit.model("modified-phong", rho_d=0.0, rho_s=1.0, n=n)
        a = albedo_from_values(ph.eval(wi, wo)[:, None], w, T)[:, 0]
        assert a[0] == pytest.approx(1.0, abs=2e-3)


def test_linear_solves_match_scipy():
    rng = np.random.default_rng(3)
    N = 400
    A = np.ascontiguousarray(rng.random((N, 3)))
    r = A @ np.array([0.2, 1.5, -0.3]) + 0.05 * rng.standard_normal(N)
    w = rng.random(N) + 0.1
    lo, hi = np.array([0.0, 0.0, 0.0]), np.array([1.0, 1e6, 1.0])
    # L2 with bounds (the true third coefficient is negative: it lands on its bound)
    got = solve_channel(A, r, w, lo, hi, False, 0, np.empty(0))
    sw = np.sqrt(w)
    ref = lsq_linear(A * sw[:, None], r * sw, bounds=(lo, hi), tol=1e-12).x
    np.testing.assert_allclose(got, ref, atol=1e-8)
    G = (A * w[:, None]).T @ A
    np.testing.assert_allclose(box_lstsq(G, (A * w[:, None]).T @ r, lo, hi), ref, atol=1e-8)
    # L1 with bounds, against the linear program min Σ w t, −t ≤ A p − r ≤ t
    got = solve_channel(A, r, w, lo, hi, True, 200, np.empty(0))
    c = np.concatenate([np.zeros(3), w])
    A_ub = np.block([[A, -np.eye(N)], [-A, -np.eye(N)]])
    b_ub = np.concatenate([r, -r])
    lp = linprog(c, A_ub=A_ub, b_ub=b_ub, bounds=list(zip(lo, hi, strict=True)) + [(0, None)] * N)
    l1 = lambda p: float(np.sum(w * np.abs(A @ p - r)))  # noqa: E731
    assert l1(got) == pytest.approx(lp.fun, rel=1e-5)


def test_recovers_nielsen_parameters_from_a_merl_table():
    # A MERL table of known Nielsen parameters (a sharp lobe, s in the thousands), read
    # back through MeasuredBRDF: the fit from the declared defaults (s = 20) must return
    # the parameters the table was made with.
    truth = dict(rho_d=[0.05, 0.1, 0.2], k_s=[300.0, 250.0, 200.0], s=2000.0, alpha=0.3)
    src = brdfkit.model("nielsen", **truth)
    target = MeasuredBRDF(table_from_function(src.eval))
    r = fit(brdfkit.model("nielsen"), target, loss="l2")
    assert r.success and r.status in (0, 1), r.message
    p = r.params
    assert p["s"] == pytest.approx(2000.0, rel=1e-2)
    assert p["alpha"] == pytest.approx(0.3, abs=1e-2)
    np.testing.assert_allclose(p["rho_d"], truth["rho_d"], rtol=1e-2)
    np.testing.assert_allclose(p["k_s"], truth["k_s"], rtol=2e-2)
    assert r.metrics["l2"] < 1e-6 * r.convergence["stages"][0]["loss_before"]
    assert r.convergence["linear"] == ["rho_d", "k_s"]


def run(*args):
    return CliRunner().invoke(main, list(args))


def test_fit_command_recovers_a_sharp_phong_lobe_and_its_json_round_trips(tmp_path):
    # modified Phong with n = 3000 written as a MERL .binary; -p holds rho_d at its true
    # value; the rest is fitted with the default L1 procedure from n = 20.
    src = brdfkit.model("modified-phong", rho_d=0.1, rho_s=0.7, n=3000.0)
    path = write_binary(tmp_path / "phong.binary", table_from_function(src.eval))
    res = run("fit", "modified-phong", "--to", str(path), "-p", "rho_d=0.1", "--json")
    assert res.exit_code == 0, res.output
    d = json.loads(res.output)
    assert set(d) >= {"model", "params", "metrics", "albedo", "convergence"}
    assert d["params"]["rho_d"] == 0.1  # held
    assert d["params"]["n"] == pytest.approx(3000.0, rel=1e-2)
    np.testing.assert_allclose(d["params"]["rho_s"], 0.7, rtol=1e-2)
    assert set(d["metrics"]) == {"l1", "l2", "ngan", "log", "perceptual"}
    # the fitted params go straight back as -p
    items = [f"{k}={','.join(map(str, v)) if isinstance(v, list) else v}"
             for k, v in d["params"].items()]
    back = brdfkit.model("modified-phong", **{k: v for k, v in d["params"].items()})
    res = run("eval", "modified-phong", *sum((["-p", i] for i in items), []), "--wi", "30,0",
              "--wo", "30,180", "--json")
    assert res.exit_code == 0, res.output
    assert back is not None


def test_fit_rejects_bad_arguments():
    m = brdfkit.model("modified-phong")
    with pytest.raises(ParameterError, match="loss must be one of l1, l2, ngan, log"):
        fit(m, m, loss="l3")
    with pytest.raises(ParameterError, match="procedure must be one of"):
        fit(m, m, procedure="fast")
    with pytest.raises(ParameterError, match="target must be a brdfkit model"):
        fit(m, "merl:nickel")
    res = run("fit", "modified-phong", "--to", "merl:nickel", "--loss", "l3")
    assert res.exit_code == 2


def test_fit_command_start_frees_an_optional_parameter(tmp_path):
    # nielsen with a Fresnel index eta = 1.8 (its default is None: no Fresnel) written as a
    # MERL .binary; --start eta=1.5 must fit eta (reference: the value the data were made
    # with), -p holds s and alpha at their true values to keep the fit small.
    src = brdfkit.model("nielsen", rho_d=0.2, k_s=0.5, s=40.0, alpha=0.5, eta=1.8)
    path = write_binary(tmp_path / "fresnel.binary", table_from_function(src.eval))
    res = run("fit", "nielsen", "--to", str(path), "--start", "eta=1.5", "-p", "s=40",
              "-p", "alpha=0.5", "--json")
    assert res.exit_code == 0, res.output
    d = json.loads(res.output)
    np.testing.assert_allclose(d["params"]["eta"], 1.8, rtol=1e-2)
    assert d["params"]["s"] == 40.0  # held
    # the same name held and started: one line, exit 2
    res = run("fit", "nielsen", "--to", str(path), "--start", "eta=1.5", "-p", "eta=2")
    assert res.exit_code == 2 and "both -p (held) and --start (fitted)" in res.output
    # a malformed --start item: the error names --start, not -p
    res = run("fit", "nielsen", "--to", str(path), "--start", "eta")
    assert res.exit_code == 2 and "(e.g. --start rho_d=0.5); got 'eta'" in res.output


@pytest.mark.parametrize("adaptive", [False, True])
def test_simplex_search_takes_scipys_steps(adaptive):
    # Reference: scipy.optimize.minimize(method="Nelder-Mead", xatol=inf), which the
    # procedure called before brdfkit.fitting._simplex replaced it (an independent
    # implementation of the same algorithm): the same evaluations give the same result.
    from scipy.optimize import minimize

    from brdfkit.fitting._simplex import nelder_mead

    def rosen(x):
        return float(np.sum(100.0 * (x[1:] - x[:-1] ** 2) ** 2 + (1.0 - x[:-1]) ** 2))

    x0 = np.array([-1.2, 1.0, 0.5])
    simplex = np.vstack([x0] + [x0 + 0.3 * np.eye(3)[k] for k in range(3)])
    for maxfev in (7, 150, 2000):  # cut inside the first simplex, mid-run, converged
        ref = minimize(rosen, x0, method="Nelder-Mead",
                       options={"initial_simplex": simplex, "maxfev": maxfev,
                                "xatol": math.inf, "fatol": 1e-10, "adaptive": adaptive})
        x, fx, nfev = nelder_mead(rosen, simplex, maxfev=maxfev, fatol=1e-10,
                                  adaptive=adaptive)
        assert nfev == ref.nfev
        assert fx == ref.fun
        np.testing.assert_array_equal(x, ref.x)


@pytest.mark.parametrize("K", [1, 2, 3, 4])
def test_solve_channels_matches_the_single_channel_solve_and_its_loss(K):
    # Reference: solve_channel per channel (itself checked against lsq_linear and linprog
    # above) and the loss summed in NumPy; K = 4 takes the general (not vectorised) path.
    from brdfkit.fitting._linear import solve_channels

    rng = np.random.default_rng(K)
    N, C = 500, 3
    B = rng.random((K, N, C))
    R = np.einsum("knc,k->nc", B, rng.random(K)) + 0.05 * rng.standard_normal((N, C))
    w = rng.random(N) + 0.1
    lo, hi = np.zeros(K), np.full(K, 10.0)
    for l1 in (False, True):
        P, total = solve_channels(B, R, w, lo, hi, l1, 20, np.empty((0, 0)))
        ref = np.stack([solve_channel(np.ascontiguousarray(B[:, :, c].T),
                                      np.ascontiguousarray(R[:, c]), w, lo, hi, l1, 20,
                                      np.empty(0)) for c in range(C)], axis=1)
        np.testing.assert_allclose(P, ref, rtol=1e-12, atol=1e-14)
        d = np.einsum("knc,kc->nc", B, P) - R
        assert total == pytest.approx(float(np.sum(w[:, None] * (np.abs(d) if l1 else d * d))),
                                      rel=1e-12)
    B[0, 3, 1] = np.nan  # a non-finite basis value: the loss is inf, not NaN
    assert solve_channels(B, R, w, lo, hi, True, 3, np.empty((0, 0)))[1] == math.inf


def test_albedo_error_estimate_bounds_the_true_error():
    # References: closed forms and a second method. Lambertian: a(θ) = ρ at every θ.
    # Modified Phong (f = ρ_d/π + ρ_s (n + 2)/(2π) cosⁿα, α the angle to the mirror
    # direction): at normal incidence the mirror is the normal, ∫ cosⁿθ cos θ dω = 2π/(n + 2),
    # so a(0) = ρ_d + ρ_s; at the other angles the albedo engine (error ≤ 1e-9, stated).
    from brdfkit.analysis import albedo
    from brdfkit.fitting.samples import ALBEDO_THETA_DEG, albedo_with_error

    wi, wo, w, T = albedo_nodes(ALBEDO_THETA_DEG)
    rho = np.array([0.2, 0.5, 0.9])
    f = np.asarray(brdfkit.model("lambert", rho_d=rho).eval(wi, wo)).reshape(len(w), -1)
    a, err = albedo_with_error(f, w, T, 48, 24)
    assert err.shape == a.shape == (T, 3)
    assert np.all(np.abs(a - rho) <= err)
    assert err.max() <= 2e-2 * rho.max()  # and not vacuous: a small fraction of a
    for n in (1.0, 20.0, 300.0):
        m = brdfkit.model("modified-phong", rho_d=0.2, rho_s=0.6, n=n)
        f = np.asarray(m.eval(wi, wo)).reshape(len(w), -1)
        a, err = albedo_with_error(f, w, T, 48, 24)
        assert abs(a[0, 0] - 0.8) <= err[0, 0], n
        ref = albedo(m, np.radians(ALBEDO_THETA_DEG), tol=1e-9)
        assert np.max(ref.error) <= 1e-8
        assert np.all(np.abs(a[:, 0] - np.ravel(ref.albedo)) <= err[:, 0]), n
        assert err.max() <= 0.05 * 0.8  # not vacuous (a sharp lobe: the largest, n = 300)
    with pytest.raises(ParameterError, match="multiples of 3"):
        albedo_with_error(f, w, T, 48, 25)


def test_fit_result_albedos_carry_their_error():
    # A Lambertian fitted to a Lambertian: both albedo curves are the fitted and the
    # target's ρ (closed form), within the reported error estimates; the JSON carries them
    # after the albedo keys it always had.
    target = brdfkit.model("lambert", rho_d=[0.3, 0.5, 0.7])
    r = fit(brdfkit.model("lambert"), target, loss="l2")
    rho_fit = np.asarray(r.params["rho_d"])
    assert rho_fit == pytest.approx([0.3, 0.5, 0.7], rel=1e-9)
    assert np.all(np.abs(r.albedo_model - rho_fit) <= r.albedo_model_error)
    assert np.all(np.abs(r.albedo_target - np.array([0.3, 0.5, 0.7])) <= r.albedo_target_error)
    d = r.to_dict()["albedo"]
    assert list(d) == ["theta_deg", "model", "target", "rel_error", "model_error",
                       "target_error"]
    assert np.asarray(d["model_error"]).shape == r.albedo_model.shape
