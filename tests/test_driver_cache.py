"""The disk-cached evaluation loops (brdfkit.models._drivers).

References: the generic loop eval_pairs_checked (bit-equal results: the same code with the
kernel a global instead of an argument) and Numba's own cache statistics (a second process
loads the loop from disk: a cache hit and no compilation).
"""

from __future__ import annotations

import ast
import json
import os
import subprocess
import sys
import textwrap

import numba
import numpy as np
import pytest

import brdfkit
from brdfkit.models._base import eval_pairs_checked
from brdfkit.models._drivers import CALLED_KERNEL_LOOPS, _loop_source, cache_dir, cached_driver


def _pairs(n, seed=0):
    rng = np.random.default_rng(seed)
    w = rng.normal(size=(2, n, 3))
    w[..., 2] = np.abs(w[..., 2])
    w /= np.linalg.norm(w, axis=-1, keepdims=True)
    return np.ascontiguousarray(w[0]), np.ascontiguousarray(w[1])


@pytest.mark.parametrize("name, params", [
    ("nielsen", {"rho_d": [0.1, 0.2, 0.3], "k_s": [2.0, 3.0, 4.0], "s": 80.0}),
    ("modified-phong", {}),
    ("lafortune", {}),
])
def test_cached_loop_equals_the_generic_loop(name, params):
    m = brdfkit.model(name, **params)
    driver = cached_driver(m.kernel)
    assert driver is not None
    wi, wo = _pairs(5000)
    wi[17] = [0.0, 0.0, 2.0]  # not a unit vector: NaN in that row and counted
    P = np.ascontiguousarray(m.packed)
    got, ref = np.empty((5000, P.shape[0])), np.empty((5000, P.shape[0]))
    n_got = driver(wi, wo, P, got)
    n_ref = eval_pairs_checked(m.kernel, wi, wo, P, ref)
    assert n_got == n_ref == 1
    np.testing.assert_array_equal(got, ref)  # NaN rows compare equal too


def test_a_kernel_without_an_importable_name_keeps_the_generic_loop():
    @numba.njit
    def local_kernel(ix, iy, iz, ox, oy, oz, p):  # pragma: no cover - compiled
        return p[0]

    assert cached_driver(local_kernel) is None


_CHILD = textwrap.dedent("""
    import json, numpy as np, brdfkit
    from brdfkit.models._drivers import cached_driver
    m = brdfkit.model("ashikhmin-shirley")  # model.eval runs the checked loop of its kernel
    wi = np.array([[0.0, 0.6, 0.8]]); wo = np.array([[0.0, -0.6, 0.8]])
    value = float(m.eval(wi, wo)[0])
    d = cached_driver(m.kernel)
    print(json.dumps({"value": value, "cached": d is not None,
                      "hits": sum(d.stats.cache_hits.values()) if d else 0,
                      "misses": sum(d.stats.cache_misses.values()) if d else 0}))
""")


def _child(env):
    out = subprocess.run([sys.executable, "-c", _CHILD], env=env, capture_output=True,
                         text=True, timeout=600, check=True)
    return json.loads(out.stdout.strip().splitlines()[-1])


def test_a_second_process_loads_the_loop_from_disk(tmp_path):
    env = {**os.environ, "BRDFKIT_CACHE_DIR": str(tmp_path)}
    first = _child(env)
    assert first["cached"] and first["misses"] == 1 and first["hits"] == 0
    written = list((tmp_path / "drivers").glob("*/_brdfkit_driver_*.py"))
    assert len(written) == 1
    second = _child(env)
    assert second["cached"] and second["hits"] == 1 and second["misses"] == 0
    assert second["value"] == first["value"]


def test_an_unwritable_cache_directory_only_costs_speed(tmp_path):
    blocker = tmp_path / "not-a-directory"
    blocker.write_text("")
    env = {**os.environ, "BRDFKIT_CACHE_DIR": str(blocker)}
    got = _child(env)
    assert not got["cached"]
    ref = brdfkit.model("ashikhmin-shirley").eval(np.array([0.0, 0.6, 0.8]),
                                                  np.array([0.0, -0.6, 0.8]))
    assert got["value"] == pytest.approx(float(ref), rel=1e-15)


def test_cache_dir_follows_the_environment(monkeypatch, tmp_path):
    monkeypatch.setenv("BRDFKIT_CACHE_DIR", str(tmp_path / "x"))
    assert cache_dir() == tmp_path / "x" / "drivers"
    monkeypatch.delenv("BRDFKIT_CACHE_DIR")
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "xdg"))
    assert cache_dir() == tmp_path / "xdg" / "brdfkit" / "drivers"


def test_the_exact_sphere_loop_is_kept_on_disk():
    # the sphere's loop (render.sphere, registered with add_loop) was compiled in every
    # process (0.35-0.6 s of the explorer's first view); a disk-cached loop counts a cache
    # hit or miss in Numba's own statistics, a loop compiled in memory counts neither
    from brdfkit.models._drivers import loop_driver
    from brdfkit.render import render_sphere

    m = brdfkit.model("lambert", rho_d=0.5)
    r = render_sphere(m, phi_l=0.5, size=8, antialias=1)  # pixel centres only
    d = loop_driver(m.kernel, loop="sphere")
    assert sum(d.stats.cache_hits.values()) + sum(d.stats.cache_misses.values()) == 1
    # closed form: a Lambertian pixel is rho_d/pi * max(N.L, 0), N at the pixel's centre
    # (x, y) = ((c + 1/2)/4 - 1, 1 - (r + 1/2)/4), the light in the xz-plane at phi_l
    c = (np.arange(8) + 0.5) / 4.0 - 1.0
    x, y = c[None, :], -c[:, None]
    z = np.sqrt(np.clip(1.0 - x * x - y * y, 0.0, None))
    expected = 0.5 / np.pi * np.maximum(np.sin(0.5) * x + np.cos(0.5) * z, 0.0)
    inside = x * x + y * y < 1.0
    assert np.allclose(r.radiance[..., 0][inside], expected[inside], rtol=1e-12, atol=0)


def _called_names(fn: ast.FunctionDef) -> set[str]:
    return {n.func.id for n in ast.walk(fn) if isinstance(n, ast.Call)
            and isinstance(n.func, ast.Name)}


@pytest.mark.parametrize("loop", sorted(CALLED_KERNEL_LOOPS))
def test_branching_loops_call_the_kernel_through_one_function(loop):
    """The generated source of a branching loop (what Numba compiles): its driver calls
    ``_kernel_call`` and never ``kernel`` itself (Numba would inline the kernel's IR at
    each call site: the compile time this avoids, see CALLED_KERNEL_LOOPS), and
    ``_kernel_call`` is an ordinary njit function (no ``inline=``) calling ``kernel`` once
    with the loops' IEEE error model. The values are the generic loop's, bit for bit:
    test_cached_loop_equals_the_generic_loop."""
    for cache in (True, False):
        tree = ast.parse(_loop_source(loop, cache=cache))
        fns = {f.name: f for f in tree.body if isinstance(f, ast.FunctionDef)}
        called = _called_names(fns["driver"])
        assert "_kernel_call" in called and "kernel" not in called
        wrapper = fns["_kernel_call"]
        assert [n.func.id for n in ast.walk(wrapper) if isinstance(n, ast.Call)
                and isinstance(n.func, ast.Name)] == ["kernel"]
        (decorator,) = wrapper.decorator_list
        options = {k.arg: ast.literal_eval(k.value) for k in decorator.keywords}
        assert options == {"error_model": "numpy", **({"cache": True} if cache else {})}


def test_the_vector_loop_inlines_the_kernel_into_its_chunk():
    """The vectorising loop is unchanged: its chunk calls ``kernel`` directly (inlined in
    Numba's IR once, so that LLVM vectorises the chunk's loop), with no _kernel_call."""
    tree = ast.parse(_loop_source("vector", cache=True))
    fns = {f.name: f for f in tree.body if isinstance(f, ast.FunctionDef)}
    assert "_kernel_call" not in fns
    assert "kernel" in _called_names(fns["chunk"])
