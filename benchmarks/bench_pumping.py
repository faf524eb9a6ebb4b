"""Benchmark of albedo pumping-up (Neumann et al. 1999 §3; issue 4 §4).

Prints, side by side with the base model:

1. the time to build the albedo table of a ``modified-phong`` n = 5000 pump
   (ρ_d = 0, ρ_s = 1): target ≤ 0.2 s (median of the repeats, after one
   warm-up build that also compiles);
2. evaluation time on N pairs (default 10 million) of the base and of the
   model pumped once and twice, median of the repeats, and the ratio to the
   base: target ≤ 1.3×. Two pair sets: uniform on the hemisphere (most pairs
   miss a sharp lobe, where the pumped kernel skips its table lookups) and
   "in the lobe" (wo within ~3 lobe widths of the mirror of wi, every pair
   pays for the lookups). The models are timed in turn, repeatedly, and the
   medians compared (a drift of the machine's speed hits all alike).

Run: ``.venv/bin/python benchmarks/bench_pumping.py [--pairs N] [--repeats R]``.
The machine should be otherwise idle (the kernels use every core).
"""

from __future__ import annotations

import argparse
import statistics

import numpy as np
from _timing import median_time

import brdfkit
from brdfkit.pumping import build_albedo_table, pump


def _pairs(n, rng, lobe_width=None):
    ti = np.arccos(rng.uniform(0.0, 1.0, n))
    wi = np.stack([np.sin(ti), np.zeros(n), np.cos(ti)], axis=-1)
    if lobe_width is None:
        to = np.arccos(rng.uniform(0.0, 1.0, n))
        po = rng.uniform(0.0, 2 * np.pi, n)
        wo = np.stack([np.sin(to) * np.cos(po), np.sin(to) * np.sin(po), np.cos(to)], axis=-1)
    else:
        r = wi * np.array([-1.0, -1.0, 1.0])
        wo = r + rng.normal(0.0, lobe_width, (n, 3))
        wo /= np.linalg.norm(wo, axis=-1, keepdims=True)
        wo[:, 2] = np.abs(wo[:, 2])
    return np.ascontiguousarray(wi), np.ascontiguousarray(wo)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--pairs", type=int, default=10_000_000)
    ap.add_argument("--repeats", type=int, default=5)
    args = ap.parse_args(argv)
    rng = np.random.default_rng(0)

    print("1. albedo table build, modified-phong n = 5000 (rho_d = 0, rho_s = 1)")
    m5000 = brdfkit.model("modified-phong", rho_d=0.0, rho_s=1.0, n=5000.0)
    tab = build_albedo_table(m5000)  # warm-up: compiles the engine for this kernel
    t_build = median_time(lambda: build_albedo_table(m5000), args.repeats)
    print(f"   {tab.n_intervals} intervals, {tab.n_evaluations} engine angles, "
          f"max midpoint error {tab.max_midpoint_error[0]:.2e}")
    print(f"   median build time {t_build * 1e3:8.1f} ms   (target <= 200 ms: "
          f"{'OK' if t_build <= 0.2 else 'MISSED'})")

    print(f"\n2. evaluation, {args.pairs:,} pairs, median of {args.repeats}")
    print(f"   {'model':34s} {'pairs':9s} {'time (ms)':>10s} {'M evals/s':>10s} {'ratio':>7s}"
          f" {'rnd':>5s}")
    for n in (20.0, 5000.0):
        base = brdfkit.model("modified-phong", rho_d=0.0, rho_s=1.0, n=n)
        stages = [("base", base), ("pumped 1x (max)", pump(base, "max")),
                  ("pumped 2x (controlled)", pump(base, "controlled", times=2))]
        width = float(brdfkit.halfangle.beta_from_exponent(n))
        for label, lw in (("uniform", None), ("in-lobe", width)):
            wi, wo = _pairs(args.pairs, rng, lw)
            for _, m in stages:
                m.eval(wi[:1000], wo[:1000])  # compile
            # interleaved (base, 1x, 2x, base, ...) so that drifts of the machine's speed
            # hit every model alike; medians per model
            times = {name: [] for name, _ in stages}
            for _ in range(args.repeats):
                for name, m in stages:
                    times[name].append(median_time(lambda m=m, wi=wi, wo=wo: m.eval(wi, wo), 1))
            t_base = statistics.median(times["base"])
            for name, _ in stages:
                t = statistics.median(times[name])
                ratio = t / t_base
                paired = statistics.median(
                    a / b for a, b in zip(times[name], times["base"], strict=True))
                flag = ("" if name == "base" else
                        ("  OK" if max(ratio, paired) <= 1.3 else "  MISSED"))
                print(f"   {f'n={n:g} ' + name:34s} {label:9s} {t * 1e3:10.1f} "
                      f"{args.pairs / t / 1e6:10.1f} {ratio:7.2f} {paired:5.2f}{flag}")


if __name__ == "__main__":
    main()
