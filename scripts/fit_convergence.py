"""Convergence matrix of the fitting procedure: models × hard MERL materials, L1 and status.

    PYTHONPATH=src python scripts/fit_convergence.py [--procedure auto] [--models …]
        [--materials …] [--seed 0]

A model name ending in ``+eta`` is fitted with its optional index of refraction η free
(started at 1.5: Fresnel on); ``microfacet-ggx`` / ``microfacet-beckmann`` choose the
distribution. Each cell: final L1, status (0 converged, 1 at a bound, 2 evaluation limit,
3 non-finite; NaN flagged), seconds. The rows with parameters at bounds are listed below the
table with the message of the fit.
"""

from __future__ import annotations

import argparse
import math
import os
import time

import brdfkit
from brdfkit.fitting import fit
from brdfkit.spec import ModelSpec

MATERIALS = ("two-layer-silver", "nickel", "violet-rubber", "red-fabric2",
             "gold-metallic-paint", "white-diffuse-bball", "black-obsidian")
MODELS = ("modified-phong", "modified-blinn-phong", "nielsen", "lafortune", "ward",
          "cook-torrance", "microfacet-ggx", "microfacet-beckmann", "nielsen+eta",
          "cook-torrance+eta", "microfacet-ggx+eta")


def build(name):
    """A model word of MODELS (``NAME[-DISTRIBUTION][+eta]``) as a spec, built."""
    words = []
    if name.endswith("+eta"):
        name, words = name[:-4], ["eta=1.5"]
    if name.startswith("microfacet-"):
        name, words = "microfacet", [f"distribution={name.split('-')[1]}", *words]
    return ModelSpec.parse(name, words).build()


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--procedure", default="auto")
    ap.add_argument("--models", default=",".join(MODELS))
    ap.add_argument("--materials", default=",".join(MATERIALS))
    ap.add_argument("--seed", type=int, default=0)
    a = ap.parse_args()
    models, mats = a.models.split(","), a.materials.split(",")
    load = os.getloadavg()
    print(f"procedure {a.procedure}, loss l1, seed {a.seed}, load average {load[0]:.1f}\n")
    print("| model | " + " | ".join(mats) + " |")
    print("|---|" + "---|" * len(mats))
    notes = []
    targets = {m: brdfkit.data.material("merl:" + m) for m in mats}
    for name in models:
        cells = []
        for mat in mats:
            t0 = time.perf_counter()
            r = fit(build(name), targets[mat], procedure=a.procedure, seed=a.seed)
            nan = not all(math.isfinite(v) for v in r.metrics.values())
            cells.append(f"{r.value:.4g} ({r.status}{', NaN' if nan else ''}, "
                         f"{time.perf_counter() - t0:.1f} s)")
            if r.status != 0:
                notes.append(f"- {name} → {mat}: {r.message}")
        print(f"| {name} | " + " | ".join(cells) + " |", flush=True)
    print()
    print("\n".join(notes))


if __name__ == "__main__":
    main()
