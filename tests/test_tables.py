"""Tests of the shared tables (brdfkit.tables): the grid variable and the compiled Lookup.

The Lookup tests moved here from tests/test_pumping.py unchanged (reference: a closed
form with declared kinks); the grid variable is checked against its printed definition
in extended precision (no cancellation at grazing or at the normal).
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from brdfkit.tables import LUT_TOL, _lookup, build_lookup, mu_of_w, theta_of_w, w_of_mu


# --------------------------------------------------------------------------- grid variable
def test_grid_variable_round_trips_without_cancellation():
    """w(μ) = √(1 − √(1 − μ)), μ(w) = 1 − (1 − w²)², θ(w) = arccos μ(w), evaluated in
    extended precision (mpmath-free: Python's decimal at 50 digits) vs the float64
    definitions: relative error a few ulp over w ∈ [1e-8, 1], also where the printed
    forms cancel (μ → 0: 1 − √(1 − μ); w → 1: arccos near 1)."""
    from decimal import Decimal, getcontext

    getcontext().prec = 50
    w = np.r_[np.geomspace(1e-8, 1e-2, 40), np.linspace(0.01, 0.99, 99),
              1.0 - np.geomspace(1e-2, 1e-9, 40)]
    for wk in w:
        d = Decimal(float(wk))
        mu_ref = 1 - (1 - d * d) ** 2
        u = (1 - d * d)
        # θ = 2 asin(u/√2) via θ/2 = atan(u/√(2 − u²)): float64 of the exact ratio is enough
        t_ref = 2.0 * math.atan(float(u / (2 - u * u).sqrt()))
        mu = float(mu_of_w(wk))
        assert abs(mu - float(mu_ref)) <= 4e-16 * float(mu_ref)
        assert abs(float(theta_of_w(wk)) - t_ref) <= 4e-16 * max(t_ref, 1e-300)
        w_back = float(w_of_mu(float(mu_ref)))
        w_ref = float((1 - (1 - mu_ref).sqrt()).sqrt())
        # w(μ) is ill-conditioned at the normal (dw/dμ → ∞): compare there in θ instead
        if wk < 0.99:
            assert abs(w_back - w_ref) <= 4e-16 * w_ref
    assert theta_of_w(0.0) == 0.5 * math.pi and theta_of_w(1.0) == 0.0
    assert w_of_mu(0.0) == 0.0 and w_of_mu(1.0) == 1.0 and w_of_mu(1.5) == 1.0


# --------------------------------------------------------------------------- evaluation lookup
KINKS = [0.3, 0.3051]  # two kinks in one first-level cell ([19/64, 20/64))


def _kinked(mu):
    # closed form with kinks at KINKS (slope jumps 2 and 1) and a sharp rise near grazing
    mu = np.asarray(mu, dtype=float)
    return (1.0 + np.abs(mu - KINKS[0]) + 0.5 * np.abs(mu - KINKS[1])
            + 0.5 * np.exp(-mu / 0.01))[:, None]


@pytest.mark.parametrize("bound", ["upper", "lower"])
def test_lookup_accuracy_bound_and_kink_anchoring(bound):
    """Lookup vs a closed form at 2e5 random points: within 3 LUT_TOL, on the requested side;
    declared kinks are grid nodes (no refinement), undeclared ones cost intervals."""
    lk = build_lookup(_kinked, kinks=KINKS, bound=bound)
    mu = np.random.default_rng(1).uniform(0.0, 1.0, 200_000)
    exact = _kinked(mu)[:, 0]
    got = lk(mu)[:, 0]
    rel = (got - exact) / exact
    assert np.max(np.abs(rel)) <= 3 * LUT_TOL
    # from the requested side, up to rounding (the margin is verified at check points only)
    assert (np.min(rel) >= -1e-12) if bound == "upper" else (np.max(rel) <= 1e-12)
    exact_k = _kinked(np.array(KINKS))[:, 0]
    assert np.all(np.abs(lk(np.array(KINKS))[:, 0] / exact_k - 1.0) <= 3 * LUT_TOL)
    blind = build_lookup(_kinked, kinks=[], bound=bound)
    assert lk.n_intervals < blind.n_intervals / 2
    assert blind.max_error > 0.0 and lk.epsilon <= 2 * max(lk.max_error, 1e-15) + 1e-14


def test_lookup_kernel_matches_numpy_and_is_memory_safe():
    """The compiled _lookup and Lookup.__call__ agree bit for bit on [0, 1], and clamp
    outside it (unnormalised or NaN cosines never index outside the table)."""
    import numba

    lk = build_lookup(_kinked, kinks=KINKS)
    p = np.concatenate([[7.0, 8.0], lk.packed(0)])  # the lookup at an offset, as in a row

    @numba.njit
    def run(p, mus):
        out = np.empty(mus.size)
        for i in range(mus.size):
            out[i] = _lookup(p, 2, mus[i])
        return out

    mu = np.r_[np.linspace(0.0, 1.0, 10_001), np.nextafter(1.0, 2.0)]
    np.testing.assert_array_equal(run(p, mu), lk(mu)[:, 0])
    edge = run(p, np.array([1.0, 1.5, 1e300, -0.5, np.nan]))
    assert edge[1] == edge[2] == edge[0] and edge[3] == edge[4] == run(p, np.array([0.0]))[0]


# --------------------------------------------------------------------------- users of the Lookup
@pytest.mark.parametrize("n", [20.0, 1e4])
@pytest.mark.parametrize("lobe", ["phong", "blinn"])
def test_hs_lookup_is_a_tight_upper_bound(n, lobe):
    """phong-energy-conserving reads H_s from the shared Lookup: within 3e-9 of the
    quadrature (specular_integral, ~1e-11) and never below it, so F_s/H_s never gains
    energy (the albedo is <= k_rho up to rounding)."""
    from brdfkit.models.phong import _hs_table, specular_integral

    rng = np.random.default_rng(3)
    mu = np.r_[rng.random(2000) ** 4, 1.0 - rng.random(2000) ** 4, 1e-12, 1.0]
    exact = specular_integral(np.arccos(mu), n, lobe)
    rel = _hs_table(n, lobe)(mu)[:, 0] / exact - 1.0
    assert np.max(np.abs(rel)) <= 3e-9
    assert np.min(rel) >= -1e-13  # the margin is verified at check points only
