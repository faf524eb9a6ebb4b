"""Benchmark of the energy compensation operators (issue 22 §5).

Prints, side by side in one run:

1. the time to build a compensation's tables (E(μ) by the albedo engine, its
   spline, the kernel's lookup and E_avg: ``brdfkit.compensation.compensation_table``)
   for GGX α = 0.3, Beckmann α = 0.3 and modified-phong n = 20 (ρ_d = 0, ρ_s = 1),
   median of the repeats after one warm-up build that also compiles: target
   ≤ 200 ms; with the furnace deficit max |1 − a(θ)| over θ ∈ {0, 30, 60, 75, 85, 89}°
   of the Kulla–Conty compensated model (albedo engine, tol 1e-8) beside it (target
   1e-5), the accuracy the table's engine tolerance buys;
2. evaluation time on N pairs (default 10 million, uniform on the hemisphere) of the
   base (GGX microfacet α = 0.3, modified-phong n = 20) and of its Kulla–Conty and
   Turquin compensations, the models timed in turn (base, KC, Turquin, base, …) and
   the medians compared, and the median of the per-round ratios: target ≤ 1.3×.

Run: ``.venv/bin/python benchmarks/bench_compensation.py [--pairs N] [--repeats R]``.
The machine should be otherwise idle (the kernels use every core).
"""

from __future__ import annotations

import argparse
import os
import statistics

import numpy as np
from _timing import median_time

import brdfkit
from brdfkit.analysis import albedo
from brdfkit.compensation import ENGINE_TOL, compensate, compensation_table

THETA = np.radians([0.0, 30.0, 60.0, 75.0, 85.0, 89.0])


def _pairs(n, rng):
    ti = np.arccos(rng.uniform(0.0, 1.0, n))
    wi = np.stack([np.sin(ti), np.zeros(n), np.cos(ti)], axis=-1)
    to = np.arccos(rng.uniform(0.0, 1.0, n))
    po = rng.uniform(0.0, 2 * np.pi, n)
    wo = np.stack([np.sin(to) * np.cos(po), np.sin(to) * np.sin(po), np.cos(to)], axis=-1)
    return np.ascontiguousarray(wi), np.ascontiguousarray(wo)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--pairs", type=int, default=10_000_000)
    ap.add_argument("--repeats", type=int, default=5)
    args = ap.parse_args(argv)
    try:
        cpu = next(line.split(":", 1)[1].strip() for line in open("/proc/cpuinfo")
                   if line.startswith("model name"))
    except (OSError, StopIteration):
        cpu = "unknown CPU"
    print(f"# {cpu}; load average {os.getloadavg()[0]:.2f}")
    rng = np.random.default_rng(0)

    print(f"\n1. table build (engine tol {ENGINE_TOL:g}), median of {args.repeats}")
    print(f"   {'base':36s} {'intervals':>9s} {'build (ms)':>10s} {'furnace deficit':>16s}")
    for label, m in (
            ("GGX alpha=0.3", brdfkit.model("microfacet", distribution="ggx", alpha=0.3)),
            ("Beckmann alpha=0.3", brdfkit.model("microfacet", alpha=0.3)),
            ("modified-phong n=20", brdfkit.model("modified-phong", n=20, rho_d=0, rho_s=1))):
        tab = compensation_table(m)  # warm-up: compiles the engine for this kernel
        t = median_time(lambda m=m: compensation_table(m), args.repeats)
        a = np.asarray(albedo(compensate(m), THETA, tol=1e-8).albedo)
        deficit = float(np.max(np.abs(1.0 - a)))
        flag = "OK" if t <= 0.2 and deficit <= 1e-5 else "MISSED"
        print(f"   {label:36s} {tab.spline.n_intervals:9d} {t * 1e3:10.1f} {deficit:16.2e}  "
              f"{flag}")

    print(f"\n2. evaluation, {args.pairs:,} uniform pairs, median of {args.repeats}")
    print(f"   {'model':36s} {'time (ms)':>10s} {'M evals/s':>10s} {'ratio':>7s} {'rnd':>5s}")
    wi, wo = _pairs(args.pairs, rng)
    for label, base in (
            ("GGX alpha=0.3", brdfkit.model("microfacet", distribution="ggx", alpha=0.3)),
            ("modified-phong n=20", brdfkit.model("modified-phong", n=20, rho_d=0, rho_s=1))):
        stages = [("base", base), ("kulla-conty", compensate(base, "kulla-conty")),
                  ("turquin", compensate(base, "turquin"))]
        for _, m in stages:
            m.eval(wi[:1000], wo[:1000])  # compile
        times = {name: [] for name, _ in stages}
        for _ in range(args.repeats):  # interleaved: a drift of the machine hits all alike
            for name, m in stages:
                times[name].append(median_time(lambda m=m: m.eval(wi, wo), 1))
        t_base = statistics.median(times["base"])
        for name, _ in stages:
            t = statistics.median(times[name])
            ratio = t / t_base
            paired = statistics.median(
                a / b for a, b in zip(times[name], times["base"], strict=True))
            flag = "" if name == "base" else ("  OK" if max(ratio, paired) <= 1.3 else "  MISSED")
            print(f"   {label + ' ' + name:36s} {t * 1e3:10.1f} {args.pairs / t / 1e6:10.1f} "
                  f"{ratio:7.2f} {paired:5.2f}{flag}")
    print(f"# load average after {os.getloadavg()[0]:.2f}")


if __name__ == "__main__":
    main()
