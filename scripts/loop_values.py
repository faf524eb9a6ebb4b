"""Values of every registered model's examples on fixed pairs, to an .npz (issue 18).

Every example of every registered model (6000 random pairs with some below the horizon,
a 360x360 grid and a small serial call), each reciprocal model pumped with g = max and
controlled and pumped twice, and the surrogates of a few materials. Run it with two source
trees and compare the files with ``np.array_equal`` to show that a change to the loops
gives the same values bit for bit::

    PYTHONPATH=OLD/src python scripts/loop_values.py old.npz
    PYTHONPATH=src python scripts/loop_values.py new.npz
"""
import sys

import numpy as np

import brdfkit
from brdfkit.models import MODELS
from brdfkit.pumping import pump

rng = np.random.default_rng(1)
n = 6000
w = rng.normal(size=(2, n, 3))
w /= np.linalg.norm(w, axis=-1, keepdims=True)
w[0, : n // 2, 2] = np.abs(w[0, : n // 2, 2])
w[1, : n // 3, 2] = np.abs(w[1, : n // 3, 2])
wi, wo = np.ascontiguousarray(w[0]), np.ascontiguousarray(w[1])
g = np.linspace(0, np.pi / 2, 30)
t, p = np.meshgrid(g, np.linspace(0, 2 * np.pi, 12))
d = np.stack([np.sin(t) * np.cos(p), np.sin(t) * np.sin(p), np.cos(t)], -1).reshape(-1, 3)
wi2 = np.repeat(d, d.shape[0], 0)
wo2 = np.tile(d, (d.shape[0], 1))
small = (wi[:100], wo[:100])  # serial path
out = {}
for name, cls in MODELS.items():
    for i, ex in enumerate(cls.examples):
        m = brdfkit.model(name, **ex)
        out[f"{name}/{i}/big"] = m.eval(wi, wo)
        out[f"{name}/{i}/grid"] = m.eval(wi2, wo2)
        out[f"{name}/{i}/small"] = m.eval(*small)
        if i == 0 and m.kernel is not None and m.reciprocal:
            for gname in ("max", "controlled"):
                pm = pump(m, g=gname)
                out[f"{name}/{i}/pump-{gname}"] = pm.eval(wi, wo)
            pm2 = pump(pump(m, g="max"), g="controlled")
            out[f"{name}/{i}/pump2"] = pm2.eval(wi2, wo2)
for spec in ("merl:nickel", "merl:nickel@npf", "merl:nickel@abc", "merl:nickel@sgd",
             "rgl:acrylic_felt_white", "merl:violet-rubber@sgd"):
    m = brdfkit.model(spec)
    out[spec] = m.eval(wi, wo)
    out[spec + "/grid"] = m.eval(wi2, wo2)
np.savez(sys.argv[1], **out)
print(len(out), "arrays")
