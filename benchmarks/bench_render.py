"""Benchmark of the exact sphere render (Lewis's test configuration; issue 11 §1).

Prints, per model and image side S, the median time of ``render_sphere`` (direct
light only, Φ_L = 30°) and its pixels per second, side by side with the named
baseline: ``model.eval`` alone on the same (wi, wo) pairs (the part of the
render no renderer can avoid), and the ratio render/eval. Target: a 512²
image in ≤ 20 ms. A second table times the ambient term (L_a > 0): the
first call builds the ρ(θ_V) table with the albedo engine (cached per model),
later calls only interpolate it.

Every model is compiled and rendered once before timing; the models are timed
in turn, repeatedly, and the medians compared.

Run: ``.venv/bin/python benchmarks/bench_render.py [--repeats R] [--sizes 256,512]``.
The machine should be otherwise idle.
"""

from __future__ import annotations

import argparse
import math
import time

import numpy as np
from _timing import median_time

import brdfkit
from brdfkit.pumping import pump
from brdfkit.render import render_sphere
from brdfkit.render.sphere import _lit_pixels

TARGET_512_S = 0.020




def _models():
    return {
        "lambert": brdfkit.model("lambert", rho_d=0.8),
        "blinn (Lewis Fig. 3)": brdfkit.model("blinn", k_d=0.5, k_s=0.5, n=20),
        "modified-phong RGB": brdfkit.model("modified-phong", rho_d=[0.1, 0.2, 0.3],
                                            rho_s=0.5, n=100),
        "microfacet GGX": brdfkit.model("microfacet", distribution="ggx", alpha=0.1),
        "modified-phong pumped": pump(brdfkit.model("modified-phong", rho_d=0.2, rho_s=0.7,
                                                    n=20)),
    }


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeats", type=int, default=15)
    ap.add_argument("--sizes", default="256,512")
    args = ap.parse_args(argv)
    sizes = [int(s) for s in args.sizes.split(",")]
    phi = math.radians(30.0)
    models = _models()
    for m in models.values():  # compile everything first
        render_sphere(m, phi_l=phi, size=16)
    print(f"direct light, phi_L = 30 deg, median of {args.repeats}")
    print(f"{'model':24s} {'S':>5s} {'render ms':>10s} {'Mpix/s':>8s} {'eval ms':>8s} "
          f"{'render/eval':>11s} {'target':>7s}")
    for S in sizes:
        L = (math.sin(phi), 0.0, math.cos(phi))
        wi, wo = np.empty((S * S, 3)), np.empty((S * S, 3))
        idx, cos_l = np.empty(S * S, dtype=np.int64), np.empty(S * S)
        k = _lit_pixels(S, *L, wi, wo, idx, cos_l)
        a, b = wi[:k], wo[:k]
        for name, m in models.items():
            t_r = median_time(lambda m=m, S=S: render_sphere(m, phi_l=phi, size=S), args.repeats)
            t_e = median_time(lambda m=m, a=a, b=b: m.eval(a, b), args.repeats)
            ok = "" if S != 512 else ("met" if t_r <= TARGET_512_S else "MISSED")
            print(f"{name:24s} {S:5d} {1e3 * t_r:10.2f} {S * S / t_r / 1e6:8.1f} "
                  f"{1e3 * t_e:8.2f} {t_r / t_e:11.2f} {ok:>7s}")
    print("\nambient term (L_a = 0.5, S = 512): first call (builds the rho table) and later")
    print(f"{'model':24s} {'first s':>8s} {'later ms':>9s} {'table nodes':>11s} {'rho error':>10s}")
    for name, m in _models().items():  # new objects: the per-model cache starts empty
        t0 = time.perf_counter()
        r = render_sphere(m, phi_l=phi, size=512, ambient=0.5)
        first = time.perf_counter() - t0
        later = median_time(lambda m=m: render_sphere(m, phi_l=phi, size=512, ambient=0.5),
                             max(3, args.repeats // 3))
        nodes = r.ambient_message.split(" on ")[-1].split(" nodes")[0] if r.success else "-"
        print(f"{name:24s} {first:8.2f} {1e3 * later:9.2f} {nodes:>11s} "
              f"{r.ambient_error / 0.5:10.2g}")


if __name__ == "__main__":
    main()
