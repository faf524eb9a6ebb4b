"""``brdfkit reproduce``: the three papers' figures, tables and claims into one report.

Progress on stderr: a bar with the count and an ETA, rewritten in place, when stderr is a
terminal; one line per finished item otherwise. Exit status 0 when every item was
computed, 1 when some failed (each is in the report with its error), 2 for bad input.
"""

from __future__ import annotations

import os
import sys
import time

import click

from brdfkit.cli._common import deprecated_alias
from brdfkit.cli._progress import stderr_is_interactive

__all__ = ["reproduce_cmd", "progress_printer"]

#: Exit status when the report was written but some items failed.
EXIT_ITEMS_FAILED = 1
_BAR = 28


def progress_printer(*, interactive: bool):
    """``progress(stage, done, total, label)`` writing to stderr: a bar with an ETA when
    *interactive*, else one line per step."""
    state = {"stage": None, "t0": 0.0, "start": 0, "width": 0}

    def progress(stage: str, done: int, total: int, label: str) -> None:
        now = time.perf_counter()
        if stage != state["stage"]:
            if state["width"]:
                click.echo("", err=True)
            state.update(stage=stage, t0=now, start=done, width=0)
        rate_n = done - state["start"]
        eta = ((now - state["t0"]) / rate_n * (total - done)) if rate_n > 0 else None
        eta_text = "" if eta is None or done >= total else f" ETA {eta:4.0f} s"
        if interactive:
            filled = int(_BAR * done / max(total, 1))
            text = (f"{stage}: [{'#' * filled}{'.' * (_BAR - filled)}] {done}/{total}"
                    f"{eta_text} {label}")[:110]
            click.echo("\r" + text.ljust(state["width"]), nl=False, err=True)
            state["width"] = max(state["width"], len(text))
            if done >= total:
                click.echo("", err=True)
                state["width"] = 0
        else:
            click.echo(f"{stage}: {done}/{total}{eta_text} {label}".rstrip(), err=True)

    return progress


@click.command("reproduce")
@click.option("--out", "out", default="report", show_default=True, metavar="DIR",
              help="Directory of the report: index.html, report.md, claims.json, figures/.")
@click.option("--only", type=click.Choice(["lewis", "neumann", "nielsen", "beyond"]),
              default=None, help="One paper only (beyond: the project's own extensions).")
@click.option("--full", is_flag=True, default=False,
              help="Refit all 100 MERL materials (resumable, under DIR/fitting-study) and "
                   "render at paper quality; default: the shipped study batches, previews.")
@click.option("--workers", "jobs", type=click.IntRange(min=1, max=256), default=None,
              metavar="N", help="Worker processes (default: the number of CPUs).")
@deprecated_alias("--jobs", "jobs_old", "use --workers (as fit names it)",
                  type=click.IntRange(min=1, max=256))
@click.option("--study-dir", default=None, metavar="DIR",
              help="The fitting study's batch directory (default: the shipped batches).")
@click.option("--no-cache", is_flag=True, default=False,
              help="Compute every item again (and do not store the results).")
def reproduce_cmd(out, only, full, jobs, jobs_old, study_dir, no_cache):
    """Recompute every figure, table and claim of Lewis 1993, Neumann et al. 1999 and
    Nielsen et al. 2015 into one report (open DIR/index.html).

    Results are cached by content (code and inputs), so a re-run is fast.
    """
    from brdfkit._io import check_output_path
    from brdfkit.errors import BrdfkitError
    from brdfkit.report.reproduce import reproduce

    if os.path.exists(out) and not os.path.isdir(out):
        raise BrdfkitError(f"--out must be a directory; {out!r} is a file")
    check_output_path(os.path.join(out, "index.html") if os.path.isdir(out) else out,
                      option="--out")
    if study_dir is not None and not os.path.isdir(study_dir):
        raise BrdfkitError(f"--study-dir must be a directory of fitting-study batches; "
                           f"{study_dir!r} is not a directory")
    jobs = jobs or jobs_old or max(1, os.cpu_count() or 1)
    progress = progress_printer(interactive=stderr_is_interactive())
    run = reproduce(out, only=only, full=full, jobs=jobs, study_dir=study_dir,
                    use_cache=not no_cache, progress=progress)
    index = os.path.join(out, "index.html")
    click.echo(f"{index}: {len(run.results)} items ({run.cached} from the cache, "
               f"{len(run.failed)} failed) in {run.seconds:.1f} s; open it in a browser")
    if run.failed:
        for r in run.failed:
            click.echo(f"brdfkit: failed: {r['kind']} {r['name']}: {r['error']}", err=True)
        sys.exit(EXIT_ITEMS_FAILED)
