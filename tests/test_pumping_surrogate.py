"""brdfkit.pumping.surrogate: the fast one-times pumped model a fit evaluates.

Reference values are independent of the surrogate's tables: the specular albedo of
modified Phong from Lewis's H_s by its own quadrature (azimuth in closed form,
tanh-sinh in the polar angle: ``brdfkit.models.specular.specular_integral``), the exact
pumped model (its own table at the full accuracy, compiled kernel), and the parameters a
synthetic MERL table was made with.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

import brdfkit
import brdfkit.pumping.surrogate as sur
from brdfkit.fitting import fit
from brdfkit.fitting.samples import merl_samples
from brdfkit.models.specular import specular_integral
from brdfkit.pumping import PumpedBRDF, pump
from brdfkit.pumping.surrogate import SURROGATE_ALBEDO_TOL, surrogate

VARY = ("rho_d", "rho_s", "n")


def test_surrogate_albedo_within_its_stated_bound():
    # a = rho_d + rho_s (n+2)/(2 pi) H_s(theta, n) for modified Phong (Nielsen eq. 1: the
    # lobe's albedo is its normalisation times Lewis's H_s). The n are off the grid (between
    # nodes, where the interpolation error peaks) from a broad lobe to a sharp one, and
    # coloured linear parameters; the surrogate combines them from its basis tables.
    S = surrogate(pump(brdfkit.model("modified-phong")), VARY)
    assert S.linear == ("rho_d", "rho_s") and S.shape == ("n",)
    rho_d, rho_s = np.array([0.1, 0.0, 0.3]), np.array([0.7, 0.9, 0.2])
    theta = np.radians(np.linspace(0.0, 89.9, 60))
    worst = 0.0
    for j in (1, 13, 26, 38):  # node index: n = e^{0.3 (j + 1/2)}: 1.6, 55, 2500, 1e5
        n = math.exp(sur.LOG_SPACING * (j + 0.5))
        got = S.albedo({"rho_d": rho_d, "rho_s": rho_s, "n": n}, np.cos(theta))
        a_s = (n + 2.0) / (2.0 * math.pi) * specular_integral(theta, n, "phong")
        ref = rho_d[None, :] + rho_s[None, :] * a_s[:, None]
        worst = max(worst, float(np.max(np.abs(got - ref))))
    assert worst <= SURROGATE_ALBEDO_TOL


def test_surrogate_matches_the_exact_model_and_ignores_its_cache():
    # The exact pumped model (full-accuracy table, compiled kernel) is the reference of
    # f* = f/g on the MERL samples. g >= rho_d = 0.1 (the albedo is at least the diffuse
    # part), so an albedo error of SURROGATE_ALBEDO_TOL plus the exact table's 1e-5 gives a
    # relative error of f* below (5e-5 + 1e-5) / 0.1 = 6e-4.
    s = merl_samples()
    exact = pump(brdfkit.model("modified-phong", rho_d=0.1, rho_s=[0.8, 0.6, 0.4], n=700.0))
    vals = exact.values
    S = surrogate(exact, VARY)
    fe = exact.eval(s.wi, s.wo)
    fs = S.with_params(**vals).eval(s.wi, s.wo)
    assert fs.shape == fe.shape
    on = fe > 0.0
    assert np.max(np.abs(fs[on] - fe[on]) / fe[on]) <= 6e-4
    assert np.array_equal(fs > 0.0, on)
    # values are a function of the parameters only: the same bits after the node cache is
    # emptied and other parameter sets were evaluated first (fits are reproducible
    # whatever ran before them in the process)
    sur._NODE_CACHE.clear()
    S2 = surrogate(exact, VARY)
    S2.with_params(**{**vals, "n": 90.0}).eval(s.wi[:50], s.wo[:50])
    assert np.array_equal(S2.with_params(**vals).eval(s.wi, s.wo), fs)
    # not a one-times pumped model with a built-in g: no surrogate
    assert surrogate(exact.root, VARY) is None
    assert surrogate(pump(exact.root, lambda wi, wo, a_i, a_o: np.maximum(a_i, a_o)),
                     VARY) is None


def test_fit_recovers_a_pumped_phong_on_the_merl_grid():
    # Data: a one-times pumped modified Phong with known parameters (a sharp, coloured
    # lobe; the exact model, full-accuracy table) on the MERL-grid samples. g1 makes f/g
    # homogeneous of degree 0 in (rho_d, rho_s) per channel (f and a both scale), so only
    # the ratio rho_d/rho_s and n are determined: the fit must hold one of them per channel,
    # give the ratio and n back, and return the exact pumped model.
    truth = dict(rho_d=0.05, rho_s=0.6, n=1500.0)
    target = pump(brdfkit.model("modified-phong", **truth))
    r = fit(pump(brdfkit.model("modified-phong")), target, loss="l1")
    assert r.success and r.status == 0, r.message
    assert isinstance(r.model, PumpedBRDF) and r.model.depth == 1
    assert r.convergence["scale_held"] == ["rho_s"]
    assert r.params["n"] == pytest.approx(1500.0, rel=1e-2)
    assert r.params["rho_d"] / r.params["rho_s"] == pytest.approx(0.05 / 0.6, rel=1e-2)
    # an exact fit (to the tables' accuracy), and the surrogate's loss at the result is the
    # exact model's to that accuracy
    start = r.convergence["stages"][0]["loss_before"]
    assert r.value <= 1e-3 * start
    assert abs(r.convergence["surrogate"]["loss"] - r.value) <= 1e-3 * start
