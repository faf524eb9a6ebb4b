"""Fitting a one-times pumped modified Phong: the surrogate vs rebuilding the model per evaluation.

    PYTHONPATH=src python benchmarks/bench_fit_pumped.py [--repeats 3] [--baseline-repeats 1]
        [--materials merl:nickel,merl:gold-metallic-paint,merl:violet-rubber]
        [--losses l1,perceptual] [--no-baseline]

Both run ``fit(pump(modified-phong), material, loss=...)`` (g = max, the default
procedure, default samples) in this process:

- surrogate (now): the pumped model is evaluated through
  ``brdfkit.pumping.surrogate`` (basis albedo tables per shape value, linear
  parameters combined); the node-table cache is emptied before every run, so each
  run pays for its own tables as a fresh process would;
- rebuild (before): the surrogate switched off, every evaluation builds
  ``pump(root.with_params(...))`` (albedo table with the engine, lookups), as
  ``fit`` did before; without the surrogate ``fit`` also skips the full-step run
  before stage (iii) (too costly at ~0.5 s per evaluation), so this is the
  procedure before this change except for the held scale (``scale_held``).
  Times are split into model builds and evaluations.
  (On main before this change every build also compiled a new driver, 4-20 s
  each: that fit did not finish in 13 minutes; not repeated here.)

Compilation is excluded (warm-up first). Prints a table of median times, evaluations, the
final loss of each (exact model in both), and the ratio.
"""

from __future__ import annotations

import argparse
import statistics
import time
import warnings

import brdfkit
import brdfkit.fitting._problem as problem_mod
import brdfkit.fitting._run as run_mod
import brdfkit.pumping.surrogate as surrogate_mod
from brdfkit.fitting import fit
from brdfkit.fitting.samples import merl_samples
from brdfkit.pumping import pump

_SPLIT = {"build": 0.0, "eval": 0.0}


def _timed(fn, key):
    def wrapper(*a, **k):
        t = time.perf_counter()
        try:
            return fn(*a, **k)
        finally:
            _SPLIT[key] += time.perf_counter() - t
    return wrapper


def run(model, target, loss, *, fast: bool):
    """(seconds, FitResult, build seconds, eval seconds) of one fit."""
    surrogate_mod._NODE_CACHE.clear()
    saved = run_mod.surrogate
    if not fast:
        run_mod.surrogate = lambda *a, **k: None
    _SPLIT.update(build=0.0, eval=0.0)
    try:
        t = time.perf_counter()
        r = fit(model, target, loss=loss)
        return time.perf_counter() - t, r, _SPLIT["build"], _SPLIT["eval"]
    finally:
        run_mod.surrogate = saved


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--baseline-repeats", type=int, default=1)
    ap.add_argument("--materials", default="merl:nickel,merl:gold-metallic-paint,"
                                           "merl:violet-rubber")
    ap.add_argument("--losses", default="l1,perceptual")
    ap.add_argument("--no-baseline", action="store_true")
    a = ap.parse_args()
    problem_mod.Problem.build = _timed(problem_mod.Problem.build, "build")
    problem_mod.Problem.evaluate = _timed(problem_mod.Problem.evaluate, "eval")
    model = pump(brdfkit.model("modified-phong"))
    s = merl_samples()
    with warnings.catch_warnings():  # warm-up: the capped and uncapped kernels compiled
        warnings.simplefilter("ignore")
        for rd, rs in ((0.1, 0.5), (0.5, 0.9)):
            pump(brdfkit.model("modified-phong", rho_d=rd, rho_s=rs, n=30.0)).eval(s.wi, s.wo)
    fit(model, brdfkit.data.material("merl:nickel"), max_evals=10, n_starts=1)
    print(f"pump(modified-phong) (g = max, once), {len(s)} samples; surrogate: median of "
          f"{a.repeats}, rebuild: median of {a.baseline_repeats}")
    print("| material | loss | path | median time (s) | evaluations | builds (s) | "
          "evaluations (s) | final loss (exact) | tables |")
    print("|---|---|---|---|---|---|---|---|---|")
    for mat in a.materials.split(","):
        target = brdfkit.data.material(mat)
        for loss in a.losses.split(","):
            rows = {}
            for fast, reps in ((True, a.repeats), (False, 0 if a.no_baseline
                                                   else a.baseline_repeats)):
                if reps == 0:
                    continue
                runs = [run(model, target, loss, fast=fast) for _ in range(reps)]
                med = statistics.median(x[0] for x in runs)
                t, r, tb, te = runs[-1]
                sur = r.convergence.get("surrogate", {})
                rows[fast] = med
                print(f"| {mat} | {loss} | {'surrogate' if fast else 'rebuild'} | {med:.2f} | "
                      f"{r.convergence['evaluations']} | {tb:.2f} | {te:.2f} | {r.value:.6g} | "
                      f"{sur.get('tables_built', '-')} |", flush=True)
            if len(rows) == 2:
                print(f"| {mat} | {loss} | ratio rebuild/surrogate | "
                      f"{rows[False] / rows[True]:.1f}x | | | | | |", flush=True)


if __name__ == "__main__":
    main()
