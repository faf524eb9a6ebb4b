"""Drafts of slow views (issue 23: a slider move drawn within 100 ms, measured in
benchmarks/bench_explorer.py): a request with ``"draft": true`` gets the slow parts of a
model whose family was slow before as drafts, marked ``"draft": true``, and the next
request with ``"draft": false`` the exact views (brdfkit.explorer.compute, "Drafts").

Reference values and their sources:
- the draft albedo curve of Lewis's Phong k_d + k_s F_s^P/(N·S): Lewis eq. (19),
  k_ρ = k_d π + k_s H_s/(N·S), H_s by its own quadrature (brdfkit.analysis.H_s, not the
  albedo engine), to the draft's stated DRAFT_ALBEDO_TOL;
- the draft pumped model against the exact pumped model (whose tables and accuracy are
  tested in tests/test_pumping*.py), to the draft's stated DRAFT_REL_TOL;
- the exact views after a draft: those of a fresh session that never drafted.
"""

from __future__ import annotations

import base64
import json
import math
import struct

import numpy as np
import pytest

import brdfkit
from brdfkit.analysis import H_s
from brdfkit.explorer import compute
from brdfkit.explorer.compute import Session
from brdfkit.pumping import pump
from brdfkit.pumping.draft import DRAFT_REL_TOL, draft_pump

STATE = {"theta_i": math.radians(30.0), "phi_i": 0.0, "phi_l": math.radians(30.0),
         "ambient": 0.0, "mode": "luminance", "cosine": False}


def _views(session, entry, draft):
    return json.loads(session.model_views(entry, {**STATE, "draft": draft}))


def _png_width(data_url: str) -> int:
    png = base64.b64decode(data_url.split(",", 1)[1])
    return struct.unpack(">I", png[16:20])[0]  # the IHDR chunk's width


def test_a_slow_family_is_drafted_then_exact(monkeypatch):
    """Every part counts as slow (DRAFT_ABOVE_S = 0) once its family was computed: the
    first request is exact (no cost known), a slider move with draft true gives the draft
    albedo curve and sphere, the same state with draft false the exact views, equal to a
    session's that never drafted; a request without "draft" never gets one."""
    monkeypatch.setattr(compute, "DRAFT_ABOVE_S", 0.0)
    s = Session()
    first = _views(s, {"spec": "phong", "params": {"k_d": 0.05, "k_s": 0.4, "n": 50.0}}, True)
    assert first["draft"] is False and len(first["albedo"]["theta_deg"]) == 90
    entry = {"spec": "phong", "params": {"k_d": 0.05, "k_s": 0.4, "n": 40.0}}
    d = _views(s, entry, True)
    assert d["draft"] is True
    th = np.radians(d["albedo"]["theta_deg"])
    assert th.size == compute.DRAFT_ALBEDO_ANGLES and _png_width(d["sphere"]) == \
        compute.DRAFT_SPHERE_SIZE
    ref = 0.05 * math.pi + 0.4 * H_s(th, 40.0, lobe="phong").albedo / np.cos(th)  # Lewis (19)
    assert np.max(np.abs(np.array(d["albedo"]["values"][0]) - ref)) <= compute.DRAFT_ALBEDO_TOL
    exact = _views(s, entry, False)
    assert exact["draft"] is False and _png_width(exact["sphere"]) == 256
    fresh = _views(Session(), entry, False)
    for key in ("albedo", "sphere", "polar", "halfdiff"):
        assert exact[key] == fresh[key], key
    # the page's next request (draft true) takes the exact views from the cache
    assert _views(s, entry, True) == exact
    moved = {**entry, "params": {**entry["params"], "n": 30.0}}
    no_key = json.loads(s.model_views(moved, STATE))  # an API client: never a draft
    assert no_key["draft"] is False and len(no_key["albedo"]["theta_deg"]) == 90


def test_a_fast_family_is_never_drafted(monkeypatch):
    """Parts that took at most DRAFT_ABOVE_S (here every part: the bound is huge) are
    never drafted: each slider move gets the exact views at once."""
    monkeypatch.setattr(compute, "DRAFT_ABOVE_S", 1e9)
    s = Session()
    for rho in (0.3, 0.4, 0.5):
        v = _views(s, {"spec": "lambert", "params": {"rho_d": rho}}, True)
        assert v["draft"] is False and len(v["albedo"]["theta_deg"]) == 90
        assert _png_width(v["sphere"]) == 256


def test_a_pumped_model_is_drafted_on_coarse_tables(monkeypatch):
    """A pumped model's slider move: the draft model first (its polar slice within
    DRAFT_REL_TOL of the exact model's), then the exact one."""
    monkeypatch.setattr(compute, "DRAFT_ABOVE_S", 0.0)
    s = Session()
    pumped = {"spec": "modified-phong", "pump": "controlled", "times": 1}
    _views(s, {**pumped, "params": {"rho_s": 0.5}}, True)
    entry = {**pumped, "params": {"rho_s": 0.45}}
    d = _views(s, entry, True)
    assert d["draft"] is True and d["name"] == "modified-phong+pump[controlled]"
    exact = _views(s, entry, False)
    assert exact["draft"] is False
    got, want = np.array(d["polar"]["values"]), np.array(exact["polar"]["values"])
    assert np.all(np.abs(got - want) <= DRAFT_REL_TOL * want)
    assert not np.array_equal(got, want)  # a draft indeed (coarser tables)


def test_draft_pump_within_its_stated_tolerance():
    """draft_pump against pump on random pairs (both g, twice, n = 5 and 500 with a
    small albedo at grazing): |f_draft − f| ≤ DRAFT_REL_TOL f, with fewer engine calls."""
    rng = np.random.default_rng(7)
    w = rng.normal(size=(2, 4000, 3))
    w[..., 2] = np.abs(w[..., 2]) + 1e-3
    wi, wo = w / np.linalg.norm(w, axis=-1, keepdims=True)
    for g, params in (("controlled", {"n": 5.0}),
                      ("max", {"n": 500.0, "rho_d": 0.0, "rho_s": 1.0})):
        base = brdfkit.model("modified-phong", **params)
        d, e = draft_pump(base, g, times=2), pump(base, g, times=2)
        fd, fe = d.eval(wi, wo), e.eval(wi, wo)
        assert np.all(np.abs(fd - fe) <= DRAFT_REL_TOL * fe), (g, params)
        assert d.table.n_evaluations < e.table.n_evaluations
        assert d.to_dict() == e.to_dict()
    with pytest.raises(brdfkit.BrdfkitError, match="times"):
        draft_pump(base, "max", times=9)


def test_compensate_is_part_of_the_cache_key():
    """Two entries that differ only in 'compensate' are two models (the session's cache
    key held spec, params, pump and times only: the second got the first's model)."""
    s = Session()
    plain = {"spec": "microfacet", "params": {"alpha": 0.5}}
    m1, _ = s.get_built(plain)
    m2, _ = s.get_built({**plain, "compensate": "kulla-conty"})
    assert m1.name != m2.name
