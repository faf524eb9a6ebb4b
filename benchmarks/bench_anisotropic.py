"""Anisotropic GGX evaluation: brdfkit ``microfacet-anisotropic`` vs Mitsuba 3 ``roughconductor``.

Issue 22 §5: each new model evaluates at least 1.2× as fast as Mitsuba 3's counterpart
on the same machine, in the same run. For N random direction pairs (uniform on the upper
hemisphere, float64 NumPy (N, 3), fixed seed; ``bench_eval.random_pairs``) this prints
the median over ``--repeats`` runs (after a warm-up) of evaluations per second, end to
end — NumPy arrays in, NumPy array out — side by side, rows interleaved per repeat so
that a change of the machine's load hits both:

- brdfkit ``microfacet-anisotropic`` (GGX, α_x = 0.1, α_y = 0.4): ``model.eval(wi, wo)``,
  with F = 1 ((N,) float64) and with a conductor's RGB η, κ ((N, 3) float64);
- Mitsuba 3 ``roughconductor`` (GGX, ``alpha_u`` = 0.1, ``alpha_v`` = 0.4; ``material
  = "none"`` for F = 1, else the same η, κ), variant ``llvm_ad_rgb``: NumPy float64 →
  float32 ``mi.Vector3f`` → ``SurfaceInteraction3f`` → ``BSDF.eval`` → ``Color3f`` →
  NumPy, all timed (its eval is f_r·cos θ: one multiply more, not removed).

The ratio column is brdfkit's rate over Mitsuba's for the same case (target ≥ 1.2). Before
timing, the agreement of the two is printed (relative difference of f_r·cos θ on 10⁵
pairs: float32 against float64). The CPU model (``lscpu``) and the load average before
and after are printed: the numbers compare only within one run.

Usage::

    .venv/bin/python benchmarks/bench_anisotropic.py                    # 1 and 10 M pairs
    .venv/bin/python benchmarks/bench_anisotropic.py --pairs 1000000 --repeats 3
"""

from __future__ import annotations

import argparse
import os
import statistics
import subprocess
import sys
import time

import numpy as np
from bench_eval import probe_mitsuba_llvm, random_pairs

AX, AY = 0.1, 0.4
ETA, K = [0.2, 0.9, 1.1], [3.9, 2.4, 2.2]


def cpu_model() -> str:
    try:
        out = subprocess.run(["lscpu"], capture_output=True, text=True, timeout=10).stdout
    except (OSError, subprocess.TimeoutExpired):
        return "unknown (lscpu failed)"
    for line in out.splitlines():
        if line.startswith("Model name:"):
            return line.split(":", 1)[1].strip()
    return "unknown"


def make_mitsuba():
    """{case: bsdf} and run(bsdf, wi, wo) -> (3, N) f_r cos θ in NumPy (llvm_ad_rgb)."""
    import drjit as dr
    import mitsuba as mi

    mi.set_variant("llvm_ad_rgb")
    base = {"type": "roughconductor", "distribution": "ggx", "alpha_u": AX, "alpha_v": AY,
            "sample_visible": False}
    bsdfs = {"F = 1": mi.load_dict({**base, "material": "none"}),
             "conductor": mi.load_dict({**base, "eta": {"type": "rgb", "value": ETA},
                                        "k": {"type": "rgb", "value": K}})}
    ctx = mi.BSDFContext()

    def run(bsdf, wi, wo):
        # Mitsuba's si.wi is toward the viewer (our wo); its eval's wo is our wi (the light)
        si = dr.zeros(mi.SurfaceInteraction3f)
        si.wi = mi.Vector3f(np.ascontiguousarray(wo.T, dtype=np.float32))
        value = bsdf.eval(ctx, si, mi.Vector3f(np.ascontiguousarray(wi.T, dtype=np.float32)))
        return np.asarray(value.numpy(), dtype=np.float64)

    return bsdfs, run


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--pairs", type=int, nargs="+", default=[1_000_000, 10_000_000],
                    help="direction pair counts (default: 1 and 10 million)")
    ap.add_argument("--repeats", type=int, default=5, help="timed repetitions (median)")
    ap.add_argument("--seed", type=int, default=12345)
    args = ap.parse_args(argv)
    if min(args.pairs) < 1000 or args.repeats < 1:
        ap.error("--pairs must be >= 1000 and --repeats >= 1")

    import numba

    import brdfkit

    print(f"CPU: {cpu_model()}; {os.cpu_count()} CPUs; Numba {numba.__version__} "
          f"({numba.get_num_threads()} threads), NumPy {np.__version__}")
    print("load average (1, 5, 15 min): {:.2f} {:.2f} {:.2f}".format(*os.getloadavg()))
    note = probe_mitsuba_llvm()
    if note:
        print("note:", note)
        return 1
    bsdfs, run = make_mitsuba()
    models = {"F = 1": brdfkit.model("microfacet-anisotropic", distribution="ggx",
                                     alpha_x=AX, alpha_y=AY),
              "conductor": brdfkit.model("microfacet-anisotropic", distribution="ggx",
                                         alpha_x=AX, alpha_y=AY, eta=ETA, k=K)}

    # agreement (f_r cos θ of the light), and the axes: alpha_u is α_x
    wi, wo = random_pairs(100_000, args.seed + 1)
    for case, m in models.items():
        fb = np.asarray(m.eval(wi, wo)).reshape(len(wi), -1)[:, 0] * wi[:, 2]
        fm = run(bsdfs[case], wi, wo)[0]
        big = fb > 1e-3 * fb.max()
        rel = np.abs(fm[big] - fb[big]) / fb[big]
        print(f"check {case}: Mitsuba vs brdfkit (x cos), median rel diff {np.median(rel):.1e}, "
              f"max {rel.max():.1e}")

    rows = []
    for n in args.pairs:
        wi, wo = random_pairs(n, args.seed)
        jobs = {}
        for case in models:
            jobs[("brdfkit", case)] = lambda m=models[case], a=wi, b=wo: m.eval(a, b)
            jobs[("Mitsuba", case)] = lambda f=bsdfs[case], a=wi, b=wo: run(f, a, b)
        times = {key: [] for key in jobs}
        for fn in jobs.values():
            fn()  # warm-up (Numba loads, Dr.Jit compiles its kernel)
        for _ in range(args.repeats):
            for key, fn in jobs.items():  # interleaved
                t = time.perf_counter()
                fn()
                times[key].append(time.perf_counter() - t)
        for case in models:
            tb = statistics.median(times[("brdfkit", case)])
            tm = statistics.median(times[("Mitsuba", case)])
            rows.append((n, case, tb, tm))

    print()
    print(f"| {'pairs':>10} | {'case':<9} | {'brdfkit M/s':>11} | {'Mitsuba M/s':>11} | "
          f"{'brdfkit (s)':>11} | {'Mitsuba (s)':>11} | {'brdfkit/Mitsuba':>15} |")
    print(f"|{'-' * 12}|{'-' * 11}|{'-' * 13}|{'-' * 13}|{'-' * 13}|{'-' * 13}|{'-' * 17}|")
    for n, case, tb, tm in rows:
        print(f"| {n:>10,} | {case:<9} | {n / tb / 1e6:11.1f} | {n / tm / 1e6:11.1f} | "
              f"{tb:11.4f} | {tm:11.4f} | {tm / tb:14.2f}x |")
    print()
    print("load average (1, 5, 15 min): {:.2f} {:.2f} {:.2f}".format(*os.getloadavg()))
    return 0


if __name__ == "__main__":
    sys.exit(main())
