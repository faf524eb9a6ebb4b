"""The Phong family's formula kernels against their former branching kernels, one run.

For N random pairs (both directions uniform on the upper hemisphere, fixed seed)
this prints the median (``--repeats`` runs after a warm-up) of evaluations per
second of

- ``model.eval`` now: the branch-free formula kernel (``brdfkit._dual``) in the
  ``"vector"`` loop (``lobe_power`` multiplies for an integral exponent);
- the former kernel, copied below as it was (``if below_horizon: return 0.0``,
  ``lobe_pow``'s loop, ``n_dot_h``'s branch; for ``lafortune`` and ``nh-power-series``
  the class's kernel, a loop over the lobes, which model.eval ran until issue 23), in the
  ``"checked"`` loop that ``BRDF.eval`` ran for it (the baseline);

and the ratio new/former, after checking that both give the same values
(bit-equal is expected: the formulas repeat the former operations). The machine's
load average is printed: ratios are comparable within one run only.

Usage::

    .venv/bin/python benchmarks/bench_phong_formulas.py --pairs 2000000 --repeats 5
"""

from __future__ import annotations

import argparse
import math
import os

import numba
import numpy as np
from _timing import median_time

import brdfkit
from brdfkit._kern import INV_PI, INV_TWO_PI, below_horizon, n_dot_h, r_dot_v
from brdfkit.models._drivers import loop_driver
from brdfkit.models._lobes import lobe_pow

INV_8PI = 1.0 / (8.0 * math.pi)


@numba.njit(cache=False)
def former_modified_phong(ix, iy, iz, ox, oy, oz, p):
    if below_horizon(iz, oz):
        return 0.0
    rho_d, rho_s, n = p[0], p[1], p[2]
    cos_r = r_dot_v(ix, iy, iz, ox, oy, oz)
    return rho_d * INV_PI + rho_s * (n + 2.0) * INV_TWO_PI * lobe_pow(cos_r, n)


@numba.njit(cache=False)
def former_modified_blinn_phong(ix, iy, iz, ox, oy, oz, p):
    if below_horizon(iz, oz):
        return 0.0
    rho_d, rho_s, n = p[0], p[1], p[2]
    nh = n_dot_h(ix, iy, iz, ox, oy, oz)
    return rho_d * INV_PI + rho_s * (n + 8.0) * INV_8PI * lobe_pow(nh, n)


@numba.njit(cache=False)
def former_nielsen_no_eta(ix, iy, iz, ox, oy, oz, p):
    """The former nielsen kernel for η not given (F = 1), its common path (no rescaling)."""
    if below_horizon(iz, oz):
        return 0.0
    rho_d, k_s, s, alpha = p[0], p[1], p[2], p[3]
    lv = ix * ox + iy * oy + iz * oz
    sx, sy, sz = ix + ox, iy + oy, iz + oz
    length = math.sqrt(sx * sx + sy * sy + sz * sz)
    hz = sz / length
    hz2 = hz * hz
    base = (1.0 - alpha) * (2.0 * iz * oz - lv) + alpha * hz2 * hz2
    return rho_d * INV_PI + k_s * lobe_pow(base, s)


CASES = (("modified-phong", {"rho_d": 0.2, "rho_s": 0.5, "n": 20.0}, former_modified_phong),
         ("modified-blinn-phong", {"rho_d": 0.2, "rho_s": 0.5, "n": 20.0},
          former_modified_blinn_phong),
         ("nielsen", {}, former_nielsen_no_eta),
         # the lobe series: the kernel of the class (a loop over the lobes; still the
         # kernel of the albedo and sphere loops) against the formula unrolled per count
         ("lafortune", {}, brdfkit.models.MODELS["lafortune"].kernel),
         ("lafortune", {"C_xy": [-1.0, -0.9], "C_z": [1.0, 0.7], "n": [20.0, 5.0]},
          brdfkit.models.MODELS["lafortune"].kernel),
         ("nh-power-series", {}, brdfkit.models.MODELS["nh-power-series"].kernel))


def hemisphere(rng, n: int) -> np.ndarray:
    z = rng.random(n)
    ph = 2.0 * math.pi * rng.random(n)
    s = np.sqrt(1.0 - z * z)
    return np.stack([s * np.cos(ph), s * np.sin(ph), z], -1)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--pairs", type=int, default=2_000_000)
    ap.add_argument("--repeats", type=int, default=5)
    args = ap.parse_args(argv)
    rng = np.random.default_rng(12345)
    wi, wo = hemisphere(rng, args.pairs), hemisphere(rng, args.pairs)
    print("load average (1, 5, 15 min): {:.2f} {:.2f} {:.2f}".format(*os.getloadavg()))
    print(f"{args.pairs:,} pairs, median of {args.repeats} after a warm-up\n")
    print("| model                | former M evals/s | formula M evals/s | formula/former |")
    print("|----------------------|------------------|-------------------|----------------|")
    for name, params, former in CASES:
        m = brdfkit.model(name, **params)
        old = loop_driver(former)  # the "checked" loop BRDF.eval ran for a kernel
        out = np.empty((args.pairs, 1))
        old(wi, wo, m.packed, out)
        new = m.eval(wi, wo)
        if not np.array_equal(out[:, 0], new):
            rel = np.max(np.abs(out[:, 0] - new) / np.maximum(np.abs(out[:, 0]), 1e-300))
            print(f"note: {name}: former and formula differ, max rel {rel:.2e}")
        t_old = median_time(lambda old=old, out=out, m=m: old(wi, wo, m.packed, out),
                            args.repeats)
        t_new = median_time(lambda m=m: m.eval(wi, wo), args.repeats)
        label = name if "n" not in params or np.ndim(params["n"]) == 0 else \
            f"{name} {len(params['n'])} lobes"
        print(f"| {label:20s} | {args.pairs / t_old / 1e6:16.1f} | "
              f"{args.pairs / t_new / 1e6:17.1f} | {t_old / t_new:13.2f}x |")
    print("\nload average (1, 5, 15 min): {:.2f} {:.2f} {:.2f}".format(*os.getloadavg()))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
