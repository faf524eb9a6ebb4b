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
- ``bridge diffuse`` and Mitsuba's ``diffuse`` (ρ = 0.5): the cheapest pair;
- ``Dr.Jit-traced GGX``: the alternative route measured — the same Walter GGX BSDF
  (D cos θ_h sampling, exact conductor Fresnel per channel) written as a Python BSDF
  in Dr.Jit operations (:func:`traced_ggx`, here in the benchmark only: brdfkit's
  Numba kernels cannot be traced as they are written, with Python branches and
  ``math`` calls), compiled by Dr.Jit into Mitsuba's symbolic megakernel.

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


def traced_ggx(mi, dr):
    """Walter et al. 2007 GGX conductor (eqs. 20, 33, 34, 35) as a Dr.Jit-traced BSDF."""

    class TracedGGX(mi.BSDF):
        def __init__(self, props):
            mi.BSDF.__init__(self, props)
            self.alpha = ALPHA
            self.m_flags = mi.BSDFFlags.GlossyReflection
            self.m_components = [self.m_flags]

        def _d(self, cos_h):
            a2 = self.alpha * self.alpha
            t = cos_h * cos_h * (a2 - 1.0) + 1.0
            return dr.select(cos_h > 0.0, a2 / (dr.pi * t * t), 0.0)

        def _g1(self, cos_t):
            c2 = cos_t * cos_t
            tan2 = dr.maximum(1.0 - c2, 0.0) / c2
            return 2.0 / (1.0 + dr.sqrt(1.0 + self.alpha * self.alpha * tan2))

        def _f(self, cos_d):
            return mi.Color3f(*[mi.fresnel_conductor(cos_d, dr.llvm.ad.Complex2f(e, k))
                                for e, k in zip(ETA, K, strict=True)])

        def eval(self, ctx, si, wo, active=True):
            ci, co = mi.Frame3f.cos_theta(si.wi), mi.Frame3f.cos_theta(wo)
            h = dr.normalize(si.wi + wo)
            f = (self._f(dr.dot(wo, h)) * self._d(h.z) * self._g1(ci) * self._g1(co)
                 / (4.0 * ci))  # f_r cos θ_o: one cos θ_o cancels
            return dr.select((ci > 0.0) & (co > 0.0), f, 0.0)

        def pdf(self, ctx, si, wo, active=True):
            ci, co = mi.Frame3f.cos_theta(si.wi), mi.Frame3f.cos_theta(wo)
            h = dr.normalize(si.wi + wo)
            p = self._d(h.z) * h.z / (4.0 * dr.abs(dr.dot(si.wi, h)))
            return dr.select((ci > 0.0) & (co > 0.0), p, 0.0)

        def eval_pdf(self, ctx, si, wo, active=True):
            return self.eval(ctx, si, wo, active), self.pdf(ctx, si, wo, active)

        def sample(self, ctx, si, sample1, sample2, active=True):
            a2 = self.alpha * self.alpha
            u = sample2.x
            cos2 = (1.0 - u) / (1.0 + (a2 - 1.0) * u)  # tan²θ_h = α² u/(1 − u)
            cos_h = dr.sqrt(cos2)
            sin_h = dr.sqrt(dr.maximum(1.0 - cos2, 0.0))
            s, c = dr.sincos(2.0 * dr.pi * sample2.y)
            h = mi.Vector3f(sin_h * c, sin_h * s, cos_h)
            bs = dr.zeros(mi.BSDFSample3f)
            bs.wo = mi.reflect(si.wi, h)
            bs.pdf = self.pdf(ctx, si, bs.wo, active)
            bs.eta = 1.0
            bs.sampled_type = mi.UInt32(+mi.BSDFFlags.GlossyReflection)
            bs.sampled_component = 0
            value = self.eval(ctx, si, bs.wo, active) / dr.maximum(bs.pdf, 1e-20)
            return bs, dr.select(bs.pdf > 0.0, value, 0.0)

        def traverse(self, callback):
            pass

        def parameters_changed(self, keys):
            pass

        def to_string(self):
            return "TracedGGX[]"

    return TracedGGX


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--size", type=int, default=256)
    ap.add_argument("--spp", type=int, default=16)
    ap.add_argument("--repeats", type=int, default=5)
    args = ap.parse_args()

    import drjit as dr
    import mitsuba as mi

    variant = use_variant("llvm_ad_rgb")
    mi.register_bsdf("bench_traced_ggx", lambda props: traced_ggx(mi, dr)(props))
    model = brdfkit.model("microfacet", distribution="ggx", alpha=ALPHA, eta=ETA, k=K)
    native = {"type": "roughconductor", "distribution": "ggx", "alpha": ALPHA,
              "eta": {"type": "rgb", "value": ETA}, "k": {"type": "rgb", "value": K}}
    # The bridge's BSDF objects are made per row and dropped after it: while a Python BSDF
    # object is alive, Dr.Jit's symbolic calls (the native rows) trace it too and fail.
    rows = [
        ("roughconductor (Mitsuba, symbolic)", lambda: native, False),
        ("roughconductor (Mitsuba, wavefront)", lambda: native, True),
        ("bridge microfacet GGX", lambda: mitsuba_bsdf(model), True),
        ("Dr.Jit-traced GGX (Python, symbolic)", lambda: {"type": "bench_traced_ggx"}, False),
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
    for a, b in ((rows[0][0], rows[2][0]), (rows[0][0], rows[3][0]), (rows[4][0], rows[5][0])):
        ia, ib = results[a][1], results[b][1]
        d = ia.mean(axis=0) - ib.mean(axis=0)
        var = (ia.var(axis=0, ddof=1) + ib.var(axis=0, ddof=1)) / args.repeats
        z = d.sum() / math.sqrt(var.sum())
        print(f"agreement {b} vs {a}: mean difference {d.mean():+.2e}, z = {z:+.2f}")
    # the bridge and the traced GGX draw the same half vectors from the same numbers
    diff = np.abs(results[rows[2][0]][1] - results[rows[3][0]][1]).max()
    print(f"largest pixel difference, bridge vs Dr.Jit-traced GGX (same seeds): {diff:.2e}")


if __name__ == "__main__":
    main()
