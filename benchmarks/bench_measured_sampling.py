"""Variance reduction of the tabulated sampler of measured materials (brdfkit.data.sampler).

For each material and incidence θ_i it estimates the directional albedo of the channel
mean, a = ∫ f̄ cos θ_o dω_o, with N samples from three densities, in one process, same
seed, and prints the standard deviation of the estimator f̄ cos θ_o / pdf per sample:

- ``cosine``: cos θ/π (brdfkit's fallback, what measured materials had before);
- ``1-D``: one tabulated θ_h marginal for every view (n_theta_o = n_psi = 1), + cosine;
- ``2-D``: the default per-θ_o (θ_h, ψ) tables, + cosine (the materials' sampler);

for the built-in materials and for a MERL table (``nearest`` lookup) of a GGX microfacet
material of our own making;

the ratios std(cosine)/std(2-D) and std(1-D)/std(2-D) (the factor in samples the 2-D
tables save is the square of the ratio), and the median time to build the 2-D tables.

    PYTHONPATH=src .venv/bin/python benchmarks/bench_measured_sampling.py [--n 20000]
"""

from __future__ import annotations

import argparse
import math
import time

import numpy as np

import brdfkit
import brdfkit.data as bd
from brdfkit.data.measured import MeasuredBRDF
from brdfkit.data.merl import table_from_function
from brdfkit.data.sampler import tabulated_strategy
from brdfkit.geometry import pdf_cosine_hemisphere, sample_cosine_hemisphere
from brdfkit.models.sampling import COSINE

SPECS = ("merl:nickel", "merl:gray-plastic", "merl:violet-rubber", "merl:nickel@abc",
         "merl:gold-metallic-paint@sgd", "merl:blue-metallic-paint@npf", "rgl:spectralon",
         "nielsen:bluebook")
THETAS = (0.0, 45.0, 75.0)


def estimator_std(model, strategy, theta_deg, n, seed):
    t = math.radians(theta_deg)
    wo = np.array([math.sin(t), 0.0, math.cos(t)])
    u = np.random.default_rng(seed).random((n, 2))
    if strategy is COSINE:
        wi = sample_cosine_hemisphere(u)
        pdf = pdf_cosine_hemisphere(wi)
    else:
        wi = strategy.sample(wo, u)
        pdf = strategy.pdf(wi, wo)
    up = (wi[:, 2] > 0.0) & (pdf > 0.0)
    w = np.where(up[:, None], wi, [0.0, 0.0, 1.0])
    f = np.asarray(model.eval(wo, w)).mean(axis=-1)  # ω_i first, as the albedo engine
    f = np.where(np.isfinite(f), f, 0.0)  # unmeasured bins of a table: no value, counted as 0
    est = np.where(up, f * w[:, 2] / np.where(up, pdf, 1.0), 0.0)
    return float(est.mean()), float(est.std(ddof=1))


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--n", type=int, default=20000)
    args = ap.parse_args()
    print(f"N = {args.n} samples per estimate; std of one sample's estimate\n")
    print(f"{'material':32s} {'θi':>4s} {'albedo':>8s} {'cosine':>9s} {'1-D':>9s} "
          f"{'2-D':>9s} {'cos/2D':>7s} {'1D/2D':>6s} {'build ms':>8s}")
    table = MeasuredBRDF(table_from_function(
        brdfkit.model("microfacet", distribution="ggx", alpha=0.15).eval), lookup="nearest")
    for spec in (*SPECS, "MERL table of GGX alpha=0.15"):
        m = table if spec.startswith("MERL table") else bd.material(spec)
        m.sharpest_lobe()
        times = []
        for _ in range(3):
            t0 = time.perf_counter()
            s2 = tabulated_strategy(m)
            times.append(time.perf_counter() - t0)
        s1 = tabulated_strategy(m, n_theta_o=1, n_psi=1)
        for th in THETAS:
            a, sc = estimator_std(m, COSINE, th, args.n, 1)
            _, s1d = estimator_std(m, s1, th, args.n, 1)
            a2, s2d = estimator_std(m, s2, th, args.n, 1)
            print(f"{spec[:32]:32s} {th:4.0f} {a2:8.4f} {sc:9.4f} {s1d:9.4f} {s2d:9.4f} "
                  f"{sc / s2d:7.1f} {s1d / s2d:6.1f} {1e3 * float(np.median(times)):8.1f}")


if __name__ == "__main__":
    main()
