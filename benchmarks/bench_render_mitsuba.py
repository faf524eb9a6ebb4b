"""Render time: brdfkit ``microfacet`` through the Mitsuba bridge vs Mitsuba's ``roughconductor``.

Scene: the sphere test configuration (``brdfkit.render.mitsuba_sphere.sphere_scene``):
orthographic camera from +z, unit sphere, directional light at Φ_L = 45° (E = 1) and a
constant environment L_a = 0.2, ``path`` integrator with max_depth 2, S×S pixels,
``--spp`` samples per pixel, variant ``llvm_ad_rgb``. The sphere's BSDF is

- ``roughconductor``: Mitsuba's own GGX conductor (α = 0.2, eta/k of the RGB set below,
  visible-normal sampling, its default), rendered in Dr.Jit's default symbolic mode
  (one fused kernel: how Mitsuba is normally run);
- ``roughconductor (wavefront)``: the same with the symbolic modes off (the mode the
  bridge needs), to separate the cost of the mode from the cost of the bridge;
- ``bridge microfacet``: ``brdfkit.model("microfacet", distribution="ggx", alpha=0.2,
  eta=…, k=…)`` through ``mitsuba_bsdf`` (NumPy/Numba on every wavefront);
- ``bridge diffuse`` and Mitsuba's ``diffuse`` (ρ = 0.5): the cheapest pair.

Each row: the median over ``--repeats`` renders (after one warm-up render that compiles
the kernels), all rows in one process, side by side. The ratio column is the row's
median over the native ``roughconductor`` (symbolic) median; the target of issue 11 is
≤ 2 for the bridge's microfacet. Before timing, the script checks that the bridge and
the native images agree: mean over the disc of the two images within 3 standard errors
of their difference (per-pixel variances from the repeats, pixels independent).

The machine is shared: the load average is printed before and after.

Usage::

    .venv/bin/python benchmarks/bench_render_mitsuba.py            # 256², 16 spp, 5 repeats
    .venv/bin/python benchmarks/bench_render_mitsuba.py --size 128 --spp 8 --repeats 3
"""

from __future__ import annotations

import argparse
import gc
import math
import os
import statistics
import time

import numpy as np

import brdfkit
from brdfkit.render.mitsuba_bridge import mitsuba_bsdf, use_variant, wavefront
from brdfkit.render.mitsuba_sphere import sphere_scene

ALPHA = 0.2
ETA = [0.2, 0.9, 1.1]
K = [3.9, 2.4, 2.2]
PHI_L = math.radians(45.0)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--size", type=int, default=256)
    ap.add_argument("--spp", type=int, default=16)
    ap.add_argument("--repeats", type=int, default=5)
    args = ap.parse_args()

    import mitsuba as mi

    variant = use_variant("llvm_ad_rgb")
    model = brdfkit.model("microfacet", distribution="ggx", alpha=ALPHA, eta=ETA, k=K)
    native = {"type": "roughconductor", "distribution": "ggx", "alpha": ALPHA,
              "eta": {"type": "rgb", "value": ETA}, "k": {"type": "rgb", "value": K}}
    # The bridge's BSDF objects are made per row and dropped after it: while a Python BSDF
    # object is alive, Dr.Jit's symbolic calls (the native rows) trace it too and fail.
    rows = [
        ("roughconductor (Mitsuba, symbolic)", lambda: native, False),
        ("roughconductor (Mitsuba, wavefront)", lambda: native, True),
        ("bridge microfacet GGX", lambda: mitsuba_bsdf(model), True),
        ("diffuse (Mitsuba, symbolic)", lambda: {"type": "diffuse", "reflectance": 0.5}, False),
        ("bridge diffuse", lambda: mitsuba_bsdf(brdfkit.model("diffuse", rho_d=0.5)), True),
    ]
    print(f"variant {variant}, {args.size}² pixels, {args.spp} spp, {args.repeats} repeats; "
          f"load average before: {os.getloadavg()[0]:.2f}")
    results = {}
    order = [r for r in rows if not r[2]] + [r for r in rows if r[2]]  # symbolic first
    for name, make, wave in order:
        scene = mi.load_dict(sphere_scene(make(), phi_l=PHI_L, ambient=0.2, size=args.size,
                                          variant=variant))

        def render(seed, scene=scene, wave=wave):
            if wave:
                with wavefront():
                    return np.array(mi.render(scene, spp=args.spp, seed=seed))
            return np.array(mi.render(scene, spp=args.spp, seed=seed))

        render(1000)  # warm-up: kernel compilation
        times, images = [], []
        for r in range(args.repeats):
            t0 = time.perf_counter()
            images.append(render(r))
            times.append(time.perf_counter() - t0)
        results[name] = (statistics.median(times), np.stack(images))
        del scene, render
        gc.collect()

    base = results[rows[0][0]][0]
    print(f"{'renderer':40s} {'median s':>9s} {'ratio':>7s}")
    for name, _, _ in rows:
        t = results[name][0]
        print(f"{name:40s} {t:9.3f} {t / base:7.2f}")
    print(f"load average after: {os.getloadavg()[0]:.2f}")

    # agreement: the disc's mean radiance, bridge vs native, within 3 standard errors
    for a, b in ((rows[0][0], rows[2][0]), (rows[3][0], rows[4][0])):
        ia, ib = results[a][1], results[b][1]
        d = ia.mean(axis=0) - ib.mean(axis=0)
        var = (ia.var(axis=0, ddof=1) + ib.var(axis=0, ddof=1)) / args.repeats
        z = d.sum() / math.sqrt(var.sum())
        print(f"agreement {b} vs {a}: mean difference {d.mean():+.2e}, z = {z:+.2f}")


if __name__ == "__main__":
    main()
