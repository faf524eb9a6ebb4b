"""
``brdfkit reproduce``: every figure, table and claim of the three papers, into one report
========================================================================================

:func:`reproduce` computes every item of :func:`brdfkit.report.reproduce_items.items`
(figures, tables, claims), each on its own — in a process pool of *jobs* workers —, and
writes ``index.html``, ``report.md``, ``claims.json`` and ``figures/*.png`` under the output
directory (each file atomically). An item that raises is recorded as failed (its one-line
error) and the run goes on; :class:`Run` says how many failed.

**Cache by content.** An item's result is stored under the cache directory
(``$BRDFKIT_CACHE_DIR``, else ``$XDG_CACHE_HOME/brdfkit`` or ``~/.cache/brdfkit``,
sub-directory ``reproduce/``) keyed by the SHA-256 of: every file of the brdfkit package
(the code version), every file of the fitting-study directory read (the inputs), the
item and the run's settings (preview or full). A re-run with nothing changed reads every
item from there; any change of code or data recomputes every item (no guess about which
items a change touches). Failures are not cached. Each version of code and inputs has its
own directory; the :data:`KEEP_VERSIONS` most recently used are kept, older ones removed.

**--full.** Fits every MERL material again (:func:`brdfkit.fitting.study.run_study`,
*jobs* workers, resumable: the batch files are kept under ``OUT/fitting-study/`` and a
re-run continues them) and renders at paper quality, then reports as above from those
batches.

Public objects
--------------
- :func:`reproduce`, :class:`Run`, :func:`code_version`, :func:`default_study_dir`,
  :func:`cache_root`.
"""

from __future__ import annotations

import hashlib
import json
import multiprocessing
import os
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path

from brdfkit._cache import disk_cache_dir, memo
from brdfkit.errors import BrdfkitError
from brdfkit.report.claim_record import Context
from brdfkit.report.reproduce_items import PAPERS, Item, compute_item, items

__all__ = ["Run", "cache_root", "code_version", "default_study_dir", "reproduce"]

#: Expected seconds of the slow items at preview settings (measured on the 2-core machine),
#: so the pool starts them first; unlisted items count 1 s.
_COST = {"figure:neumann-fig8": 25.0, "figure:energy-reciprocity": 12.0,
         "figure:neumann-fig1": 12.0, "figure:nielsen-fig1": 10.0, "figure:lewis-fig7": 9.0,
         "claim:lewis-5-reciprocity": 7.0, "table:lewis-table2": 8.0,
         "claim:neumann-5-controlled-bound": 9.0, "figure:neumann-fig4": 6.0,
         "figure:neumann-fig3": 6.0, "claim:lewis-table2": 5.0,
         "claim:neumann-4-fig8-brighter": 15.0, "claim:neumann-3.1-super-metal": 5.0}


@dataclass
class Run:
    """The outcome of :func:`reproduce`: the results (one dict per item, in the report's
    order), the files written, and the counts."""

    out: str
    results: list[dict]
    files: list[str] = field(default_factory=list)
    seconds: float = 0.0

    @property
    def failed(self) -> list[dict]:
        return [r for r in self.results if r["status"] == "failed"]

    @property
    def cached(self) -> int:
        return sum(1 for r in self.results if r.get("cached"))


def default_study_dir() -> str:
    """The shipped batches: ``docs/fitting-study-data`` of the clone brdfkit runs from."""
    return str(Path(__file__).resolve().parents[3] / "docs" / "fitting-study-data")


def cache_root() -> Path:
    """Where results are cached (module docstring)."""
    return disk_cache_dir("reproduce")


def _hash_tree(root: Path, h) -> None:
    for path in sorted(p for p in root.rglob("*") if p.is_file()
                       and "__pycache__" not in p.parts and not p.name.startswith(".")):
        h.update(str(path.relative_to(root)).encode() + b"\0")
        h.update(path.read_bytes())


@memo(maxsize=1)  # once per process: the package does not change under a running command
def code_version() -> str:
    """SHA-256 (16 hex digits) of every file of the brdfkit package: the code version."""
    h = hashlib.sha256()
    _hash_tree(Path(__file__).resolve().parents[1], h)
    return h.hexdigest()[:16]


def _inputs_version(study_dir: str) -> str:
    h = hashlib.sha256(code_version().encode())
    if os.path.isdir(study_dir):
        _hash_tree(Path(study_dir), h)
    return h.hexdigest()


def _key(item: Item, inputs: str, full: bool) -> str:
    return hashlib.sha256(f"{inputs}|{item.key}|full={full}".encode()).hexdigest()[:24]


def _load(cache: Path, key: str) -> tuple[dict, bytes | None] | None:
    meta = cache / f"{key}.json"
    if not meta.exists():
        return None
    try:
        rec = json.loads(meta.read_text(encoding="utf-8"))
        png = (cache / f"{key}.png").read_bytes() if rec.get("png") else None
    except (OSError, ValueError):  # a damaged entry: recompute it
        return None
    return rec, png


def _store(cache: Path, key: str, rec: dict, png: bytes | None) -> None:
    from brdfkit import _io

    try:
        cache.mkdir(parents=True, exist_ok=True)
        if png is not None:
            _io.write_atomic(cache / f"{key}.png", lambda fh: fh.write(png), option="cache")
        text = json.dumps({**rec, "png": png is not None}, ensure_ascii=False)
        _io.write_atomic(cache / f"{key}.json", lambda fh: fh.write(text.encode("utf-8")),
                         option="cache")
    except (OSError, BrdfkitError):  # an unwritable cache costs only time on the next run
        pass


#: Versions (of code and inputs) whose results are kept: this one and the last few, so
#: switching between branches does not recompute, while old versions do not pile up
#: (~5 MB each, mostly figures).
KEEP_VERSIONS = 4


def _prune(current: Path) -> None:
    """Remove all but the :data:`KEEP_VERSIONS` most recently used version directories."""
    import shutil

    try:
        current.mkdir(parents=True, exist_ok=True)
        os.utime(current)  # mark as used now
        versions = sorted((p for p in current.parent.iterdir() if p.is_dir()),
                          key=lambda p: p.stat().st_mtime, reverse=True)
    except OSError:  # an unwritable cache costs only time
        return
    for old in versions[KEEP_VERSIONS:]:
        shutil.rmtree(old, ignore_errors=True)


def _work(item: Item, ctx: Context, threads: int | None) -> tuple[dict, bytes | None]:
    """Compute one item; never raises: a failure is a record with its one-line error."""
    from brdfkit._threads import numba_threads
    from brdfkit.cli._group import one_line

    t0 = time.perf_counter()
    try:
        if threads is None:
            payload, png = compute_item(item, ctx)
        else:
            with numba_threads(threads):
                payload, png = compute_item(item, ctx)
        return {"status": "ok", "payload": payload,
                "seconds": time.perf_counter() - t0}, png
    except Exception as exc:  # noqa: BLE001 - any failure of one item is reported, not fatal
        return {"status": "failed", "error": one_line(f"{type(exc).__name__}: {exc}"),
                "seconds": time.perf_counter() - t0}, None


def _work_item(args) -> tuple[Item, tuple[dict, bytes | None]]:
    """:func:`_work` of one ``(item, ctx)`` in a pool worker (one Numba thread each)."""
    it, ctx = args
    return it, _work(it, ctx, 1)


def _full_study(out: str, *, jobs: int, progress, materials=("merl:all",)) -> str:
    """Refit *materials* (every MERL material) into ``OUT/fitting-study`` (resumable);
    its path."""
    from brdfkit.fitting.batch import expand_targets
    from brdfkit.fitting.study import read_ngan_table, run_study, study_batches

    directory = os.path.join(out, "fitting-study")
    ngan = os.environ.get("BRDFKIT_NGAN_CSV") or str(
        Path(__file__).resolve().parents[4] / "shared" / "data" / "measured"
        / "merl_fits_lafortune_ngan2005.csv")
    parts = ("nielsen", "neumann") + (("anchors",) if os.path.exists(ngan) else ())
    targets = expand_targets(list(materials))
    names = read_ngan_table(ngan) if "anchors" in parts else None
    # one bar over the whole study: every batch's fits and as many derived rows
    grand = sum(2 * len(b.targets) for b in study_batches(targets, parts=parts,
                                                          ngan_names=names))
    state = {"offset": 0, "batch": 0}

    def tick(done, total, label):
        if not label:  # a batch (of fits or of derived rows) starts: nothing new to show
            state["offset"] += state["batch"]
            state["batch"] = total
            if state["offset"] + done > 0:
                return
        if progress is not None:
            progress("fitting study", min(state["offset"] + done, grand), grand, label or "")

    run_study(directory, materials=targets, parts=parts, workers=jobs,
              ngan_csv=ngan if "anchors" in parts else None, progress=tick)
    return directory


def reproduce(out, *, only: str | None = None, full: bool = False, jobs: int = 1,
              study_dir: str | None = None, use_cache: bool = True,
              progress: Callable[[str, int, int, str], None] | None = None,
              materials: tuple[str, ...] = ("merl:all",)) -> Run:
    """Compute every item and write the report under *out* (module docstring).

    Parameters (keyword-only but *out*)
    -----------------------------------
    only : {"lewis", "neumann", "nielsen", "beyond"}, optional
        One paper's items only.
    full : bool
        Refit the fitting study (every MERL material) and render at paper quality.
    jobs : int
        Worker processes (≥ 1); 1 computes in this process. The workers are *spawned*
        (no fork of Numba's threads), so a script calling this with ``jobs > 1`` needs the
        ``if __name__ == "__main__":`` guard, as any spawn-based multiprocessing does.
    study_dir : str, optional
        The fitting study's batch directory (default: the shipped batches).
    use_cache : bool
        Read and write the result cache.
    progress : callable, optional
        ``progress(stage, done, total, label)`` after each step.
    materials : tuple of str
        The materials a full run refits (default every MERL material; a subset for a quick
        look — the report then describes only those).
    """
    if only is not None and only not in PAPERS:
        raise BrdfkitError(f"only must be one of {', '.join(PAPERS)}; got {only!r}")
    if isinstance(jobs, bool) or not isinstance(jobs, int) or jobs < 1:
        raise BrdfkitError(f"jobs must be an integer >= 1 (worker processes); got {jobs!r}")
    out = os.fspath(out)
    t0 = time.perf_counter()
    try:
        os.makedirs(out, exist_ok=True)
    except OSError as exc:  # an unwritable place, a file in the way: one line, no traceback
        raise BrdfkitError(f"out {out!r}: cannot create the report's directory "
                           f"({exc.strerror or exc}); choose a writable directory") from None
    if full and study_dir is None:
        study_dir = _full_study(out, jobs=jobs, progress=progress, materials=materials)
    ctx = Context(study_dir=study_dir or default_study_dir(), full=full)
    todo = items(only=only)
    inputs = _inputs_version(ctx.study_dir)
    cache = cache_root() / inputs[:16]  # one directory per code and input version
    if use_cache:
        _prune(cache)
    results: dict[str, dict] = {}
    pngs: dict[str, bytes] = {}
    pending = []
    for it in todo:
        hit = _load(cache, _key(it, inputs, full)) if use_cache else None
        if hit is None:
            pending.append(it)
        else:
            results[it.key] = {**hit[0], "cached": True}
            if hit[1] is not None:
                pngs[it.key] = hit[1]
    done = len(results)
    if progress is not None:
        progress("items", done, len(todo), f"{done} from the cache")
    pending.sort(key=lambda it: -_COST.get(it.key, 1.0))

    def finish(it: Item, rec: dict, png: bytes | None) -> None:
        nonlocal done
        results[it.key] = rec
        if png is not None:
            pngs[it.key] = png
        if rec["status"] == "ok" and use_cache:
            _store(cache, _key(it, inputs, full), rec, png)
        done += 1
        if progress is not None:
            progress("items", done, len(todo), it.key
                     + (" FAILED" if rec["status"] == "failed" else ""))

    if jobs == 1 or len(pending) <= 1:
        for it in pending:
            finish(it, *_work(it, ctx, None))
    else:
        spawn = multiprocessing.get_context("spawn")  # no fork of Numba's threads
        # leaving the block terminates the workers: on Ctrl-C or SIGTERM (SystemExit) at
        # once, nothing more is computed; what finished is cached, so a re-run resumes
        with spawn.Pool(processes=min(jobs, len(pending))) as pool:
            for it, (rec, png) in pool.imap_unordered(_work_item, [(it, ctx) for it in pending]):
                finish(it, rec, png)
            pool.close()  # done: let the workers exit normally (their finalizers run)
            pool.join()
    ordered = [{"kind": it.kind, "name": it.name, "paper": it.paper, "section": it.section,
                "title": it.title, **results[it.key]} for it in todo]
    run = Run(out=out, results=ordered)
    from brdfkit.report.reproduce_write import write_report

    run.seconds = time.perf_counter() - t0
    run.files = write_report(run, pngs={f"{r['kind']}:{r['name']}": pngs.get(
        f"{r['kind']}:{r['name']}") for r in ordered}, ctx=ctx, only=only)
    return run
