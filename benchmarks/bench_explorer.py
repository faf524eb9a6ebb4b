"""Explorer latency: from a slider move to every view recomputed (issues 12 §2 and 23).

    .venv/bin/python benchmarks/bench_explorer.py [--repeats 9] [--views] [--only NAME ...]

One ``POST /api/views`` round trip through the real app (FastAPI's in-process
TestClient, so the JSON encoding, the HTTP layer and the worker process are included, the
browser's drawing not), per model, for the two kinds of slider:

- a **parameter** slider (a new model: every view, including the 90-angle albedo curve
  and the θ_h × θ_d image, is recomputed), as the page asks it: ``"draft": true`` — a
  slow model's slow parts come as drafts (``brdfkit.explorer.compute``, "Drafts") — and
  then, when the answer held a draft, the same state with ``"draft": false`` (the exact
  views): the columns ``param move`` (what the page draws first: the target) and
  ``exact`` (the draft's request plus the exact one, until the page is final), with
  ``draft`` saying whether the model's moves were drafted; ``no drafts`` is the same move
  asked with ``"draft": false`` (the page before drafts: every view exact at once; the
  baseline, timed in the same run) and ``ratio`` = param move / no drafts;
- a **direction/light** slider (θ_i or Φ_L: the model-only views come from the cache).

The models: every registered model (:data:`brdfkit.models.MODELS`, its first parameter
with a number as its default is the one moved), a measured material (``merl:nickel``:
no parameters, so its "parameter move" is a new ``times`` of nothing: shown as "-") and a
pumped model (``modified-phong`` pumped ``controlled`` twice, its ``rho_s`` moved). Each
request holds one model; the table prints medians in ms and the target 100 ms. With
``--views`` the views are also timed one by one in this process (median, ms) so that the
slowest is visible.
"""

from __future__ import annotations

import argparse
import os
import statistics
import time
import warnings

from _timing import median_time
from bench_explorer_edit import _lscpu_model

from brdfkit.explorer import views
from brdfkit.explorer.compute import build_entry
from brdfkit.models import MODELS

TARGET_MS = 100.0
#: The app's time budget per request here: a first request may compile a model's loops
#: (a new source stamp: ~1 min on a loaded machine); the warm-up call absorbs it.
BUDGET_S = 600.0
#: The relative step of a moved parameter per request (a new value each time: no cache
#: answers it); tiny, so every request draws the same model within plotting accuracy.
STEP = 1e-6
#: A pumped model of the explorer ("pump" and "times" in the page).
PUMPED = {"spec": "modified-phong", "params": {}, "pump": "controlled", "times": 2}


def first_number(cls) -> str | None:
    """The first declared parameter whose default is a number (not a choice, not
    'not given', not an RGB triple)."""
    for p in cls.describe()["params"]:
        d = p.get("default")
        if isinstance(d, int | float) and not isinstance(d, bool):
            return p["name"]
    return None


def entries() -> list[tuple[str, dict, str | None]]:
    """``(label, entry, moved parameter)`` of every benchmarked model."""
    out = [(name, {"spec": name, "params": {}}, first_number(cls))
           for name, cls in MODELS.items()]
    out.append(("merl:nickel", {"spec": "merl:nickel", "params": {}}, None))
    out.append(("pumped mod.-phong", PUMPED, "rho_s"))
    return out


def _median_ms(f, repeats):
    f()  # warm-up (compilation, caches)
    return 1e3 * median_time(f, repeats)


def bench_one(client, entry, moved, n):
    """Medians (ms): a parameter move as the page draws it first and until exact (None
    without a parameter), whether it was drafted, and an angle move."""
    counter = {"k": 0}
    m = build_entry(entry)
    base = m.to_dict()["params"].get(moved) if moved else None
    first, drafted = [], []

    def post(e, theta_i, draft=True) -> bool:
        r = client.post("/api/views", json={"models": [e], "theta_i": theta_i, "phi_l": 30,
                                            "draft": draft})
        assert r.status_code == 200 and "error" not in r.json()["models"][0], r.text[:500]
        return r.json()["models"][0]["draft"]

    def param_move():  # a new parameter value each time: nothing cached
        counter["k"] += 1
        v = base * (1.0 - STEP * counter["k"]) if base else STEP * counter["k"]
        e = {**entry, "params": {**entry["params"], moved: v}}
        t0 = time.perf_counter()
        was_draft = post(e, 30)
        first.append(time.perf_counter() - t0)
        drafted.append(was_draft)
        if was_draft:  # the page asks again for the exact views
            assert post(e, 30, draft=False) is False

    def old_move():  # as the page asked before drafts: every view exact at once
        counter["k"] += 1
        v = base * (1.0 - STEP * counter["k"]) if base else STEP * counter["k"]
        post({**entry, "params": {**entry["params"], moved: v}}, 30, draft=False)

    def angle_move():
        counter["k"] += 1
        post(entry, 10 + counter["k"] % 60)

    t_old = _median_ms(old_move, n) if moved else None
    t_exact = _median_ms(param_move, n) if moved else None
    first, drafted = first[1:], drafted[1:]  # without the warm-up call
    t_first = 1e3 * statistics.median(first) if moved else None
    return (t_first, t_exact, t_old, (any(drafted) if moved else None),
            _median_ms(angle_move, n), m)


def view_parts(m, n):
    return [_median_ms(f, n) for f in (
        lambda: views.polar(m, 0.5), lambda: views.curves(m, 0.5),
        lambda: views.lobe(m, 0.5), lambda: views.sphere(m, phi_l=0.5),
        lambda: views.halfdiff(m), lambda: views.albedo_curve(m))]


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeats", type=int, default=9)
    ap.add_argument("--views", action="store_true", help="time each view too")
    ap.add_argument("--only", nargs="*", help="these models only")
    a = ap.parse_args()
    print("load average (1, 5, 15 min) before: {:.2f} {:.2f} {:.2f}".format(*os.getloadavg()))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        from fastapi.testclient import TestClient

        from brdfkit.explorer.app import create_app
    print(f"{'model':28s} {'param move':>10s} {'exact':>8s} {'draft':>5s} "
          f"{'no drafts':>9s} {'ratio':>5s} {'angle move':>10s}" +
          ("  | polar  curves  lobe  sphere  halfdiff  albedo" if a.views else "") +
          f"  (ms, median of {a.repeats})")
    worst = 0.0
    with TestClient(create_app(budget_s=BUDGET_S), base_url="http://127.0.0.1:8765") as client:
        for label, entry, moved in entries():
            if a.only and label not in a.only:
                continue
            t_param, t_exact, t_old, drafted, t_angle, m = bench_one(client, entry, moved,
                                                                     a.repeats)
            worst = max(worst, t_param or 0.0, t_angle)
            what = f"{label} ({moved})" if moved else label
            line = (f"{what:28s} {'-' if t_param is None else f'{t_param:.1f}':>10s} "
                    f"{'-' if t_exact is None else f'{t_exact:.1f}':>8s} "
                    f"{'-' if drafted is None else ('yes' if drafted else 'no'):>5s} "
                    f"{'-' if t_old is None else f'{t_old:.1f}':>9s} "
                    f"{'-' if t_old is None else f'{t_param / t_old:.2f}':>5s} "
                    f"{t_angle:10.1f}")
            if a.views:
                line += "  | " + "  ".join(f"{x:5.1f}" for x in view_parts(m, a.repeats))
            print(line, flush=True)
    print(f"\nslowest: {worst:.1f} ms (param move as first drawn, angle move); target: <= "
          f"{TARGET_MS:.0f} ms per slider move (issues 12, 23)")
    print(f"cpu: {_lscpu_model()}; load average (1, 5, 15 min) after: "
          "{:.2f} {:.2f} {:.2f}".format(*os.getloadavg()))


if __name__ == "__main__":
    main()
