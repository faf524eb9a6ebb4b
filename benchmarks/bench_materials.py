"""Built-in and measured materials: evaluation rates, MERL lookup vs NumPy, I/O, export.

For N random direction pairs (both uniform on the upper hemisphere, float64 (N, 3),
fixed seed) this prints medians over ``--repeats`` runs after one warm-up run:

- surrogate evaluation rate, M pairs/s (3 channels each) and M channel-evals/s, of
  ``merl:nickel`` as NBRDF (blocked 3-channel driver), NBRDF through the per-channel
  scalar kernel (the whole net once per channel: the engines' path), NPF, ABC, SGD;
- ``MeasuredBRDF`` lookup rate (nearest, linear) vs a plain NumPy implementation of
  the same nearest lookup (the reference reader's formulas, vectorised); the table is
  ``merl:nickel`` exported onto the MERL grid;
- ``read_binary`` of a 35 MB file, and the export of an NBRDF material
  (``table_from_function`` + ``write_binary``).

Targets (issue 9): lookups ≥ 50 M evals/s and ≥ 5x NumPy; read ≤ 0.15 s; NBRDF export
≤ 1 s. The machine's load average is printed: numbers are comparable within one run.

Usage::

    .venv/bin/python benchmarks/bench_materials.py               # 10 M pairs, 5 repeats
    .venv/bin/python benchmarks/bench_materials.py --pairs 1000000 --repeats 3
"""

from __future__ import annotations

import argparse
import os
import statistics
import tempfile
import time

import numpy as np


def random_pairs(n: int, seed: int = 12345):
    rng = np.random.default_rng(seed)

    def hemi():
        z = 1.0 - rng.random(n)
        phi = 2.0 * np.pi * rng.random(n)
        r = np.sqrt(1.0 - z * z)
        return np.ascontiguousarray(np.stack([r * np.cos(phi), r * np.sin(phi), z], -1))

    return hemi(), hemi()


def numpy_nearest(values, wi, wo):
    """The reference reader's nearest lookup in NumPy (values: (3, 1458000) in 1/sr)."""
    h = wi + wo
    h /= np.linalg.norm(h, axis=-1, keepdims=True)
    theta_h = np.arccos(np.clip(h[:, 2], -1, 1))
    phi_h = np.arctan2(h[:, 1], h[:, 0])
    c, s = np.cos(-phi_h), np.sin(-phi_h)
    tx = wi[:, 0] * c - wi[:, 1] * s
    ty = wi[:, 0] * s + wi[:, 1] * c
    tz = wi[:, 2]
    c, s = np.cos(-theta_h), np.sin(-theta_h)
    dx = tx * c + tz * s
    dz = tz * c - tx * s
    theta_d = np.arccos(np.clip(dz, -1, 1))
    phi_d = np.arctan2(ty, dx)
    ih = np.clip(np.sqrt(np.maximum(theta_h, 0) / (np.pi / 2) * 8100).astype(np.int64), 0, 89)
    idd = np.clip((theta_d / (np.pi / 2) * 90).astype(np.int64), 0, 89)
    phi_d = np.where(phi_d < 0, phi_d + np.pi, phi_d)
    ip = np.clip((phi_d / np.pi * 180).astype(np.int64), 0, 179)
    idx = ip + 180 * idd + 16200 * ih
    out = values[:, idx].T
    return np.where(((wi[:, 2] > 0) & (wo[:, 2] > 0))[:, None], out, 0.0)


def timed(f, repeats: int) -> float:
    f()  # warm-up (compilation)
    ts = []
    for _ in range(repeats):
        t = time.perf_counter()
        f()
        ts.append(time.perf_counter() - t)
    return statistics.median(ts)


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--pairs", type=int, default=10_000_000)
    ap.add_argument("--repeats", type=int, default=5)
    args = ap.parse_args(argv)

    from brdfkit.data import (
        MeasuredBRDF,
        material,
        read_binary,
        table_from_function,
        write_binary,
    )
    from brdfkit.models._base import eval_pairs_checked

    n = args.pairs
    print(f"load average before: {os.getloadavg()}")
    wi, wo = random_pairs(n)
    rows = []

    def rate(label, f, channels=3, note=""):
        t = timed(f, args.repeats)
        rows.append((label, t, n / t / 1e6, channels * n / t / 1e6, note))
        return t

    nb = material("merl:nickel")
    rate("NBRDF merl:nickel (blocked driver)", lambda: nb.eval(wi, wo))
    out = np.empty((n, 3))
    P = np.ascontiguousarray(nb.packed)
    m_small = max(n // 10, 1)  # the per-channel path is slow: time a tenth, scale

    def per_channel():
        eval_pairs_checked(nb.kernel, wi[:m_small], wo[:m_small], P, out[:m_small])

    t = timed(per_channel, args.repeats) * (n / m_small)
    rows.append(("NBRDF per-channel kernel (net x3)", t, n / t / 1e6, 3 * n / t / 1e6,
                 f"timed on {m_small} pairs"))
    for rep in ("npf", "abc", "sgd"):
        m = material(f"merl:nickel@{rep}")
        rate(f"{rep.upper()} merl:nickel@{rep}", lambda m=m: m.eval(wi, wo))

    with tempfile.TemporaryDirectory() as tmp:
        path = os.path.join(tmp, "nickel.binary")
        t_export = timed(lambda: write_binary(path, table_from_function(nb.eval)), 3)
        t_read = timed(lambda: read_binary(path), args.repeats)
        table = read_binary(path)
    near = MeasuredBRDF(table)
    lin = near.with_params(lookup="linear")
    values = np.where(table.valid, table.values, 0.0).reshape(3, -1)
    t_near = rate("MeasuredBRDF nearest", lambda: near.eval(wi, wo))
    t_lin = rate("MeasuredBRDF linear", lambda: lin.eval(wi, wo))
    m_np = max(n // 5, 1)
    t_np = timed(lambda: numpy_nearest(values, wi[:m_np], wo[:m_np]), args.repeats) * (n / m_np)
    rows.append(("NumPy nearest (same lookup)", t_np, n / t_np / 1e6, 3 * n / t_np / 1e6,
                 f"timed on {m_np} pairs"))
    ok = np.allclose(numpy_nearest(values, wi[:100000], wo[:100000]),
                     np.nan_to_num(near.eval(wi[:100000], wo[:100000])), rtol=0, atol=0)

    print(f"\n{n:,} random pairs, median of {args.repeats}; M pairs/s (3 channels each)")
    print(f"{'what':38s} {'time s':>9s} {'M pairs/s':>10s} {'M ch-evals/s':>13s}  note")
    for label, t, r, rc, note in rows:
        print(f"{label:38s} {t:9.3f} {r:10.1f} {rc:13.1f}  {note}")
    print(f"\nnearest vs NumPy: {t_np / t_near:.1f}x, linear vs NumPy nearest: "
          f"{t_np / t_lin:.1f}x (targets >= 5x; >= 50 M evals/s); NumPy == compiled: {ok}")
    print(f"read_binary 35 MB: {t_read:.3f} s (target <= 0.15 s)")
    print(f"export NBRDF onto the MERL grid (table_from_function + write_binary): "
          f"{t_export:.3f} s (target <= 1 s)")
    print(f"load average after: {os.getloadavg()}")


if __name__ == "__main__":
    main()
