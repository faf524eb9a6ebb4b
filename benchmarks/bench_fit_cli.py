"""One-line fit from a fresh process: ``brdfkit fit nielsen --to merl:nickel --json`` (issue 10).

    .venv/bin/python benchmarks/bench_fit_cli.py [--repeats 7] [--material merl:nickel]

Runs the installed ``brdfkit`` console script (next to this interpreter) in a new process
each time and prints the wall time of each part of the target: the first run (which loads
or, on a fresh clone, compiles and stores Numba's caches and the generated evaluation
loops), then the median, minimum and maximum of the following runs against the 2 s
target, and the same for ``python -c "import brdfkit.cli"`` (interpreter start and
imports), so that the fit's own share can be read off. The JSON printed by the command is
checked to hold the parameters and every metric.
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import time
from pathlib import Path

TARGET_S = 2.0


def _wall(cmd) -> tuple[float, str]:
    t = time.perf_counter()
    out = subprocess.run(cmd, capture_output=True, text=True, check=True)
    return time.perf_counter() - t, out.stdout


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--repeats", type=int, default=7)
    ap.add_argument("--material", default="merl:nickel")
    a = ap.parse_args()
    script = Path(sys.executable).with_name("brdfkit")
    if not script.exists():
        sys.exit(f"bench_fit_cli: no console script at {script}: install the package "
                 "(bash scripts/setup.sh --dev)")
    cmd = [str(script), "fit", "nielsen", "--to", a.material, "--json"]
    first, out = _wall(cmd)
    d = json.loads(out)
    missing = {"params", "metrics"} - set(d)
    if missing or set(d["metrics"]) != {"l1", "l2", "ngan", "log", "perceptual"}:
        sys.exit(f"bench_fit_cli: unexpected output (missing {sorted(missing)})")
    runs = [_wall(cmd)[0] for _ in range(a.repeats)]
    imports = [_wall([sys.executable, "-c", "import brdfkit.cli"])[0] for _ in range(a.repeats)]
    load = os.getloadavg()
    print(f"`{' '.join(['brdfkit', *cmd[1:]])}`, fresh process per run, {a.repeats} runs, "
          f"load average {load[0]:.1f} {load[1]:.1f} {load[2]:.1f} (2 cores)")
    print("| what | median (s) | min (s) | max (s) | median / 2 s target |")
    print("|---|---|---|---|---|")
    print(f"| first run (caches loaded or built) | {first:.2f} | | | {first / TARGET_S:.2f} |")
    for label, ts in (("fit command", runs), ("`import brdfkit.cli` alone", imports)):
        m = statistics.median(ts)
        print(f"| {label} | {m:.2f} | {min(ts):.2f} | {max(ts):.2f} | {m / TARGET_S:.2f} |")


if __name__ == "__main__":
    main()
