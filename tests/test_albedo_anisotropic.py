"""The albedo engine on an elongated half-vector lobe (``microfacet-anisotropic``), the
explorer's tolerance (views.ALBEDO_TOL = 1e-4): converged after ONE refinement at most,
within the tolerance and below its error estimate.

Reference (a second method, not the engine): a dense product rule in the NORMAL frame,
θ_o by composite Gauss–Legendre (12 panels of 50 nodes on [0, π/2]) and φ_o by the
trapezoid rule over the full circle (1200 nodes: spectrally accurate for the periodic,
analytic integrand), f from the model's kernel. Doubling both node counts changes it by
≤ 2.2e-16 at these angles (checked when the test was written), so it is exact to ~1e-15.

Before the azimuth break points of :func:`brdfkit.analysis.quadrature._axis_breaks` the
level-0 panels put 15 azimuths across a crest ~0.15 rad wide (true error 0.026) and the
level-1 estimate was 4e-4 (true 1.4e-6): 68 of the explorer's 90 angles needed level 2,
so with MAX_LEVEL = 1 this test failed (status MAX_LEVEL_REACHED).
"""

from __future__ import annotations

import math

import numpy as np
import pytest

import brdfkit
from brdfkit.analysis import albedo
from brdfkit.analysis.albedo_engine import evaluate_pairs
from brdfkit.explorer.views import ALBEDO_TOL

#: the reference rule: GL_PANELS panels of GL_NODES nodes in θ_o, PHI_NODES in φ_o
GL_PANELS, GL_NODES, PHI_NODES = 12, 50, 1200


def _reference(model, theta, phi):
    """a(θ_i, φ_i) by the product rule of the module docstring."""
    x, w = np.polynomial.legendre.leggauss(GL_NODES)
    edges = np.linspace(0.0, 0.5 * math.pi, GL_PANELS + 1)
    half = 0.5 * np.diff(edges)
    t = (half[:, None] * x + (0.5 * (edges[:-1] + edges[1:]))[:, None]).ravel()
    wt = (half[:, None] * w).ravel()
    p = 2.0 * math.pi * np.arange(PHI_NODES) / PHI_NODES
    tt, pp = np.meshgrid(t, p, indexing="ij")
    wo = np.stack([np.sin(tt) * np.cos(pp), np.sin(tt) * np.sin(pp), np.cos(tt)], -1)
    wi = np.array([[math.sin(theta) * math.cos(phi), math.sin(theta) * math.sin(phi),
                    math.cos(theta)]])
    f = evaluate_pairs(model, wi, wo.reshape(-1, 3))[:, 0].reshape(tt.shape)
    return float(np.sum(f * np.cos(tt) * np.sin(tt) * wt[:, None]) * 2.0 * math.pi / PHI_NODES)


@pytest.mark.parametrize("params", [{}, {"distribution": "ggx", "alpha_x": 0.3,
                                         "alpha_y": 0.05}])
def test_elongated_lobe_converges_by_level_one(monkeypatch, params):
    eng = __import__("brdfkit.analysis.albedo_engine", fromlist=["MAX_LEVEL"])
    monkeypatch.setattr(eng, "MAX_LEVEL", 1)
    model = brdfkit.model("microfacet-anisotropic", **params)
    # the explorer's curve (90 angles up to 89.5°) at an oblique incidence azimuth: the
    # crests lie at different azimuths in the two halves of the node frame
    th = np.radians(np.linspace(0.0, 89.5, 90))
    r = albedo(model, th, phi=0.7, tol=ALBEDO_TOL)
    assert r.success, r.message
    for k in (0, 40, 78):
        want = _reference(model, float(th[k]), 0.7)
        err = abs(float(r.albedo[k]) - want)
        assert err <= ALBEDO_TOL, (k, err)
        assert err <= float(r.error[k]), (k, err, float(r.error[k]))  # honest estimate
