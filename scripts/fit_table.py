"""Fit each model of issue 10 to a handful of MERL materials and print a Markdown table.

    PYTHONPATH=src python scripts/fit_table.py [--materials merl:nickel,...] [--pumped-starts 1]

Columns: material, model, l1 (the loss minimised), l2, perceptual, fitted shape
parameters, fit time (s), evaluations, status. Rows are printed as each fit finishes.
"""

from __future__ import annotations

import argparse
import time

import numpy as np

import brdfkit
from brdfkit.fitting import fit
from brdfkit.spec import ModelSpec

MATERIALS = ("merl:nickel", "merl:violet-rubber", "merl:two-layer-silver", "merl:red-fabric2",
             "merl:gold-metallic-paint")
MODELS = ("modified-phong", "modified-blinn-phong", "nielsen", "lafortune", "ward",
          "cook-torrance", "microfacet-beckmann", "microfacet-ggx", "pumped-modified-phong")


#: The table's model words → the spec of each (brdfkit.spec.ModelSpec, command-line words).
SPECS = {"pumped-modified-phong": ("modified-phong", (), "max"),
         "microfacet-beckmann": ("microfacet", ("distribution=beckmann",), None),
         "microfacet-ggx": ("microfacet", ("distribution=ggx",), None)}


def build(name):
    target, params, g = SPECS.get(name, (name, (), None))
    return ModelSpec.parse(target, params, pump=g).build()


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--materials", default=",".join(MATERIALS))
    ap.add_argument("--models", default=",".join(MODELS))
    ap.add_argument("--pumped-starts", type=int, default=1)
    ap.add_argument("--loss", default="l1")
    a = ap.parse_args()
    print("| material | model | l1 | l2 | perceptual | shape parameters | time (s) | evals | "
          "status |")
    print("|---|---|---|---|---|---|---|---|---|")
    for spec in a.materials.split(","):
        target = brdfkit.data.material(spec)
        for name in a.models.split(","):
            m = build(name)
            lobes = {p.name for p in m.params if p.kind == "lobes"}
            t0 = time.perf_counter()
            starts = a.pumped_starts if name.startswith("pumped") else 3
            r = fit(m, target, loss=a.loss, n_starts=starts)
            dt = time.perf_counter() - t0
            # scalar and per-lobe parameters (the per-channel ones are in the JSON)
            shape = {k: v for k, v in r.params.items()
                     if isinstance(v, float) or (isinstance(v, list) and k in lobes)}
            txt = ", ".join(
                f"{k}=" + ("/".join(f"{x:.4g}" for x in v) if isinstance(v, list) else f"{v:.4g}")
                for k, v in shape.items())
            ok = all(np.isfinite(v) for v in r.metrics.values())
            print(f"| {spec} | {name} | {r.metrics['l1']:.4g} | {r.metrics['l2']:.4g} | "
                  f"{r.metrics['perceptual']:.3g} | {txt} | {dt:.1f} | "
                  f"{r.convergence['evaluations']} | {r.status} {r.message}"
                  f"{'' if ok else ' NON-FINITE'} |", flush=True)


if __name__ == "__main__":
    main()
