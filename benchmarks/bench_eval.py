"""Evaluation throughput: brdfkit vs Mitsuba 3 (llvm_ad_rgb) vs plain NumPy.

For N random direction pairs (both uniform on the upper hemisphere, float64
NumPy arrays of shape (N, 3), fixed seed) this prints the median (over
``--repeats`` runs, after one warm-up run) of BRDF evaluations per second,
end to end: NumPy arrays in, NumPy array out.

Rows
----
- brdfkit ``modified-phong``, ``nielsen``, ``cook-torrance`` and ``microfacet``
  (Beckmann, α = 0.1, F = 1): ``model.eval(wi, wo)`` → (N,) float64.
- Mitsuba 3 ``roughconductor`` (Beckmann, same α, ``material="none"`` so F = 1),
  variant ``llvm_ad_rgb``: NumPy float64 (N, 3) → float32 ``mi.Vector3f`` →
  ``SurfaceInteraction3f``/``BSDFContext`` → ``BSDF.eval`` → ``Color3f`` →
  NumPy, all inside the timed region. Mitsuba's ``eval`` returns f_r·cos θ
  (its convention); the cosine costs one multiply and is not removed.
- Mitsuba 3 with Python-registered twins (``mi.register_bsdf``) of ``modified-phong``,
  ``nielsen`` and ``cook-torrance`` (the same formulas written in Dr.Jit:
  :func:`twin_formulas`), evaluated the same way (Dr.Jit traces the Python ``eval`` into
  one LLVM kernel).
- Plain NumPy modified Phong (vectorised array expressions, float64).

The ratio column is brdfkit / Mitsuba for the comparable pairs: ``microfacet``
vs ``roughconductor`` and each twinned model vs its Python-registered twin.
Before timing, the script checks that the compared implementations agree
(relative difference of f_r·cos θ on 10⁵ pairs; Mitsuba is single precision
and uses the rational fit of the Beckmann G₁, brdfkit the exact erf form,
tabulated to < 1e-13 relative).

The machine's load average (``os.getloadavg``) is printed before and after
the timings: the numbers are only comparable within one run, and only when
the load is low. ``--threads 1`` gives single-thread costs (ns/eval column).

Mitsuba's LLVM variants need Debian's ``libllvm19``
(``apt-get update && apt-get install -y libllvm19``; LLVM 15/16 load but abort
on microfacet kernels). The script looks for ``libLLVM-19.so*`` and sets
``DRJIT_LIBLLVM_PATH`` if it is not set; it first probes the variant in a
child process (an abort there cannot take the benchmark down) and prints a
note and skips the Mitsuba rows if it does not work.

Usage::

    .venv/bin/python benchmarks/bench_eval.py                 # 10 million pairs, 5 repeats
    .venv/bin/python benchmarks/bench_eval.py --pairs 1000000 --repeats 3
"""

from __future__ import annotations

import argparse
import glob
import math
import os
import statistics
import subprocess
import sys
import time

import numpy as np

ALPHA = 0.1
PHONG = {"rho_d": 0.2, "rho_s": 0.5, "n": 20.0}

PROBE = r"""
import mitsuba as mi, drjit as dr
mi.set_variant("llvm_ad_rgb")
b = mi.load_dict({"type": "roughconductor", "distribution": "beckmann", "alpha": 0.1,
                  "material": "none"})
si = dr.zeros(mi.SurfaceInteraction3f)
si.wi = mi.Vector3f([0.3, 0.1], [0.0, 0.2], [0.954, 0.97])
v = b.eval(mi.BSDFContext(), si, mi.Vector3f([-0.3, 0.0], [0.0, -0.2], [0.954, 0.97]))
print(float(v.x[0]))
"""


# --------------------------------------------------------------------------- inputs
def random_pairs(n: int, seed: int = 12345) -> tuple[np.ndarray, np.ndarray]:
    """Two (n, 3) float64 arrays uniform on the upper hemisphere (z = u, φ = 2πu')."""
    rng = np.random.default_rng(seed)

    def hemi():
        z = 1.0 - rng.random(n)  # (0, 1]
        phi = 2.0 * np.pi * rng.random(n)
        r = np.sqrt(np.maximum(0.0, 1.0 - z * z))
        return np.ascontiguousarray(np.stack([r * np.cos(phi), r * np.sin(phi), z], axis=-1))

    return hemi(), hemi()


def median_rate(fn, n: int, repeats: int) -> tuple[float, float]:
    """(median evaluations per second, median seconds) over *repeats* runs after a warm-up."""
    fn()
    times = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t0)
    t = statistics.median(times)
    return n / t, t


# --------------------------------------------------------------------------- NumPy reference
def numpy_modified_phong(wi: np.ndarray, wo: np.ndarray, rho_d: float, rho_s: float,
                         n: float) -> np.ndarray:
    """Nielsen eq. (1) in plain NumPy: ρ_d/π + ρ_s (n+2)/2π max(0, R·V)ⁿ, 0 below the horizon."""
    iz, oz = wi[:, 2], wo[:, 2]
    r_dot_v = 2.0 * iz * oz - np.einsum("ij,ij->i", wi, wo)  # R·V with R the mirror of wi
    f = rho_d / np.pi + rho_s * (n + 2.0) / (2.0 * np.pi) * np.maximum(r_dot_v, 0.0) ** n
    return np.where((iz > 0.0) & (oz > 0.0), f, 0.0)


# --------------------------------------------------------------------------- Mitsuba
def find_libllvm19() -> str | None:
    pats = ["/usr/lib/x86_64-linux-gnu/libLLVM-19.so*", "/usr/lib/x86_64-linux-gnu/libLLVM.so.19*",
            "/usr/lib/aarch64-linux-gnu/libLLVM-19.so*", "/usr/lib/llvm-19/lib/libLLVM*.so*"]
    for pat in pats:
        hits = sorted(glob.glob(pat))
        if hits:
            return hits[0]
    return None


def probe_mitsuba_llvm() -> str:
    """'' if the llvm_ad_rgb variant evaluates a roughconductor in a child process, else why not."""
    if "DRJIT_LIBLLVM_PATH" not in os.environ:
        lib = find_libllvm19()
        if lib:
            os.environ["DRJIT_LIBLLVM_PATH"] = lib
    try:
        out = subprocess.run([sys.executable, "-c", PROBE], capture_output=True, text=True,
                             timeout=600, env=os.environ.copy())
    except subprocess.TimeoutExpired:
        return "the llvm_ad_rgb probe timed out"
    if out.returncode != 0:
        last = (out.stderr.strip().splitlines() or ["(no message)"])[-1]
        return (f"the llvm_ad_rgb probe failed (exit {out.returncode}): {last[:200]}. "
                "Install Debian's libllvm19 (apt-get install -y libllvm19) or set "
                "DRJIT_LIBLLVM_PATH to libLLVM-19.so")
    return ""


#: The brdfkit models with a Dr.Jit twin (name → Mitsuba row), at these parameters.
NIELSEN = {"rho_d": 0.2, "k_s": 2.0, "s": 20.0, "alpha": 0.5}  # brdfkit's defaults, F = 1
COOK = {"m": 0.1, "rho_s": 1.0}  # brdfkit's defaults, F = 1
#: Floor of (N·L)(N·V) in Cook-Torrance's denominator (brdfkit.models.vgroove.DENOM_FLOOR).
DENOM_FLOOR = 1e-280
TWINS = {"modified-phong": "python-phong", "nielsen": "python-nielsen",
         "cook-torrance": "python-cook-torrance"}


def twin_formulas(dr, mi):
    """name → f(v, light, cos_v, cos_l) -> f_r: the brdfkit formulas in Dr.Jit (float32).

    Same expressions as the brdfkit kernels (models/phong.py, grazing.py ``_nielsen``,
    vgroove.py ``_cook_torrance``), without the far-grazing underflow branches (both
    directions within 1e-140 of the horizon: no random pair gets there).
    """
    def phong(v, light, cos_v, cos_l):
        r_dot_v = dr.maximum(dr.dot(mi.reflect(v), light), 0.0)
        return (PHONG["rho_d"] / math.pi + PHONG["rho_s"] * (PHONG["n"] + 2.0)
                / (2.0 * math.pi) * dr.power(r_dot_v, PHONG["n"]))

    def nielsen(v, light, cos_v, cos_l):
        a = NIELSEN["alpha"]
        h = v + light
        hz = h.z * dr.rsqrt(dr.squared_norm(h))  # N·H
        hz2 = hz * hz
        base = (1.0 - a) * (2.0 * cos_v * cos_l - dr.dot(v, light)) + a * hz2 * hz2
        return (NIELSEN["rho_d"] / math.pi
                + NIELSEN["k_s"] * dr.power(dr.maximum(base, 0.0), NIELSEN["s"]))

    def cook(v, light, cos_v, cos_l):
        m = COOK["m"]
        h = v + light
        l2 = dr.squared_norm(h)
        c2 = h.z * h.z / l2  # cos²δ
        d = dr.exp(-(1.0 - c2) / (c2 * m * m)) / (4.0 * math.pi * m * m * c2 * c2)
        g = dr.minimum(1.0, 4.0 * h.z * dr.minimum(cos_v, cos_l) / l2)  # V-groove G
        return COOK["rho_s"] * d * g / dr.maximum(cos_v * cos_l, DENOM_FLOOR)

    return {"python-phong": phong, "python-nielsen": nielsen, "python-cook-torrance": cook}


def make_mitsuba(pairs_wi: np.ndarray, pairs_wo: np.ndarray):
    """Return {name: callable() -> NumPy result} for the Mitsuba rows (variant llvm_ad_rgb)."""
    import drjit as dr
    import mitsuba as mi

    mi.set_variant("llvm_ad_rgb")

    def python_bsdf(formula):
        class TwinBSDF(mi.BSDF):
            """A brdfkit formula as a Mitsuba BSDF; eval returns f_r cos θ_o (Mitsuba's
            convention)."""

            def __init__(self, props):
                mi.BSDF.__init__(self, props)
                self.m_flags = mi.BSDFFlags.DiffuseReflection | mi.BSDFFlags.GlossyReflection
                self.m_components = [self.m_flags]

            def eval(self, ctx, si, wo, active=True):
                cos_i = mi.Frame3f.cos_theta(si.wi)
                cos_o = mi.Frame3f.cos_theta(wo)
                f = formula(si.wi, wo, cos_i, cos_o)
                return mi.Color3f(dr.select((cos_i > 0) & (cos_o > 0), f * cos_o, 0.0))

            def pdf(self, ctx, si, wo, active=True):
                return mi.warp.square_to_cosine_hemisphere_pdf(wo)

            def eval_pdf(self, ctx, si, wo, active=True):
                return self.eval(ctx, si, wo, active), self.pdf(ctx, si, wo, active)

            def sample(self, ctx, si, sample1, sample2, active=True):
                bs = mi.BSDFSample3f()
                bs.wo = mi.warp.square_to_cosine_hemisphere(sample2)
                bs.pdf = mi.warp.square_to_cosine_hemisphere_pdf(bs.wo)
                bs.eta = 1.0
                bs.sampled_type = mi.UInt32(+mi.BSDFFlags.DiffuseReflection)
                bs.sampled_component = 0
                value = self.eval(ctx, si, bs.wo, active) / dr.maximum(bs.pdf, 1e-12)
                return bs, value

            def to_string(self):
                return "TwinBSDF[]"

        return TwinBSDF

    bsdfs = {"roughconductor": mi.load_dict({"type": "roughconductor",
                                             "distribution": "beckmann", "alpha": ALPHA,
                                             "material": "none"})}
    for name, formula in twin_formulas(dr, mi).items():
        plugin = "bench_" + name.replace("-", "_")
        twin = python_bsdf(formula)
        mi.register_bsdf(plugin, lambda props, cls=twin: cls(props))
        bsdfs[name] = mi.load_dict({"type": plugin})
    ctx = mi.BSDFContext()

    def run(bsdf, wi, wo):
        # Mitsuba's si.wi is the direction toward the viewer (our wo); its eval's wo is our wi.
        si = dr.zeros(mi.SurfaceInteraction3f)
        si.wi = mi.Vector3f(np.ascontiguousarray(wo.T, dtype=np.float32))
        light = mi.Vector3f(np.ascontiguousarray(wi.T, dtype=np.float32))
        value = bsdf.eval(ctx, si, light)
        return np.asarray(value.numpy(), dtype=np.float64)  # (3, N), f_r cos θ_light

    rows = {name: (lambda b=b, wi=pairs_wi, wo=pairs_wo: run(b, wi, wo))
            for name, b in bsdfs.items()}
    return rows, run, bsdfs


# --------------------------------------------------------------------------- main
def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--pairs", type=int, default=10_000_000, help="direction pairs (10 million)")
    ap.add_argument("--repeats", type=int, default=5, help="timed repetitions (median; >= 1)")
    ap.add_argument("--seed", type=int, default=12345)
    ap.add_argument("--no-mitsuba", action="store_true", help="skip the Mitsuba rows")
    ap.add_argument("--threads", type=int, default=0,
                    help="Numba threads for brdfkit (default: all); Mitsuba is not limited")
    args = ap.parse_args(argv)
    if args.pairs < 1000 or args.repeats < 1:
        ap.error("--pairs must be >= 1000 and --repeats >= 1")

    import numba

    import brdfkit

    if args.threads < 0:
        ap.error("--threads must be >= 0")
    if args.threads:
        numba.set_num_threads(args.threads)
    n = args.pairs
    wi, wo = random_pairs(n, args.seed)
    print("load average (1, 5, 15 min): {:.2f} {:.2f} {:.2f}".format(*os.getloadavg()))
    print(f"brdfkit {brdfkit.__version__}, NumPy {np.__version__}, Numba {numba.__version__} "
          f"({numba.get_num_threads()} threads), {os.cpu_count()} CPUs; {n:,} pairs, "
          f"median of {args.repeats} after a warm-up")

    models = {
        "modified-phong": brdfkit.model("modified-phong", **PHONG),
        "nielsen": brdfkit.model("nielsen", **NIELSEN),
        "cook-torrance": brdfkit.model("cook-torrance", **COOK),
        "microfacet": brdfkit.model("microfacet", distribution="beckmann", alpha=ALPHA),
    }
    rows = []  # (implementation, model, rate, seconds)
    for name, m in models.items():
        rate, t = median_rate(lambda m=m: m.eval(wi, wo), n, args.repeats)
        rows.append(("brdfkit", name, rate, t))
    rate, t = median_rate(lambda: numpy_modified_phong(wi, wo, **PHONG), n, args.repeats)
    rows.append(("NumPy", "modified-phong", rate, t))

    # correctness of the reference rows on a subset
    k = min(n, 100_000)
    f_np = numpy_modified_phong(wi[:k], wo[:k], **PHONG)
    f_bk = models["modified-phong"].eval(wi[:k], wo[:k])
    checks = [f"NumPy vs brdfkit modified-phong: max rel diff "
              f"{np.max(np.abs(f_np - f_bk) / np.maximum(f_bk, 1e-300)):.2e}"]

    note = ""
    if args.no_mitsuba:
        note = "Mitsuba rows skipped (--no-mitsuba)."
    else:
        note = probe_mitsuba_llvm()
    if not note:
        mit, run, bsdfs = make_mitsuba(wi, wo)
        # agreement first: Mitsuba returns f_r cos θ_light (3 equal channels), float32
        for key, name in (("roughconductor", "microfacet"),
                          *((v, k) for k, v in TWINS.items())):
            fm = run(bsdfs[key], wi[:k], wo[:k])[0]
            fb = models[name].eval(wi[:k], wo[:k]) * wi[:k, 2]
            big = fb > 1e-3 * fb.max()
            rel = np.abs(fm[big] - fb[big]) / fb[big]
            checks.append(f"Mitsuba {key} vs brdfkit {name} (x cos): median rel diff "
                          f"{np.median(rel):.1e}, max {rel.max():.1e}")
        for key in ("roughconductor", *TWINS.values()):
            rate, t = median_rate(mit[key], n, args.repeats)
            rows.append(("Mitsuba llvm_ad_rgb", key, rate, t))

    rate_of = {(impl.split()[0], name): r for impl, name, r, _ in rows}
    ratio = {("brdfkit", "microfacet"): ("Mitsuba", "roughconductor"),
             **{("brdfkit", k): ("Mitsuba", v) for k, v in TWINS.items()}}
    print()
    print(f"| {'implementation':<20} | {'model':<20} | {'M evals/s':>9} | {'ns/eval':>7} | "
          f"{'time (s)':>8} | {'brdfkit/Mitsuba':>20} |")
    print(f"|{'-' * 22}|{'-' * 22}|{'-' * 11}|{'-' * 9}|{'-' * 10}|{'-' * 22}|")
    for impl, name, rate, t in rows:
        other = ratio.get((impl, name))
        r = ""
        if other and other in rate_of:
            r = f"{rate / rate_of[other]:.2f}x"
        elif impl.startswith("Mitsuba"):
            mine = {v: k for k, v in ratio.items()}[(impl.split()[0], name)]
            r = f"(vs {mine[1]})"
        print(f"| {impl:<20} | {name:<20} | {rate / 1e6:9.1f} | {1e9 / rate:7.1f} | {t:8.3f} | "
              f"{r:>20} |")
    print()
    print("load average (1, 5, 15 min): {:.2f} {:.2f} {:.2f}".format(*os.getloadavg()))
    for c in checks:
        print("check:", c)
    if note:
        print("note:", note)
    return 0


if __name__ == "__main__":
    sys.exit(main())
