"""Disney principled BRDF evaluation: brdfkit ``disney`` vs Mitsuba 3's ``principled``.

For N random direction pairs (both uniform on the upper hemisphere, float64 NumPy arrays
of shape (N, 3), fixed seed) this prints the median time (over ``--repeats`` runs after a
warm-up, the two implementations interleaved in every repeat so that a change of the
machine's load hits both) of an evaluation end to end, NumPy arrays in, NumPy array out:

- brdfkit: ``brdfkit.model("disney", …).eval(wi, wo)`` → (N, 3) float64, the RGB pass of
  the shared terms (``"rgb"`` loop of ``brdfkit.models._drivers``);
- Mitsuba 3, variant ``llvm_ad_rgb``: NumPy float64 (N, 3) → float32 ``mi.Vector3f`` →
  ``SurfaceInteraction3f``/``BSDFContext`` → ``principled`` ``BSDF.eval`` → ``Color3f`` →
  NumPy (as ``bench_eval.py`` does for ``roughconductor``). Mitsuba's ``eval`` returns
  f_r·cos θ (its convention: one multiply more).

The parameters correspond as far as the two models do: ``base_color`` (Mitsuba takes linear
RGB: it gets brdfkit's linearised C_d = base_color^2.2), ``roughness``, ``anisotropic``,
``metallic``, ``specular``, ``specular_tint`` (``spec_tint``), ``sheen``, ``sheen_tint``,
``clearcoat``, ``clearcoat_gloss``; Mitsuba's ``spec_trans`` is 0 (reflection only) and
brdfkit's ``subsurface`` 0. Mitsuba's ``principled`` is Burley's 2015 revision (its
diffuse splits retro-reflection, its sheen and clearcoat differ in detail), so the values
are not compared; the work is the same kind: every lobe present. Two parameter sets: every
lobe on (``all``), and Burley's defaults (``default``: sheen and clearcoat 0, which
Mitsuba then skips at load time while brdfkit's branch-free kernel still computes them).

Target (issue 22 §5): brdfkit at least 1.2× as fast as Mitsuba (ratio = Mitsuba time /
brdfkit time). The CPU model and the load average are printed before and after: the
ratio is only meaningful within one run.

Usage::

    .venv/bin/python benchmarks/bench_disney.py                        # 1 and 10 M pairs
    .venv/bin/python benchmarks/bench_disney.py --pairs 1000000 --repeats 3
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

SETS = {
    "all": {"base_color": [0.82, 0.67, 0.16], "roughness": 0.5, "anisotropic": 0.5,
            "metallic": 0.3, "specular": 0.5, "specular_tint": 0.3, "sheen": 0.5,
            "sheen_tint": 0.5, "clearcoat": 0.5, "clearcoat_gloss": 0.6},
    "default": {"base_color": [0.82, 0.67, 0.16], "roughness": 0.5, "specular": 0.5},
}
MITSUBA_NAMES = {"specular_tint": "spec_tint"}


def cpu_model() -> str:
    try:
        out = subprocess.run(["lscpu"], capture_output=True, text=True, timeout=10).stdout
    except (OSError, subprocess.SubprocessError):
        return "unknown (no lscpu)"
    for line in out.splitlines():
        if line.startswith("Model name:"):
            return line.split(":", 1)[1].strip()
    return "unknown"


def make_mitsuba(params: dict):
    """The ``principled`` BSDF with *params* and ``run(wi, wo)`` → NumPy (3, N)."""
    import drjit as dr
    import mitsuba as mi

    mi.set_variant("llvm_ad_rgb")
    props = {"type": "principled"}
    for k, v in params.items():
        if k == "base_color":
            props[k] = {"type": "rgb", "value": (np.asarray(v) ** 2.2).tolist()}
        else:
            props[MITSUBA_NAMES.get(k, k)] = float(v)
    bsdf = mi.load_dict(props)
    ctx = mi.BSDFContext()

    def run(wi, wo):
        # Mitsuba's si.wi is the direction toward the viewer (our wo); its eval's wo is our wi
        si = dr.zeros(mi.SurfaceInteraction3f)
        si.wi = mi.Vector3f(np.ascontiguousarray(wo.T, dtype=np.float32))
        light = mi.Vector3f(np.ascontiguousarray(wi.T, dtype=np.float32))
        return np.asarray(bsdf.eval(ctx, si, light).numpy(), dtype=np.float64)

    return run


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--pairs", type=int, nargs="+", default=[1_000_000, 10_000_000],
                    help="direction pair counts (default 1 and 10 million)")
    ap.add_argument("--repeats", type=int, default=5, help="timed repetitions (median)")
    ap.add_argument("--seed", type=int, default=12345)
    args = ap.parse_args(argv)
    if min(args.pairs) < 1000 or args.repeats < 1:
        ap.error("--pairs must be >= 1000 and --repeats >= 1")

    import numba

    import brdfkit

    note = probe_mitsuba_llvm()
    print(f"CPU: {cpu_model()}; {os.cpu_count()} CPUs, Numba {numba.__version__} "
          f"({numba.get_num_threads()} threads), brdfkit {brdfkit.__version__}")
    print("load average (1, 5, 15 min): {:.2f} {:.2f} {:.2f}".format(*os.getloadavg()))
    if note:
        print("note:", note)
        return 1
    rows = []
    for n in args.pairs:
        wi, wo = random_pairs(n, args.seed)
        for label, params in SETS.items():
            model = brdfkit.model("disney", **params)
            mit = make_mitsuba(params)
            fns = {"brdfkit": lambda m=model, a=wi, b=wo: m.eval(a, b),
                   "mitsuba": lambda r=mit, a=wi, b=wo: r(a, b)}
            for fn in fns.values():
                fn()  # warm-up: compile/trace, first-touch allocations
            times = {k: [] for k in fns}
            for _ in range(args.repeats):
                for k, fn in fns.items():
                    t0 = time.perf_counter()
                    fn()
                    times[k].append(time.perf_counter() - t0)
            med = {k: statistics.median(v) for k, v in times.items()}
            rows.append((n, label, med["brdfkit"], med["mitsuba"]))
            del mit
    print()
    print("| pairs | parameters | brdfkit disney (ns/eval) | Mitsuba principled (ns/eval) | "
          "Mitsuba / brdfkit |")
    print("|---:|---|---:|---:|---:|")
    for n, label, tb, tm in rows:
        print(f"| {n:,} | {label} | {1e9 * tb / n:.1f} | {1e9 * tm / n:.1f} | {tm / tb:.2f}x |")
    print()
    print("load average (1, 5, 15 min): {:.2f} {:.2f} {:.2f}".format(*os.getloadavg()))
    print("target: brdfkit >= 1.2x as fast as Mitsuba's principled (ratio >= 1.2)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
