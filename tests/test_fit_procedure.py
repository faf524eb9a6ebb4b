"""The fitting procedure (issue 10 §3): a free parameter never makes a fit worse, a result at
a bound is never reported plain "converged", an index of refraction is recovered.

References are independent of the code under test: nested models (Nielsen's eq. (3) with
η → 0 is the model without η: the dielectric Fresnel factor is 1 under total internal
reflection, sin θ > η, so its L1 optimum bounds the one with η free from above), and the
parameters synthetic targets were made with.
"""

from __future__ import annotations

import pytest

import brdfkit
from brdfkit.fitting import fit
from brdfkit.fitting.procedure import AT_BOUND


def test_free_eta_never_makes_the_nielsen_fit_worse():
    # Regression: with η free (Fresnel on) Nielsen's procedure ended at L1 ≈ 0.0209 with
    # s → 1e6 and η → 0.01, reported "converged", where without η it reached ≈ 0.0127.
    # (coarser samples than the default, for speed: the identity holds on any samples)
    target = brdfkit.data.material("merl:two-layer-silver")
    kw = dict(procedure="nielsen", strides=(15, 45))
    without = fit(brdfkit.model("nielsen"), target, **kw)
    with_eta = fit(brdfkit.model("nielsen", eta=1.5), target, **kw)
    # nested models: min over (…, η) ≤ min over (…) with F = 1 (η → 0), up to the stopping
    # tolerance and F(η = 1e-6) = 1 − O(1e-6) at normal incidence
    assert with_eta.value <= without.value * (1.0 + 1e-4)
    for r in (without, with_eta):
        assert r.success
        s = r.params["s"]
        assert 1.0 < s < 1e4, s  # a broad lobe, not the mirror-like spike at the bound 1e6
        if r.convergence["at_bounds"]:
            assert r.status == AT_BOUND


def test_eta_is_recovered_and_an_undetermined_eta_is_reported_at_its_bound():
    # Synthetic grey targets: Nielsen's model evaluated at the MERL grid's bin centres.
    truth = dict(rho_d=0.1, k_s=30.0, s=300.0, alpha=0.3)
    # (a) η = 1.5 in the target, fitted from η = 1.2: every parameter back
    r = fit(brdfkit.model("nielsen", eta=1.2), brdfkit.model("nielsen", eta=1.5, **truth))
    assert r.success, r.message
    assert r.params["eta"] == pytest.approx(1.5, rel=2e-2)
    assert r.params["s"] == pytest.approx(300.0, rel=2e-2)
    assert r.params["alpha"] == pytest.approx(0.3, abs=2e-2)
    assert r.params["k_s"] == pytest.approx(30.0, rel=3e-2)
    assert r.params["rho_d"] == pytest.approx(0.1, rel=1e-2)
    # (b) the target has F = 1 (no η: the limit η → 0): the fit matches it and says that η
    # sits at (is indistinguishable from) its lower bound, never plain "converged"
    r = fit(brdfkit.model("nielsen", eta=1.5), brdfkit.model("nielsen", **truth))
    assert r.metrics["l1"] <= 1e-4 * r.convergence["stages"][0]["loss_before"]
    assert r.status == AT_BOUND, r.message
    assert "eta" in {b["parameter"] for b in r.convergence["at_bounds"]}, r.message
    assert "eta" in r.message
    # reproducible with the same seed
    again = fit(brdfkit.model("nielsen", eta=1.5), brdfkit.model("nielsen", **truth))
    assert again.params == r.params


def test_lafortune_gauge_held_and_the_lobe_recovered():
    # Lafortune data with C_xy = -1.6, C_z = 2, n = 12, rho_s = 0.1 (a lobe tilted towards
    # grazing). (C_xy, C_z) -> t (C_xy, C_z), rho_s -> rho_s / t^n leaves f unchanged
    # (identity of the formula), so from the default C_z = 1 (held: fit_gauge) the exact
    # answer is C_xy = -0.8, rho_s = 0.1 * 2^12 -- the same BRDF, which the fit must reach.
    from brdfkit.data import MeasuredBRDF, table_from_function

    src = brdfkit.model("lafortune", rho_d=0.1, rho_s=0.1, C_xy=-1.6, C_z=2.0, n=12.0)
    target = MeasuredBRDF(table_from_function(src.eval))
    r = fit(brdfkit.model("lafortune"), target, loss="l2")
    assert r.convergence["gauge_held"] == {"C_z[0]": 1.0}
    assert r.status == 0, r.message
    assert r.params["C_z"] == [1.0]
    assert r.params["C_xy"][0] == pytest.approx(-0.8, rel=1e-3)
    assert r.params["n"][0] == pytest.approx(12.0, rel=1e-3)
    assert r.params["rho_s"] == pytest.approx([0.1 * 2.0 ** 12] * 3, rel=1e-2)


def test_the_alpha_mix_is_never_worse_than_its_two_ends():
    # Nested models: Nielsen's α-mix contains the Phong-like (α = 0) and the Blinn-like
    # (α = 1) model, so its optimum is at most the better of their optima. Regression
    # (checked to fail without the fix): from α = 0.5 the search settled in the α ≈ 0 basin,
    # 0.00126 where α = 1 gives 0.00059 on blue-fabric with Fresnel (20 of 100 materials
    # were > 1 % worse in the study); under procedure="nielsen" the two ends are fitted
    # first and taken as candidates (BRDF.fit_bound_starts), which makes it hold.
    target = brdfkit.data.material("merl:blue-fabric")
    kw = dict(procedure="nielsen", strides=(15, 45))  # coarser samples, for speed
    mix = fit(brdfkit.model("nielsen", eta=1.5), target, **kw)
    ends = [fit(brdfkit.model("nielsen", eta=1.5, alpha=a), target, fixed={"alpha": a},
                **kw).value for a in (0.0, 1.0)]
    assert mix.value <= min(ends) * (1.0 + 2e-3), (mix.value, ends)
    labels = [s["start"] for s in mix.convergence["starts"]]
    assert "alpha = 0 fitted first" in labels and "alpha = 1 fitted first" in labels
    # the default procedure starts near both bounds instead (cheaper; not a guarantee)
    staged = fit(brdfkit.model("nielsen", eta=1.5), target, strides=(15, 45))
    labels = [s["start"] for s in staged.convergence["starts"]]
    assert "alpha near its lower bound" in labels and "alpha near its upper bound" in labels
    # Not a guarantee (above: with the starts near the bounds alone the study found 6 of 100
    # materials more than 1 % worse, docs/fitting.md), so the default procedure is held to
    # 1 % here, the study's margin: on AMD Zen 3 (AVX2) this fit came within 0.2 %, on an
    # Intel Xeon with AVX-512 (other SIMD rounding, another path through the simplex) within
    # 0.39 % (0.000595080 vs 0.000592743); without the bound starts it was 110 % worse.
    assert staged.value <= min(ends) * (1.0 + 1e-2), (staged.value, ends)


def test_the_ngan_projection_is_exact():
    # Reference: for a fixed lobe the ngan loss is a weighted least squares over the
    # samples with θ_i, θ_o ≤ 80° (its definition), solved here independently by
    # scipy.optimize.lsq_linear per channel; the fit's closed-form solution must reach it.
    # (Before, the solve used every sample: 20 % above this optimum on red-plastic.)
    import numpy as np
    from scipy.optimize import lsq_linear

    from brdfkit.fitting._problem import Problem
    from brdfkit.fitting.samples import merl_samples

    target = brdfkit.data.material("merl:red-plastic")
    lobe = {"C_xy": -1.4, "C_z": 1.0, "n": 24.0}
    r = fit(brdfkit.model("lafortune", **lobe), target, loss="ngan", fixed=dict(lobe))
    prob = Problem(brdfkit.model("lafortune", **lobe), target, merl_samples(), "ngan", 3)
    k, w = prob.ngan_mask, prob.w[prob.ngan_mask]
    s = prob.samples
    diffuse = np.asarray(brdfkit.model("lafortune", rho_d=1.0, rho_s=0.0, **lobe)
                         .eval(s.wi, s.wo)) * s.cos_i
    spec = np.asarray(brdfkit.model("lafortune", rho_d=0.0, rho_s=1.0, **lobe)
                      .eval(s.wi, s.wo)) * s.cos_i
    A = np.stack([diffuse[k], spec[k]], axis=1) * np.sqrt(w)[:, None]
    best = 0.0
    for c in range(3):
        sol = lsq_linear(A, prob.y[k, c] * np.sqrt(w), bounds=([0.0, 0.0], [1.0, 1e6]),
                         tol=1e-12)
        best += float(np.sum((A @ sol.x - prob.y[k, c] * np.sqrt(w)) ** 2))
    reference = float(np.sqrt(best / (np.sum(w) * 3)))
    assert r.value == pytest.approx(reference, rel=1e-6)


def test_a_parameter_the_data_do_not_determine_is_called_inert_not_at_a_bound():
    # Regression (issue 20): a diffuse target fitted by Nielsen's model ends with k_s = 0,
    # and then s and alpha change nothing (identity of eq. (3): the lobe's weight is k_s),
    # which was reported "s = 27.39, indistinguishable from its lower bound 0" and
    # "alpha = 0.9999, indistinguishable from its lower bound 0" (α sat at its *upper* one).
    target = brdfkit.model("nielsen", rho_d=0.3, k_s=0.0)  # Lambertian: f = 0.3/π
    r = fit(brdfkit.model("nielsen"), target, strides=(15, 45))
    assert r.params["k_s"] == pytest.approx(0.0, abs=1e-9)
    assert r.params["rho_d"] == pytest.approx(0.3, rel=1e-6)
    assert {"s", "alpha"} <= set(r.convergence["inert"]), r.message
    bounded = {b["parameter"] for b in r.convergence["at_bounds"]}
    assert not bounded & {"s", "alpha"}, r.message
    assert "inert" in r.message and "indistinguishable" not in r.message, r.message
    # an at-bound coordinate is named with its value and which bound
    assert "k_s = 0, at its lower bound 0" in r.message, r.message
