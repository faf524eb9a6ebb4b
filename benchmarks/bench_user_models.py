"""Evaluation speed of models written by a user vs the same formulas built in (issue 21 §6).

"A Python-defined model within 1.2× of the same formula built in": for N random pairs
(both directions uniform on the upper hemisphere, fixed seed, float64 (N, 3)) this times
``model.eval(wi, wo)`` end to end, the median of ``--repeats`` runs after a warm-up, the
user model and its built-in counterpart alternating (so a change of the machine's load
hits both), and prints them side by side with the ratio user / built-in.

Rows
----
- modified Phong (Nielsen et al. eq. 1), ρ_d = 0.2, ρ_s = 0.5, n = 20, written in the
  formula language as a user would (``max(0, R·V)ⁿ`` as ``pos_pow(R·V, n)``, the
  built-in's power) vs ``modified-phong``, and with the power as ``exp(n log R·V)``;
- Walter et al. (2007) eq. (20) with GGX D and Smith G₁ (eqs. 33–34), α = 0.2, F = 1,
  as a user would write it vs ``microfacet`` (distribution ggx, no Fresnel);
- the same written with the built-in's arithmetic (G₁/cos θ, one division by |ω_i + ω_o|²:
  ``models/microfacet.py``), which separates the cost of the user's formula from that of
  the machinery (the generated kernel and its loop);
- the BRDF Explorer file of the same formula, ``tests/brdf_files/walter_ggx.brdf`` (its
  GLSL translated by ``brdfkit.glsl``), α = 0.2, vs ``microfacet``: target ≤ 1.2×; and
  a ``.brdf`` of the built-in's arithmetic (:data:`WALTER_AS_BUILTIN`), as for Python.

The user file is written to a temporary directory, loaded through the spec
(``brdfkit.model("…/user_models.py:NAME")``) and compiled before the timings. Before
timing, the values are compared (largest relative difference on 10⁵ pairs). More rows
are one entry of :data:`ROWS`.

Measured (2-core "Intel(R) Xeon(R) Processor", shared, load average 1.2-1.8; 10 M pairs,
five runs of the script): the Walter GGX ``.brdf`` 1.22, 1.25, 1.24, 1.19, 1.25, 1.33×
the built-in (median 1.245: over the 1.2 target), the same formula in a Python file
1.20-1.23×; the ``.brdf`` with the built-in's arithmetic 1.04, 1.00, 1.02× (values equal
to 1.1e-15). The translation adds nothing (its generated kernel is the file's arithmetic,
interned, in order): the corpus file's formula costs 7 divisions and 3 square roots per
pair (``normalize``, G₁ through tan²θ twice, the final 1/(4 N·L N·V)) where the built-in
shares one 1/|s|² and takes G₁/cos θ; the translator keeps GLSL's operations as written
(float32 agreement with a GPU), so the ratio is the file's formula's.

Usage::

    .venv/bin/python benchmarks/bench_user_models.py                  # 10 M pairs, 5 runs
    .venv/bin/python benchmarks/bench_user_models.py --pairs 1000000 --repeats 3
"""

from __future__ import annotations

import argparse
import os
import pathlib
import tempfile
import time

import numpy as np

import brdfkit

USER_MODELS = '''\
from brdfkit.formula import Param, define, exp, formula, log, maximum, pos_pow, select, sqrt

PI = 3.141592653589793


@formula
def modified_phong(ix, iy, iz, ox, oy, oz, rho_d, rho_s, n):
    rv = 2.0 * iz * oz - (ix * ox + iy * oy + iz * oz)          # R.V
    return rho_d / PI + rho_s * (n + 2.0) / (2.0 * PI) * pos_pow(rv, n)


@formula
def modified_phong_exp_log(ix, iy, iz, ox, oy, oz, rho_d, rho_s, n):
    rv = 2.0 * iz * oz - (ix * ox + iy * oy + iz * oz)
    lobe = select(rv > 0.0, exp(n * log(select(rv > 0.0, rv, 1.0))), 0.0)
    return rho_d / PI + rho_s * (n + 2.0) / (2.0 * PI) * lobe


@formula
def smith_g1(c, a2):
    c2 = c * c
    return 2.0 / (1.0 + sqrt(1.0 + a2 * (1.0 - c2) / c2))        # Walter eq. (34)


@formula
def walter_ggx(ix, iy, iz, ox, oy, oz, alpha):
    hx, hy, hz = ix + ox, iy + oy, iz + oz
    cos_h = hz / sqrt(hx * hx + hy * hy + hz * hz)
    a2 = alpha * alpha
    t = (a2 - 1.0) * cos_h * cos_h + 1.0
    d = a2 / (PI * t * t)                                        # Walter eq. (33)
    return d * smith_g1(iz, a2) * smith_g1(oz, a2) / (4.0 * iz * oz)   # eq. (20), F = 1


@formula
def g1_over_cos(c, a2):
    return 2.0 / (c + sqrt(c * c + a2 * maximum(0.0, 1.0 - c * c)))


@formula
def walter_ggx_as_builtin(ix, iy, iz, ox, oy, oz, alpha):
    # the built-in's arithmetic (models/microfacet.py): |s|² terms, G1/cos, one 1/|s|²
    sx, sy, sz = ix + ox, iy + oy, iz + oz
    sxy2 = sx * sx + sy * sy
    sz2 = sz * sz
    inv_l2 = 1.0 / (sxy2 + sz2)
    a2 = alpha * alpha
    u = sz2 * inv_l2 + sxy2 * inv_l2 / a2
    d = 1.0 / (PI * a2 * (u * u))
    return d * g1_over_cos(iz, a2) * g1_over_cos(oz, a2) * 0.25


MODELS = [
    define("walter_ggx_as_builtin", eval=walter_ggx_as_builtin, reciprocal=True,
           isotropic=True, params=[Param("alpha", 0.2, 1e-4, 4.0)]),
    define("modified_phong", eval=modified_phong, reciprocal=True, isotropic=True, params=[
        Param("rho_d", 0.2, 0.0, 1.0, kind="colour"), Param("rho_s", 0.5, 0.0, 1.0, kind="colour"),
        Param("n", 20.0, 0.0, 1e6)]),
    define("modified_phong_exp_log", eval=modified_phong_exp_log, reciprocal=True,
           isotropic=True, params=[Param("rho_d", 0.2, 0.0, 1.0), Param("rho_s", 0.5, 0.0, 1.0),
                                   Param("n", 20.0, 0.0, 1e6)]),
    define("walter_ggx", eval=walter_ggx, reciprocal=True, isotropic=True,
           params=[Param("alpha", 0.2, 1e-4, 4.0)]),
]
'''


#: The corpus file of Walter GGX with Smith G1, F = 1, as a user writes it from the paper
#: (D from |H × N|², G1 from tan²θ).
WALTER_FILE = pathlib.Path(__file__).resolve().parent.parent / "tests" / "brdf_files" / \
    "walter_ggx.brdf"


#: The same formula in a .brdf with the built-in's arithmetic (as ``walter_ggx_as_builtin``
#: above; |s × N|² = s_x² + s_y² keeps the isotropy visible to the translator).
WALTER_AS_BUILTIN = """analytic
::begin parameters
float alpha 1e-4 4 0.2
::end parameters
::begin shader
const float PI = 3.14159265358979323846;
float g1_over_cos(float c, float a2)
{
    return 2.0 / (c + sqrt(c * c + a2 * max(0.0, 1.0 - c * c)));
}
vec3 BRDF(vec3 L, vec3 V, vec3 N, vec3 X, vec3 Y)
{
    vec3 s = L + V;
    vec3 t = cross(s, N);
    float sxy2 = dot(t, t);
    float sz2 = dot(s, N) * dot(s, N);
    float inv_l2 = 1.0 / (sxy2 + sz2);
    float a2 = alpha * alpha;
    float u = sz2 * inv_l2 + sxy2 * inv_l2 / a2;
    float d = 1.0 / (PI * a2 * (u * u));
    return vec3(d * g1_over_cos(dot(N, L), a2) * g1_over_cos(dot(N, V), a2) * 0.25);
}
::end shader
"""


def _write(path: pathlib.Path, text: str) -> pathlib.Path:
    path.write_text(text)
    return path


def rows(directory: pathlib.Path) -> list[tuple[str, object, object]]:
    """(label, user model, built-in model) per row."""
    path = directory / "user_models.py"
    path.write_text(USER_MODELS)
    return [
        ("modified Phong, n = 20 (Python file)",
         brdfkit.model(f"{path}:modified_phong", rho_d=0.2, rho_s=0.5, n=20.0),
         brdfkit.model("modified-phong", rho_d=0.2, rho_s=0.5, n=20.0)),
        ("  the same, the power as exp(n log R.V)",
         brdfkit.model(f"{path}:modified_phong_exp_log", rho_d=0.2, rho_s=0.5, n=20.0),
         brdfkit.model("modified-phong", rho_d=0.2, rho_s=0.5, n=20.0)),
        ("Walter GGX + Smith, a = 0.2 (Python file)",
         brdfkit.model(f"{path}:walter_ggx", alpha=0.2),
         brdfkit.model("microfacet", distribution="ggx", alpha=0.2)),
        ("  the same, the built-in's arithmetic (G1/cos)",
         brdfkit.model(f"{path}:walter_ggx_as_builtin", alpha=0.2),
         brdfkit.model("microfacet", distribution="ggx", alpha=0.2)),
        ("Walter GGX + Smith, a = 0.2 (.brdf)",
         brdfkit.model(str(WALTER_FILE), alpha=0.2),
         brdfkit.model("microfacet", distribution="ggx", alpha=0.2)),
        ("  the same, the built-in's arithmetic (.brdf)",
         brdfkit.model(str(_write(directory / "walter_as_builtin.brdf", WALTER_AS_BUILTIN)),
                       alpha=0.2),
         brdfkit.model("microfacet", distribution="ggx", alpha=0.2)),
    ]


#: Where further rows come from (a function of the temporary directory, as :func:`rows`).
ROWS = [rows]


def directions(n: int, rng) -> np.ndarray:
    z = rng.uniform(0.0, 1.0, n)
    phi = rng.uniform(0.0, 2.0 * np.pi, n)
    s = np.sqrt(1.0 - z * z)
    return np.ascontiguousarray(np.stack([s * np.cos(phi), s * np.sin(phi), z], axis=-1))


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--pairs", type=int, default=10_000_000)
    ap.add_argument("--repeats", type=int, default=5)
    args = ap.parse_args()
    rng = np.random.default_rng(2021)
    wi, wo = directions(args.pairs, rng), directions(args.pairs, rng)
    print(f"{args.pairs:,} pairs, median of {args.repeats} runs; load average "
          f"{os.getloadavg()[0]:.2f}")
    with tempfile.TemporaryDirectory() as tmp:
        table = [r for source in ROWS for r in source(pathlib.Path(tmp))]
        out = []
        for label, user, builtin in table:
            a, b = user.eval(wi[:100_000], wo[:100_000]), builtin.eval(wi[:100_000],
                                                                       wo[:100_000])
            diff = float(np.max(np.abs(a - b) / np.maximum(np.abs(b), 1e-300)))
            tu, tb = [], []
            for _ in range(args.repeats):  # alternating: a load change hits both
                for model, ts in ((user, tu), (builtin, tb)):
                    t = time.perf_counter()
                    model.eval(wi, wo)
                    ts.append(time.perf_counter() - t)
            out.append((label, float(np.median(tu)), float(np.median(tb)), diff))
    print(f"\n{'model':44s} {'user s':>8s} {'built-in s':>10s} {'ratio':>6s} "
          f"{'Mpairs/s':>9s} {'max rel diff':>12s}")
    for label, tu, tb, diff in out:
        print(f"{label:44s} {tu:8.3f} {tb:10.3f} {tu / tb:6.2f} {args.pairs / tu / 1e6:9.1f} "
              f"{diff:12.2e}")
    print(f"\nload average after: {os.getloadavg()[0]:.2f}; target: ratio <= 1.2")


if __name__ == "__main__":
    main()
