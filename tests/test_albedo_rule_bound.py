"""A bound on the fitting's fixed albedo rule (issue 18 §3: it had no error estimate).

``brdfkit.fitting.samples.albedo_nodes`` integrates a(θ_i) with a fixed 48 × 24 midpoint
rule over the half vector; ``FitResult``'s albedos (and the perceptual loss's, at 24 × 12)
come from it. Reference (a second, independent method): the albedo engine
(:func:`brdfkit.analysis.albedo`, adaptive Gauss–Kronrod with its own error estimate,
here to 1e-6) at the same angles, 0–85°. Measured: at most 1.04e-3 absolute and 4.3e-3
relative over the models below (modified Phong n = 200 and 2000 and the 85° horizon cut
are the worst); the bound asserted is twice that. The rule's self-estimate |48×24 −
24×12| is *not* a bound (it is below the true error at some angles), so the bound is
this measurement.
"""

from __future__ import annotations

import numpy as np
import pytest

import brdfkit
from brdfkit.analysis import albedo
from brdfkit.fitting.samples import ALBEDO_THETA_DEG, albedo_from_values, albedo_nodes

ABS_BOUND, REL_BOUND = 2e-3, 1e-2  # twice the measured 1.04e-3 and 4.3e-3


@pytest.mark.parametrize("spec, params", [
    ("lambert", {}),
    ("modified-phong", {"n": 20.0}),
    ("modified-phong", {"n": 200.0}),
    ("modified-phong", {"n": 2000.0}),
    ("microfacet", {"distribution": "ggx", "alpha": 0.1}),
    ("ward", {}),
    ("merl:nickel", {}),
    ("merl:blue-acrylic", {}),
    ("merl:gold-metallic-paint", {}),
])
def test_fixed_albedo_rule_within_its_bound(spec, params):
    m = brdfkit.model(spec, **params)
    wi, wo, w, n_theta = albedo_nodes(ALBEDO_THETA_DEG)
    rule = albedo_from_values(np.asarray(m.eval(wi, wo)).reshape(len(wi), -1), w, n_theta)
    r = albedo(m, np.radians(ALBEDO_THETA_DEG), tol=1e-6)
    assert r.success
    ref = np.asarray(r.albedo).reshape(n_theta, -1)
    err = np.abs(rule - ref)
    assert err.max() <= ABS_BOUND, err.max()
    assert (err / ref).max() <= REL_BOUND, (err / ref).max()
