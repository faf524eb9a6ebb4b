"""The fitting study of issue 10 §5: run (resumable) and write docs/fitting-study.md.

    PYTHONPATH=src python scripts/fit_study.py run --dir study/ [--materials merl:all]
        [--parts nielsen,neumann,anchors] [--workers 2]
        [--ngan ../shared/data/measured/merl_fits_lafortune_ngan2005.csv]
    PYTHONPATH=src python scripts/fit_study.py report --dir study/ [--out docs/fitting-study.md]
        [--figures docs/figures/study]

``run`` fits every batch of brdfkit.fitting.study (one CSV per batch under --dir, each
finished row written as it completes; re-running skips finished rows, so an
interrupted study resumes) and derives the plausibility verdict, Neumann's errors and
the lobe position of every fit. ``report`` reads the files and writes the Markdown
report and its figures. Delete --dir (or one part's folder) to remake after a change
of the fitting code.
"""

from __future__ import annotations

import argparse
import os
import sys
import time

from brdfkit.fitting.batch import expand_targets
from brdfkit.fitting.study import PARTS, run_study

#: Ngan et al.'s table (GPL, read at run time, never copied): ../shared/ beside the repository
DEFAULT_NGAN = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "shared",
                            "data", "measured", "merl_fits_lafortune_ngan2005.csv")


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    sub = ap.add_subparsers(dest="cmd", required=True)
    r = sub.add_parser("run")
    r.add_argument("--dir", required=True)
    r.add_argument("--materials", default="merl:all",
                   help="comma-separated specs, or merl:all")
    r.add_argument("--parts", default=",".join(PARTS))
    r.add_argument("--workers", type=int, default=2)
    r.add_argument("--ngan", default=os.environ.get("BRDFKIT_NGAN_CSV", DEFAULT_NGAN))
    r.add_argument("--no-derive", action="store_true")
    g = sub.add_parser("report")
    g.add_argument("--dir", required=True)
    g.add_argument("--out", default="docs/fitting-study.md")
    g.add_argument("--figures", default="docs/figures/study")
    g.add_argument("--ngan", default=os.environ.get("BRDFKIT_NGAN_CSV", DEFAULT_NGAN),
                   help="Ngan's table (only to count the anchors of the full study)")
    a = ap.parse_args(argv)
    if a.cmd == "run":
        materials = expand_targets(a.materials.split(","))
        parts = tuple(p for p in a.parts.split(",") if p)
        t0 = time.perf_counter()

        def progress(done, total, label):
            if label:
                print(f"[{time.perf_counter() - t0:7.1f} s] {done}/{total} {label}",
                      flush=True)

        reports = run_study(a.dir, materials=materials, parts=parts, workers=a.workers,
                            ngan_csv=a.ngan if "anchors" in parts else None,
                            derive=not a.no_derive, progress=progress)
        for rep in reports:
            print(f"{rep.out}: {rep.done} now, {rep.skipped} already there, {rep.failed} "
                  f"failed, of {rep.total} ({rep.seconds:.1f} s)")
        print(f"total {time.perf_counter() - t0:.1f} s")
        return 0
    from brdfkit.fitting.study import read_ngan_table
    from brdfkit.report.fit_study import write_report

    ngan = set(read_ngan_table(a.ngan)) if os.path.exists(a.ngan) else None
    print(write_report(a.dir, out=a.out, figures=a.figures, ngan_names=ngan))
    return 0


def run(argv=None) -> int:
    """main(), with brdfkit's errors (a missing Ngan table, an unknown material) as one
    line on stderr and exit status 2, as the brdfkit command prints them."""
    from brdfkit.errors import BrdfkitError

    try:
        return main(argv)
    except BrdfkitError as e:
        print(f"fit_study.py: error: {e}", file=sys.stderr)
        return 2


if __name__ == "__main__":
    sys.exit(run())
