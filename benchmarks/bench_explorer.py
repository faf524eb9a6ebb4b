"""Explorer latency: from a slider move to every view recomputed (issue 12 §2).

    .venv/bin/python benchmarks/bench_explorer.py [--repeats 9]

One ``POST /api/views`` round trip through the real app (FastAPI's in-process
TestClient, so the JSON encoding and the HTTP layer are included, the browser's drawing
not), per analytic model, for the two kinds of slider:

- a **parameter** slider (a new model: every view, including the 90-angle albedo curve
  and the θ_h × θ_d image, is recomputed);
- a **direction/light** slider (θ_i or Φ_L: the model-only views come from the cache).

Each request holds one model; the table prints medians in ms and the target 100 ms. The
views are also timed one by one (median, ms) so that the slowest is visible.
"""

from __future__ import annotations

import argparse
import warnings

from _timing import median_time

import brdfkit
from brdfkit.explorer import views

#: (model, fixed parameters, the parameter the "slider" moves, its value)
MODELS = [("lambert", {}, "rho_d", 0.5), ("modified-phong", {"n": 50}, "rho_d", 0.2),
          ("blinn", {}, "k_d", 0.5), ("nielsen", {}, "rho_d", 0.2),
          ("microfacet", {}, "alpha", 0.2), ("ward", {}, "rho_d", 0.2),
          ("cook-torrance", {}, "rho_s", 0.5)]
TARGET_MS = 100.0


def _median_ms(f, repeats):
    f()  # warm-up (compilation, caches)
    return 1e3 * median_time(f, repeats)


def bench_one(client, spec, params, moved, value, n):
    """Medians (ms): a parameter move, an angle move, and each view alone."""
    counter = {"k": 0}

    def param_move():  # a new parameter value each time: nothing cached
        counter["k"] += 1
        p = {**params, moved: value + 1e-6 * counter["k"]}
        r = client.post("/api/views", json={"models": [{"spec": spec, "params": p}],
                                            "theta_i": 30, "phi_l": 30})
        assert r.status_code == 200 and "error" not in r.json()["models"][0], r.text

    def angle_move():
        counter["k"] += 1
        r = client.post("/api/views", json={"models": [{"spec": spec, "params": params}],
                                            "theta_i": 10 + counter["k"] % 60, "phi_l": 30})
        assert r.status_code == 200, r.text

    m = brdfkit.model(spec, **params)
    parts = [_median_ms(f, n) for f in (
        lambda: views.polar(m, 0.5), lambda: views.curves(m, 0.5),
        lambda: views.lobe(m, 0.5), lambda: views.sphere(m, phi_l=0.5),
        lambda: views.halfdiff(m), lambda: views.albedo_curve(m))]
    return _median_ms(param_move, n), _median_ms(angle_move, n), parts


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeats", type=int, default=9)
    n = ap.parse_args().repeats
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        from fastapi.testclient import TestClient

        from brdfkit.explorer.app import create_app
    client = TestClient(create_app(), base_url="http://127.0.0.1:8765")
    print(f"{'model':16s} {'param move':>10s} {'angle move':>10s}  | polar  curves  lobe  "
          "sphere  halfdiff  albedo  (ms, median of", n, ")")
    for spec, params, moved, value in MODELS:
        t_param, t_angle, parts = bench_one(client, spec, params, moved, value, n)
        print(f"{spec:16s} {t_param:10.1f} {t_angle:10.1f}  | " +
              "  ".join(f"{x:5.1f}" for x in parts))
    print(f"\ntarget: <= {TARGET_MS:.0f} ms per slider move (issue 12)")


if __name__ == "__main__":
    main()
