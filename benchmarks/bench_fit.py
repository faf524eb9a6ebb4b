"""Fitting speed: brdfkit.fitting.fit vs SciPy's optimiser on a NumPy loss, same samples.

    PYTHONPATH=src python benchmarks/bench_fit.py [--repeats 3] [--material merl:nickel]

Both fit ``nielsen`` (no η: F = 1) to the material under the L1 loss over the same
MERL-grid samples and weights (brdfkit.fitting.samples.merl_samples, default strides):

- brdfkit: ``fit(model, target)`` — the default procedure: first guess by a width scan,
  linear parameters in closed form (variable projection), multi-start search on a coarser
  grid, polish on the full samples, bound check; compiled model evaluation;
- baseline: ``scipy.optimize.minimize`` (L-BFGS-B, finite-difference gradients, the
  declared bounds) over all eight parameters jointly (ρ_d, k_s per channel, s, α)
  from the declared defaults, on the Nielsen formula written in NumPy (eq. (3),
  F = 1), the loss the same weighted L1 mean.

Prints the median wall time of each, the final L1 of each (a fast wrong answer is
not a win), and the ratio. Compilation is excluded (one warm-up fit first).
"""

from __future__ import annotations

import argparse
import math
import os
import time

import numpy as np
from scipy.optimize import minimize

import brdfkit
from brdfkit.fitting import fit
from brdfkit.fitting.samples import merl_samples


def nielsen_numpy(wi, wo, rho_d, k_s, s, alpha):
    """Nielsen et al. eq. (3) with F = 1, NumPy: (N, 3) for per-channel rho_d, k_s."""
    wr = np.stack([-wi[:, 0], -wi[:, 1], wi[:, 2]], axis=1)  # mirror of wi about n
    rv = np.sum(wr * wo, axis=1)
    h = wi + wo
    h /= np.linalg.norm(h, axis=1, keepdims=True)
    nh = h[:, 2]
    lobe = np.maximum(0.0, (1.0 - alpha) * rv + alpha * nh ** 4) ** s
    return rho_d[None, :] / math.pi + k_s[None, :] * lobe[:, None]


def baseline(target, samples):
    y = np.asarray(target.eval(samples.wi, samples.wo)) * samples.cos_i[:, None]
    w = samples.weight
    W = w.sum() * 3

    def loss(x):
        m = nielsen_numpy(samples.wi, samples.wo, x[0:3], x[3:6], x[6], x[7])
        return float(np.sum(w[:, None] * np.abs(m * samples.cos_i[:, None] - y)) / W)

    decl = {p.name: p for p in brdfkit.model("nielsen").params}
    x0 = np.array([decl["rho_d"].default] * 3 + [decl["k_s"].default] * 3
                  + [decl["s"].default, decl["alpha"].default], dtype=float)
    bounds = ([(decl["rho_d"].lower, decl["rho_d"].upper)] * 3
              + [(decl["k_s"].lower, decl["k_s"].upper)] * 3
              + [(decl["s"].lower, decl["s"].upper), (decl["alpha"].lower, decl["alpha"].upper)])
    r = minimize(loss, x0, method="L-BFGS-B", bounds=bounds)
    return r.fun, r.nfev


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--material", default="merl:nickel")
    a = ap.parse_args()
    target = brdfkit.data.material(a.material)
    model = brdfkit.model("nielsen")
    samples = merl_samples()
    fit(model, target, max_evals=20, n_starts=1)  # warm-up: compilation excluded
    ours, base = [], []
    for _ in range(a.repeats):
        t0 = time.perf_counter()
        r = fit(model, target)
        ours.append(time.perf_counter() - t0)
        t0 = time.perf_counter()
        b_loss, b_nfev = baseline(target, samples)
        base.append(time.perf_counter() - t0)
    mo, mb = float(np.median(ours)), float(np.median(base))
    load = os.getloadavg()
    print(f"nielsen -> {a.material}, L1, {len(samples)} samples, {a.repeats} repeats, "
          f"load average {load[0]:.1f} {load[1]:.1f} {load[2]:.1f} (2 cores)")
    print("| method | median time (s) | final L1 | evaluations |")
    print("|---|---|---|---|")
    print(f"| brdfkit fit (default procedure) | {mo:.2f} | {r.value:.6g} | "
          f"{r.convergence['evaluations']} model |")
    print(f"| SciPy L-BFGS-B on NumPy loss, all parameters | {mb:.2f} | {b_loss:.6g} | "
          f"{b_nfev} loss |")
    print(f"ratio baseline/brdfkit: {mb / mo:.2f}x")


if __name__ == "__main__":
    main()
