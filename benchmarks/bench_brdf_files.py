"""BRDF Explorer files in brdfkit: translate + compile time, and evaluation speed.

Issue 21 §6 targets, measured side by side in one run:

1. translating and compiling a Disney-sized file (``benchmarks/brdf/principled.brdf``,
   Burley 2012, ~250 scalar operations) until its first value, in a new process with an
   empty cache (``BRDFKIT_CACHE_DIR`` a fresh directory): ≤ 3 s; the same in a new
   process from the cache (keyed on the file's content): ≤ 0.3 s. Both are timed inside
   the child from ``brdfkit.model(path)`` to the first ``eval``, after a built-in model's
   first evaluation has paid Numba's own start-up in that process (~0.3–0.5 s, any
   model's first compiled call: its registries, SciPy's BLAS); that, the interpreter
   start and ``import brdfkit`` are printed beside, not counted;
2. the compiled ``.brdf`` of Walter GGX (``tests/brdf_files/walter_ggx.brdf``, or the
   built-in copy below when the corpus is absent) against the built-in ``microfacet``
   (distribution ggx, no Fresnel, α = 0.2) on 10 M random pairs: medians of 5 runs,
   interleaved, ratio ≤ 1.2.

Run: ``python benchmarks/bench_brdf_files.py [--pairs N] [--repeats K]``.
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
PRINCIPLED = HERE / "brdf" / "principled.brdf"
WALTER = HERE.parent / "tests" / "brdf_files" / "walter_ggx.brdf"

_WALTER_TEXT = """analytic
# Walter et al. 2007: GGX D (eq. 33) with Smith G1 (eq. 34), no Fresnel
::begin parameters
float alpha 0.001 1 0.2
::end parameters
::begin shader
const float PI = 3.14159265358979323846;
float G1(float c, float a) { return 2.0 / (1.0 + sqrt(1.0 + a*a*(1.0 - c*c)/(c*c))); }
vec3 BRDF(vec3 L, vec3 V, vec3 N, vec3 X, vec3 Y)
{
    vec3 H = normalize(L + V);
    float NdotH = dot(N, H);
    float NdotL = dot(N, L), NdotV = dot(N, V);
    float a2 = alpha*alpha;
    float t = 1.0 + (a2 - 1.0)*NdotH*NdotH;
    return vec3(a2 / (PI*t*t) * G1(NdotL, alpha) * G1(NdotV, alpha) / (4.0*NdotL*NdotV));
}
::end shader
"""

_CHILD = """
import json, sys, time
t0 = time.perf_counter()
import numpy as np
import brdfkit
w = np.array([[0.0, 0.0, 1.0]])
t1 = time.perf_counter()
brdfkit.model("lambert").eval(w, w)  # Numba's own start-up (its registries, BLAS), any model's
t1b = time.perf_counter()
m = brdfkit.model(sys.argv[1])
v = m.eval(np.array([[0.3, 0.2, 0.9327379053]]), np.array([[-0.1, 0.4, 0.9110433579]]))
t2 = time.perf_counter()
print(json.dumps({"import": t1 - t0, "numba_start": t1b - t1, "model_to_value": t2 - t1b,
                  "value": v.tolist()}))
"""


def child(path: Path, cache: str) -> dict:
    env = {**os.environ, "BRDFKIT_CACHE_DIR": cache}
    start = time.perf_counter()
    out = subprocess.run([sys.executable, "-c", _CHILD, str(path)], env=env, check=True,
                         capture_output=True, text=True)
    got = json.loads(out.stdout.strip().splitlines()[-1])
    got["process"] = time.perf_counter() - start
    return got


def compile_rows(repeats: int) -> list:
    rows = []
    for _r in range(repeats):
        with tempfile.TemporaryDirectory(prefix="brdfkit-bench-") as cache:
            first = child(PRINCIPLED, cache)
            again = child(PRINCIPLED, cache)
        rows.append((first, again))
    return rows


def unit(rng, n):
    v = rng.normal(size=(n, 3))
    v[:, 2] = np.abs(v[:, 2])
    return v / np.linalg.norm(v, axis=1, keepdims=True)


def eval_rows(n_pairs: int, repeats: int):
    import brdfkit

    path = WALTER
    if not path.exists():
        path = Path(tempfile.mkdtemp()) / "walter_ggx.brdf"
        path.write_text(_WALTER_TEXT)
    params = {"alpha": 0.2} if "alpha" in {p.name for p in brdfkit.model(path).params} else {}
    f = brdfkit.model(path, **params)
    b = brdfkit.model("microfacet", distribution="ggx", alpha=0.2)
    rng = np.random.default_rng(1)
    wi, wo = unit(rng, n_pairs), unit(rng, n_pairs)
    agree = np.max(np.abs(f.eval(wi[:10000], wo[:10000]) - b.eval(wi[:10000], wo[:10000]))
                   / np.maximum(b.eval(wi[:10000], wo[:10000]), 1e-300))
    times = {"file": [], "builtin": []}
    for _ in range(repeats):  # interleaved: the same load for both
        for name, m in (("file", f), ("builtin", b)):
            t = time.perf_counter()
            m.eval(wi, wo)
            times[name].append(time.perf_counter() - t)
    return path, agree, times


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--pairs", type=int, default=10_000_000)
    ap.add_argument("--repeats", type=int, default=5)
    ap.add_argument("--compile-repeats", type=int, default=3)
    args = ap.parse_args(argv)
    try:
        cpu = next(line.split(":", 1)[1].strip() for line in open("/proc/cpuinfo")
                   if line.startswith("model name"))
    except (OSError, StopIteration):
        cpu = "unknown CPU"
    print(f"# {cpu}; load average {os.getloadavg()[0]:.2f}")
    rows = compile_rows(args.compile_repeats)
    med = lambda xs: statistics.median(xs)  # noqa: E731
    first = med([r[0]["model_to_value"] for r in rows])
    again = med([r[1]["model_to_value"] for r in rows])
    print("\n## principled.brdf (Burley 2012): model(path) → first value, new process")
    print("| run | median (s) | target (s) | process wall (s) | import brdfkit (s) | Numba "
          "start-up (s) |")
    print("|---|---|---|---|---|---|")
    for label, k, value, target in (("empty cache", 0, first, 3.0),
                                    ("from cache", 1, again, 0.3)):
        print(f"| {label} | {value:.3f} | {target} | {med([r[k]['process'] for r in rows]):.2f}"
              f" | {med([r[k]['import'] for r in rows]):.2f} | "
              f"{med([r[k]['numba_start'] for r in rows]):.2f} |")
    path, agree, times = eval_rows(args.pairs, args.repeats)
    tf, tb = med(times["file"]), med(times["builtin"])
    print(f"\n## eval, {args.pairs:,} pairs, median of {args.repeats} (interleaved)")
    print(f"# {path.name} vs microfacet ggx α=0.2: max relative difference {agree:.1e}")
    print("| model | median (s) | M evals/s | ratio to built-in | target |")
    print("|---|---|---|---|---|")
    print(f"| microfacet (built-in) | {tb:.3f} | {args.pairs / tb / 1e6:.1f} | 1.00 | |")
    print(f"| {path.name} | {tf:.3f} | {args.pairs / tf / 1e6:.1f} | {tf / tb:.2f} | ≤ 1.2 |")


if __name__ == "__main__":
    main()
