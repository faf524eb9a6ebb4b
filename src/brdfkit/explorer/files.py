"""
Models from files in the explorer: watched, reloaded, opened by path
====================================================================

A spec is *file-backed* when its target is a path to a file (:func:`spec_file`: the
target itself is a file, or it is ``PATH.py:NAME`` and ``PATH.py`` is one) — a MERL
``.binary`` table, a ``.brdf`` file, a Python file's model or any kind added to
:data:`brdfkit.spec.KINDS` later: nothing here names a kind.

- :class:`FileWatcher` — the files the shown models come from, polled by their
  ``(mtime_ns, size)`` stamp and, when that moves, their content hash (SHA-256): a
  ``touch`` is not a change; two writes of one size within one timestamp tick (same
  stamp) are seen when the stamp has aged past :data:`RACY_NS` (hashed once more).
  Each real change raises a version counter; the page asks
  ``GET /api/changes?since=N`` every 100 ms and redraws when the version passed N.
  Polled on request (no thread: nothing runs while no page asks, nothing to stop).
- :class:`FileModels` — builds a file-backed model keyed on the file's content
  (a changed file never returns the stale model), keeps the parameter values the new
  version still declares (the others are dropped and named), and when a new version
  fails to load keeps drawing the last good one with the error (the loader's one-line
  message, e.g. ``file:line:col`` of a ``.brdf``) beside it. A kind with a *draft*
  (:class:`~brdfkit.spec.SpecKind`: a template that compiles nothing — the ``.brdf``
  and ``.py`` kinds, whose models are then interpreted) is drawn from its draft at
  once; its real template is resolved in a background thread, one per file content,
  started once the draft's first views are out (:meth:`FileModels.start_compiles`:
  Numba's compiler holds the GIL; one at a time, and one whose file was saved again
  before its turn is skipped), and evaluated once (the *warm* hook: the views,
  so Numba compiles their loops); then the file's version is raised
  (:meth:`FileWatcher.mark`) and the page draws the compiled model, the same values.
  Compiling fails (a formula Numba cannot type): that content's error, as a broken
  edit's, and the last compiled version drawn.
- :func:`check_open` — the "open file" form's path: a file, not a directory, with a
  clear message otherwise.

Security: a ``.py`` model runs the file's code. The explorer serves 127.0.0.1; a Python
file is built only when the user named it — on the command line of ``brdfkit explore``
or typed into the page's "open file" box, whose request must come from this machine
(client address, ``Host`` and ``Origin`` all loopback: another web site open in the
browser cannot post one, a DNS-rebound name is refused). A ``.py`` spec arriving any
other way (a shared link's state) is refused with a message saying to open it first.
Data files (``.binary``, ``.brdf``) run no code; a link may name one the user gave or one
under ``--allow-dir`` (:class:`brdfkit.explorer.guard.FileAccess`).

Public objects
--------------
- :func:`spec_file`, :func:`runs_code`, :func:`check_open` — a target's file, whether
  loading it executes code, the open form's validation.
- :class:`FileWatcher`, :class:`FileModels` — the watch list, the file-model builder.
- :data:`POLL_INTERVAL_S` — how stale a poll may be reused.
"""

from __future__ import annotations

import hashlib
import os
import threading
import time

from brdfkit._cache import bounded_cache
from brdfkit.errors import BrdfkitError, DataFileError
from brdfkit.spec import KINDS, OPERATORS

__all__ = ["spec_file", "runs_code", "check_open", "content_digest", "FileWatcher", "FileModels",
           "POLL_INTERVAL_S", "MAX_WATCHED"]

#: A poll newer than this is reused: several pages polling every 100 ms stat each file
#: every 50 ms at most (a stat costs ~2 µs; a hash only runs on a stamp change).
POLL_INTERVAL_S = 0.05
#: Files watched at once: more than a page shows (8 models) across a few pages; the
#: least recently used is forgotten first (it is watched again when shown again).
MAX_WATCHED = 64
#: A file last hashed less than this after its mtime may have been written again within
#: the same timestamp tick (git's "racy" files): it is hashed once more when its stamp is
#: this old. The tick is ~4 ms on ext4; 2 s also covers filesystems with coarse (1-2 s)
#: timestamps. Once, not on every poll: hashing a 33 MB MERL table costs ~40-80 ms.
RACY_NS = 2_000_000_000
#: Suffixes whose loading executes the file (a Python model file).
CODE_SUFFIXES = (".py",)


def spec_file(target) -> str | None:
    """The absolute path of the file a spec's *target* names, or None: the target
    itself when it is a file, else for ``PATH:NAME`` (a Python file's model) ``PATH``
    when that is a ``.py`` file."""
    if not isinstance(target, str | os.PathLike):
        return None
    t = os.fspath(target).strip()
    if t and os.path.isfile(t):
        return os.path.abspath(t)
    head, sep, _ = t.rpartition(":")
    if sep and head.lower().endswith(CODE_SUFFIXES) and os.path.isfile(head):
        return os.path.abspath(head)
    return None


def runs_code(path: str) -> bool:
    """Whether loading the file at *path* executes it (a Python file)."""
    return path.lower().endswith(CODE_SUFFIXES)


def check_open(text) -> tuple[str, str]:
    """The page's "open file" input → ``(spec, absolute path)``: a leading ``~`` expanded
    (the loaders read the spec as a path), ``PATH.py:NAME`` keeps its ``:NAME``. Raises
    :class:`DataFileError` for an empty input, a directory or a path that is not a file,
    naming the path."""
    if not isinstance(text, str) or not text.strip():
        raise DataFileError("open file: type the path of a model file on this machine "
                            "(.brdf, .py or .py:NAME, or a MERL .binary)")
    spec = os.path.expanduser(text.strip())
    path = spec_file(spec)
    if path is None:
        head, sep, _ = spec.rpartition(":")
        shown = head if sep and head.lower().endswith(CODE_SUFFIXES) else spec
        if os.path.isdir(shown):
            raise DataFileError(f"open file: {shown} is a directory; give the path of a "
                                "model file in it")
        why = "is not a regular file" if os.path.exists(shown) else "no such file"
        raise DataFileError(f"open file: {shown}: {why} (paths are on the machine that runs "
                            f"brdfkit explore; relative to {os.getcwd()})")
    return spec, path


def content_digest(path: str) -> str | None:
    """SHA-256 of the file's bytes (hex), or None when it cannot be read now."""
    try:
        return _digest(path)
    except OSError:
        return None


def _digest(path: str) -> str:
    h = hashlib.sha256()
    with open(path, "rb") as f:
        for block in iter(lambda: f.read(1 << 20), b""):
            h.update(block)
    return h.hexdigest()


class FileWatcher:
    """The watch list: path → (stamp, content hash, version of its last change).

    :meth:`digest` registers a file and gives its current content hash (None when it
    cannot be read now); :meth:`poll` re-stats every watched file (reused within
    :data:`POLL_INTERVAL_S`) and returns the version; :meth:`changes` lists the files
    changed after a version. Thread-safe (one lock; hashing a 33 MB MERL table takes
    ~40 ms and happens only when its stamp moved)."""

    def __init__(self):
        self._lock = threading.Lock()
        # path -> [stamp, digest, version of its last change, when hashed (ns)]; in LRU order
        self._files: dict[str, list] = {}
        self._version = 0
        self._polled = -float("inf")

    @property
    def version(self) -> int:
        return self._version

    def _refresh(self, path: str, rec: list | None) -> list:
        now = time.time_ns()
        try:
            st = os.stat(path)
            stamp = (st.st_mtime_ns, st.st_size)
        except OSError:
            stamp = None
        if rec is not None and rec[0] == stamp:
            # racy (RACY_NS): hashed before the stamp was RACY_NS old, and it is now
            racy = stamp is not None and rec[3] < stamp[0] + RACY_NS <= now
            if not racy:
                return rec
        try:
            digest = None if stamp is None else _digest(path)
        except OSError:
            digest = None
        if rec is None:
            return [stamp, digest, self._version, now]
        if digest != rec[1]:
            self._version += 1
            return [stamp, digest, self._version, now]
        return [stamp, digest, rec[2], now]  # touched, same content: not a change

    def digest(self, path: str) -> str | None:
        """The content hash of *path* now (watching it from now on)."""
        with self._lock:
            rec = self._refresh(path, self._files.pop(path, None))
            self._files[path] = rec
            while len(self._files) > MAX_WATCHED:
                self._files.pop(next(iter(self._files)))
            return rec[1]

    def poll(self) -> int:
        """Re-stat the watched files (hash those whose stamp moved); the version."""
        with self._lock:
            now = time.monotonic()
            if now - self._polled >= POLL_INTERVAL_S:
                for path, rec in list(self._files.items()):
                    self._files[path] = self._refresh(path, rec)
                self._polled = now
            return self._version

    def mark(self, path: str) -> int:
        """Raise the version as for a change of the watched file *path* (what is built
        from its content changed: its compiled model is ready); the new version."""
        with self._lock:
            self._version += 1
            if path in self._files:
                self._files[path][2] = self._version
            return self._version

    def changes(self, since: int) -> list[str]:
        """The watched files whose content changed after version *since*."""
        with self._lock:
            return sorted(p for p, rec in self._files.items() if rec[2] > since)


def _kind(target):
    return next(k for k in KINDS if k.claims(target))


def _interpreted(template) -> bool:
    return bool(getattr(template, "interpreted", False))


def _load(load, target: str):
    """``load(target)`` (a kind's resolve or draft), or the one-line text of its error."""
    try:
        return load(target)
    except BrdfkitError as exc:
        return str(exc)
    except Exception as exc:  # noqa: BLE001 - a user's Python file may raise anything
        first = next((ln.strip() for ln in str(exc).splitlines() if ln.strip()), "")
        return f"{target}: {type(exc).__name__}: {first}"


class FileModels:
    """Builds file-backed models for one app (module docstring); *opened*: the files
    the user named on the command line (allowed to run code); *warm*: ``warm(model)``
    evaluates a just-compiled model once (the views it will draw), in the compiling
    thread; *watcher*: whose ``mark(path)`` is called when a compiled model is ready (a
    :class:`FileWatcher` of its own by default; the explorer's worker reports to the web
    server's instead).
    """

    def __init__(self, *, opened=(), warm=None, watcher=None):
        self.watcher = FileWatcher() if watcher is None else watcher
        self._warm = warm
        self._lock = threading.Lock()
        # one compile at a time (Numba's compiler lock serialises them anyway): a waiting
        # compile whose file changed meanwhile is skipped instead of holding the GIL
        self._compiling = threading.Lock()
        # (target, digest) -> (path, params) of a draft to compile; those started
        self._pending: dict = {}
        self._started: set = set()
        self.threads: list[threading.Thread] = []  # the compiling threads (tests join them)
        self._opened = {os.path.realpath(p) for p in opened}
        # (target, content hash) -> template or the error text of that content: a template
        # holds the file's whole model (a MERL table ~33 MB), a page edits a few files
        self._templates = bounded_cache(None, maxsize=8)
        # target -> (content hash, template, the entry before it when the template is a
        # draft) of its last version that loaded; one per file-backed target shown (the
        # page has at most 8)
        self._good = bounded_cache(None, maxsize=16)

    def allow(self, path: str) -> None:
        """Let the file at *path* run code (the user opened it)."""
        with self._lock:
            self._opened.add(os.path.realpath(path))

    def _check_allowed(self, target: str, path: str) -> None:
        if runs_code(path) and os.path.realpath(path) not in self._opened:
            raise BrdfkitError(
                f"{target}: a Python model file runs its code, so the explorer loads it only "
                "when you name it: type its path into 'open file' (or give it to brdfkit "
                "explore); a link cannot open it")

    def _template(self, target: str, digest: str | None):
        key = (target, digest)
        got = self._templates.get(key)
        if got is None:
            if digest is None:
                got = (f"{target}: the file cannot be read now (deleted or being written)")
            else:
                kind = _kind(target)
                got = _load(kind.draft or kind.resolve, target)
            self._templates[key] = got
        return got

    def stage(self, target: str, path: str, digest: str | None) -> str:
        """What a file content builds now — ``"compiled"``, ``"interpreted"`` (its draft,
        compiling) or ``"error"`` — loading it if needed (and allowed): a cache key's part."""
        self._check_allowed(target, path)
        got = self._template(target, digest)
        return "error" if isinstance(got, str) else (
            "interpreted" if _interpreted(got) else "compiled")

    def start_compiles(self) -> None:
        """Start compiling the drafts built since the last call (module docstring)."""
        with self._lock:
            todo = [(k, v) for k, v in self._pending.items() if k not in self._started]
            self._started.update(k for k, _ in todo)
            self._pending.clear()
        for key, (path, params) in todo:
            t = threading.Thread(target=self._compile, args=(key, path, params), daemon=True,
                                 name=f"brdfkit compile {os.path.basename(path)}")
            self.threads = [x for x in self.threads if x.is_alive()] + [t]
            t.start()

    def _compile(self, key: tuple, path: str, params: dict) -> None:
        target, digest = key
        kind = _kind(target)

        def compiled(t):
            template = kind.resolve(t)
            if self._warm is not None:
                self._warm(kind.build(template, params))
            return template

        with self._compiling:
            if content_digest(path) != digest:  # superseded: a newer save is drawn (or
                with self._lock:                # compiled) instead; shown again, it queues
                    self._started.discard(key)
                return
            got = _load(compiled, target)
        with self._lock:
            self._templates[key] = got
            good = self._good.get(target)
            if good is not None and good[0] == digest and _interpreted(good[1]):
                self._good[target] = good[2] if isinstance(got, str) else (digest, got, None)
            self._started.discard(key)
        self.watcher.mark(path)

    def build(self, target: str, path: str, digest: str | None, params: dict, spec_of) -> tuple:
        """``(model, info)`` of a file-backed target whose file at *path* has the content
        hash *digest* (:meth:`FileWatcher.digest`) with the page's *params*; *spec_of*
        (params → :class:`~brdfkit.spec.ModelSpec`) gives the operators. *info*: ``file``
        (path), ``digest`` (12 hex), ``reload_error`` (the new version's error when the
        last good one is drawn, else None), ``dropped`` (parameter names the version does
        not declare), ``decl`` (the model's description: its parameters), ``compiled``
        (False: the draft, interpreted, its compilation queued). Raises the load error
        when no version of the file has loaded yet."""
        self._check_allowed(target, path)
        template = self._template(target, digest)
        error = None
        if isinstance(template, str):
            error = template
            good = self._good.get(target)
            if good is None:
                raise BrdfkitError(error)
            digest, template, _ = good
        else:
            with self._lock:
                old = self._good.get(target)
                if old is None or old[0] != digest or old[1] is not template:
                    before = old if old is None or not _interpreted(old[1]) else old[2]
                    self._good[target] = (digest, template,
                                          before if _interpreted(template) else None)
        declared = {p.name for p in template.params}
        if getattr(template, "width_param", None):
            declared.add("beta")  # the half-angle the spec resolves into the width
        kept = {k: v for k, v in params.items() if k in declared}
        spec = spec_of(kept)
        if _interpreted(template):
            with self._lock:  # compiled once the draft's views are out (start_compiles)
                if (target, digest) not in self._started:
                    self._pending.setdefault((target, digest), (path, dict(spec.params)))
        base = _kind(target).build(template, spec.params)
        m = base
        for op in spec.operators:  # as ModelSpec.build, from the template loaded here
            m = OPERATORS[op.kind].apply(m, op.arguments)
        return m, {"file": path, "digest": (digest or "")[:12], "reload_error": error,
                   "dropped": sorted(set(params) - declared), "decl": base.describe(),
                   "compiled": not _interpreted(template)}
