"""Time of ``brdfkit figure neumann-fig8`` (issue 11 §4: ≤ 5 min at the defaults).

Runs :func:`brdfkit.figures.neumann_fig8.fig8_panels` (pumping the two Phongs, then
4 panels × 3 renders of 3 wavelengths each through Mitsuba's ``llvm_ad_rgb`` with the
bridge) and :func:`~brdfkit.figures.neumann_fig8.draw_fig8` ``--repeats`` times in one
process and prints the median of each part: the pumping, every panel, the drawing and
the whole figure, each with its ratio to the 300 s target of the whole. The first
repeat includes the one-time costs of a fresh process (Numba caches, Dr.Jit's LLVM
kernel compilation, ~20-30 s, paid by the first panel); they are part of what
``brdfkit figure`` pays, so repeat 1's whole is also printed alone.

The machine is shared: the load average is printed before and after.

Usage::

    .venv/bin/python benchmarks/bench_neumann_fig8.py                  # defaults, 1 repeat
    .venv/bin/python benchmarks/bench_neumann_fig8.py --spp 4 --size 160 --repeats 2
"""

from __future__ import annotations

import argparse
import os
import statistics
import time

#: Issue 11 §4: the figure at its default settings within 5 minutes.
TARGET_SECONDS = 300.0


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--spp", type=int, default=None, help="samples per pixel (default: "
                        "the figure's)")
    parser.add_argument("--size", type=int, default=None, help="panel width (default: the "
                        "figure's)")
    parser.add_argument("--repeats", type=int, default=1)
    args = parser.parse_args()

    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from brdfkit.figures import neumann_fig8 as fig8

    spp = args.spp or fig8.SPP
    size = args.size or fig8.SIZE
    print(f"load average before: {os.getloadavg()[0]:.2f}; spp {spp}, panel width {size}")
    rows: dict[str, list[float]] = {}
    for _ in range(args.repeats):
        t0 = time.perf_counter()
        res = fig8.fig8_panels(spp=spp, size=size, progress=False)
        t1 = time.perf_counter()
        plt.close(fig8.draw_fig8(res))
        t2 = time.perf_counter()
        rows.setdefault("pumping (2 albedo tables)", []).append(res["pump_seconds"])
        for (pumped, n), sec in res["seconds"].items():
            label = f"panel {'pumped' if pumped else 'plain'} n = {n:g} (3 renders)"
            rows.setdefault(label, []).append(sec)
        rows.setdefault("drawing", []).append(t2 - t1)
        rows.setdefault("whole figure", []).append(t2 - t0)
    print(f"load average after: {os.getloadavg()[0]:.2f}\n")
    print(f"| part | median s ({args.repeats} repeats) | ratio to {TARGET_SECONDS:g} s |")
    print("|---|---|---|")
    for label, ts in rows.items():
        med = statistics.median(ts)
        print(f"| {label} | {med:.1f} | {med / TARGET_SECONDS:.2f} |")
    print(f"\nrepeat 1 (fresh process, what `brdfkit figure` pays): whole figure "
          f"{rows['whole figure'][0]:.1f} s")

if __name__ == "__main__":
    main()
