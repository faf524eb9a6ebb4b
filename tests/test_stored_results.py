"""A material's long analyses: the albedo engine through its own loop, results kept on disk.

References: the engine's result through the per-channel kernel (a second path to the same
integral: the own loop must agree to rounding, the net's blocked driver reassociates sums,
~1e-13 relative); the identity f^T(ω_i, ω_o) = f(ω_o, ω_i) of the transposed model; a
result read back from disk is bit-identical to the one computed (what a cache promises).
"""

from __future__ import annotations

import copy

import numpy as np
import pytest

import brdfkit
from brdfkit._cache import clear_caches
from brdfkit.analysis import albedo_engine, stored
from brdfkit.analysis.plausibility import check
from brdfkit.render import ambient

THETA = np.radians([0.0, 40.0, 80.0])


@pytest.fixture
def store_dir(tmp_path, monkeypatch):
    monkeypatch.setattr(stored, "_root", lambda: tmp_path)
    return tmp_path


@pytest.fixture(scope="module")
def nickel():
    return brdfkit.model("merl:nickel")


def _counting(monkeypatch, module, name):
    calls = []
    inner = getattr(module, name)

    def wrapper(*args, **kwargs):
        calls.append(1)
        return inner(*args, **kwargs)

    monkeypatch.setattr(module, name, wrapper)
    return calls


def test_engine_runs_a_material_through_its_own_loop(nickel, monkeypatch):
    fast = copy.copy(nickel)
    calls = []

    def driver(wi, wo, data, out):
        calls.append(wi.shape[0])
        return nickel._driver(wi, wo, data, out)

    fast._driver = driver
    slow = copy.copy(nickel)
    slow._driver = None  # the per-channel kernel path of the "albedo" loop
    a = albedo_engine.albedo(fast, THETA, tol=1e-4)
    b = albedo_engine.albedo(slow, THETA, tol=1e-4)
    assert calls, "the engine did not use the model's own loop"
    assert a.success and b.success
    np.testing.assert_allclose(a.albedo, b.albedo, rtol=1e-11, atol=0)


def test_transposed_material_keeps_its_own_loop_swapped(nickel, random_hemisphere, rng):
    t = ambient.transposed(nickel)
    assert t._driver is not None
    wi, wo = random_hemisphere(rng, 500), random_hemisphere(rng, 500)
    np.testing.assert_array_equal(t.eval(wi, wo), nickel.eval(wo, wi))


def test_material_albedo_is_kept_and_read_back_bit_for_bit(store_dir, monkeypatch):
    m = brdfkit.model("merl:nickel@abc")
    first = stored.stored_albedo(m, THETA, tol=1e-6)
    assert len(list(store_dir.glob("*.npz"))) == 1
    calls = _counting(monkeypatch, albedo_engine, "albedo")
    again = stored.stored_albedo(m, THETA, tol=1e-6)
    assert not calls, "a kept result was recomputed"
    for field in ("theta", "albedo", "error", "status"):
        np.testing.assert_array_equal(getattr(again, field), getattr(first, field))
    # another request (tolerance, angles) or another material is another entry
    stored.stored_albedo(m, THETA, tol=1e-5)
    stored.stored_albedo(brdfkit.model("merl:gold-metallic-paint@abc"), THETA, tol=1e-6)
    assert len(calls) == 2


def test_damaged_entry_is_recomputed_and_analytic_models_are_not_kept(store_dir):
    m = brdfkit.model("merl:nickel@abc")
    ref = stored.stored_albedo(m, THETA, tol=1e-6)
    (entry,) = store_dir.glob("*.npz")
    entry.write_bytes(b"not a zip file")
    np.testing.assert_array_equal(stored.stored_albedo(m, THETA, tol=1e-6).albedo, ref.albedo)
    entry.unlink()
    stored.stored_albedo(brdfkit.model("lambert", rho_d=0.5), THETA, tol=1e-6)
    assert not list(store_dir.glob("*.npz"))


def test_check_of_a_material_reads_its_albedo_from_disk(store_dir, monkeypatch):
    m = brdfkit.model("merl:nickel@abc")
    v1 = check(m)
    calls = _counting(monkeypatch, albedo_engine, "albedo")
    v2 = check(m)
    assert not calls
    assert v2.to_dict() == v1.to_dict()


def test_ambient_table_of_a_material_is_kept_on_disk(store_dir, monkeypatch):
    # brdfkit.model gives every caller the same catalogue object, whose ambient tables live
    # in memory with it: a table an earlier test in this process built for it (the CLI's
    # render sphere --ambient of tests/test_cli_progress.py) was returned without reaching
    # this test's store, and the second call found nothing on disk (the flaky failure)
    m = brdfkit.model("merl:nickel@abc")
    clear_caches("brdfkit.render.ambient")
    t1 = ambient.ambient_table(m, theta_max=1.2, tol=1e-4)
    assert len(list(store_dir.glob("*.npz"))) == 1
    clear_caches("brdfkit.render.ambient")

    def no_build(*args):
        raise AssertionError("the kept table was rebuilt")

    monkeypatch.setattr(ambient, "_build", no_build)
    t2 = ambient.ambient_table(m, theta_max=1.2, tol=1e-4)
    np.testing.assert_array_equal(t2.theta, t1.theta)
    np.testing.assert_array_equal(t2.rho, t1.rho)
    assert (t2.error, t2.tol, t2.status, t2.detail) == (t1.error, t1.tol, t1.status, t1.detail)


def test_ambient_table_of_a_coloured_non_reciprocal_material_has_every_channel(nickel):
    # ρ(θ_V) of NBRDF nickel: three channels (the transposed model lost its channel count:
    # the table was the red channel's, painted grey); reference: the engine's albedo of
    # the transposed model computed per channel through its kernel
    t = ambient.ambient_table(nickel, theta_max=0.5, tol=1e-3)
    assert t.rho.shape[1] == 3
    slow = copy.copy(ambient.transposed(nickel))
    slow._driver = None
    ref = albedo_engine.albedo(slow, t.theta[:3], tol=1e-4).albedo
    np.testing.assert_allclose(t.rho[:3], ref, atol=2e-3)


def test_render_of_nbrdf_material_with_ambient_light(nickel):
    # the command of issue 23 failed with "cannot reshape array ... into shape (3)" at the
    # rim (a one-channel ambient table of a three-channel material); reference: each
    # pixel of a sphere lit by ambient light only is L_a·ρ(θ_V) of the table (Lewis eq. 7)
    from brdfkit.render import render_sphere

    r = render_sphere(nickel, phi_l=0.0, ambient=0.5, irradiance=0.0, size=8, rho_tol=1e-3)
    assert r.radiance.shape == (8, 8, 3) and np.all(np.isfinite(r.radiance))
    t = ambient.ambient_table(nickel, theta_max=1.5, tol=1e-3)
    c = (np.arange(8) + 0.5) / 8 * 2 - 1  # pixel centres; (3, 3) is inside, not on the rim
    theta_v = np.arccos(np.sqrt(1 - c[3] ** 2 - c[3] ** 2))
    np.testing.assert_allclose(r.radiance[3, 3], 0.5 * t(theta_v), atol=2e-3)


def test_source_stamp_is_one_per_process_and_survives_clearing(tmp_path, monkeypatch):
    # the stored results and the drivers' generated modules are keyed on one stamp, which
    # clearing the caches does not recompute: a source file written meanwhile (here: one
    # more .py in the package, as a concurrent writer would) must not change the key of a
    # result between its store and its read in the same process
    from brdfkit import _cache
    from brdfkit.models import _drivers

    stamp = _cache.source_stamp()
    key = stored.result_key("albedo", brdfkit.model("lambert"), THETA)
    monkeypatch.setattr(_cache, "_scan_sources", lambda: "changed files")
    clear_caches()
    assert _cache.source_stamp() == stamp
    assert stored.result_key("albedo", brdfkit.model("lambert"), THETA) == key
    assert _drivers.source_stamp is _cache.source_stamp
    assert stored.source_stamp is _cache.source_stamp
