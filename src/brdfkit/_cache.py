"""
One cache policy: bounded, registered, clearable
================================================

Every in-process cache of brdfkit (a memo of a pure function, a table built
once, a compiled kernel per key) is made here, by :func:`memo` (a decorator)
or :func:`bounded_cache` (a dict-like object), and follows one policy:

- **key**: the value that determines the cached result, hashable. For
  :func:`memo`, the function's arguments (positional, then keyword, as
  :func:`functools.lru_cache` keys them); for :func:`bounded_cache`, what the
  caller indexes with (e.g. ``(kernel, structure)``, ``(id(table), size)``
  with the table kept in the value, or a model object when ``weak=True``).
  A cached value is never mutated by its users (arrays are read-only or
  copied on the way out), so a hit is indistinguishable from a recomputation.
- **bound**: at most ``maxsize`` entries, least recently used evicted first.
  Each use states its ``maxsize`` and, in a comment beside it, why that many
  (what one entry costs, how many a session needs). No cache is unbounded.
- **registry**: each cache registers under a unique name (default:
  ``module.qualname``) in :data:`CACHES`; per-object caches
  (``bounded_cache(None, …)``) are tracked weakly and die with their owner.
- **clearing**: :func:`clear_caches` empties every cache (all, or those whose
  name starts with a prefix); :func:`cache_info` reports sizes, bounds, hits
  and misses. Clearing only costs time: the next call recomputes. Objects
  handed out before (a material, a compiled class) stay valid; an equal
  request afterwards may give a new, equal object.
- **weak keys** (``weak=True``): the entry lives at most as long as its key
  object (the ambient tables of a model die with the model), and within the
  bound.

What is not a cache, and so not made here: registries filled once at import
(models, formulas, primitives, figures), and per-object lazily computed
attributes derived from the object's own immutable state (a model's lobe
width, a measured table's interleaved copy), which die with the object; and
:func:`source_stamp`, a constant of the process (clearing it would not cost time
but change keys).
Caches on disk (Numba's, :mod:`brdfkit.models._drivers`' generated modules, the
results of ``brdfkit reproduce``, a material's results in :mod:`brdfkit.analysis.stored`)
are a different mechanism, keyed on a stamp of the sources; brdfkit's own live under
:func:`disk_cache_dir`, and the drivers' modules and the stored results share one stamp,
:func:`source_stamp` (computed once per process: the code a process runs is the code it
imported, whatever is written to the package's files meanwhile).

Thread safety: insertions, evictions and clearing hold a lock; reads rely on
the atomicity of dict operations under the GIL (the hit and miss counters are
then approximate). A missed value is computed outside the lock (two threads
may both compute it, as with :func:`functools.lru_cache`; the last insertion
wins, both results equal).

Public objects
--------------
- :func:`memo` — decorator: a bounded, registered memo of a function.
- :func:`bounded_cache` — a bounded, registered dict-like cache.
- :class:`BoundedCache` — the cache object (``get``, ``[]``, ``del``, ``in``,
  ``len``, ``setdefault``, ``pop``, ``clear``, ``info``).
- :func:`clear_caches`, :func:`cache_info` — every cache at once.
- :data:`CACHES` — the registry: name → cache.
- :func:`disk_cache_dir` — the directory of one of brdfkit's caches on disk.
- :func:`source_stamp` — the stamp of brdfkit's sources that keys those caches.
"""

from __future__ import annotations

import functools
import hashlib
import os
import sys
import threading
import weakref
from collections import OrderedDict
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

from brdfkit.errors import ParameterError

__all__ = ["CACHES", "BoundedCache", "CacheInfo", "bounded_cache", "cache_info",
           "clear_caches", "memo", "disk_cache_dir", "source_stamp"]

#: Every named cache, by name (module-level caches: they live as long as the process).
CACHES: dict[str, BoundedCache] = {}
#: Per-object caches (no name), tracked only while their owner keeps them.
_ANONYMOUS: weakref.WeakSet = weakref.WeakSet()
_MISSING = object()
_KWMARK = object()  # separates positional from keyword arguments in a memo's key


@dataclass(frozen=True)
class CacheInfo:
    """One cache's state: ``name``, ``size`` (entries), ``maxsize``, ``hits``, ``misses``."""

    name: str
    size: int
    maxsize: int
    hits: int
    misses: int


class BoundedCache:
    """A least-recently-used mapping of at most *maxsize* entries (module docstring).

    Reading an entry (``get``, ``[]``) makes it the most recent; inserting one
    beyond the bound evicts the least recent. With ``weak=True`` the keys are
    held by weak reference and an entry goes when its key object does.
    """

    def __init__(self, name: str | None, *, maxsize: int, weak: bool = False):
        if isinstance(maxsize, bool) or not isinstance(maxsize, int) or maxsize < 1:
            raise ParameterError(f"cache {name!r}: maxsize must be an integer >= 1; got "
                                 f"{maxsize!r}")
        self.name = name or "<per-object>"
        self.maxsize = maxsize
        self.weak = weak
        self.hits = 0
        self.misses = 0
        self._data: OrderedDict = OrderedDict()
        self._lock = threading.RLock()
        self_ref = weakref.ref(self)

        def _gone(ref, self_ref=self_ref):  # a weak key died: drop its entry
            cache = self_ref()
            if cache is not None:
                with cache._lock:
                    cache._data.pop(ref, None)

        self._gone = _gone

    # ------------------------------------------------------------------ keys
    def _key(self, key, *, create: bool = False):
        if not self.weak:
            return key
        # a weak reference compares equal to another for the same live object and hashes as
        # the object: it finds the entry; only a stored key carries the callback
        return weakref.ref(key, self._gone) if create else weakref.ref(key)

    # ------------------------------------------------------------------ mapping
    def get(self, key, default=None):
        """The value for *key* (made most recent), or *default*; counts a hit or a miss."""
        # no lock on the read path: a dict read and move_to_end are atomic under the GIL, and
        # an entry evicted by another thread in between is still a valid value to return
        k = weakref.ref(key) if self.weak else key
        data = self._data
        value = data.get(k, _MISSING)
        if value is _MISSING:
            self.misses += 1
            return default
        try:
            data.move_to_end(k)
        except KeyError:
            pass
        self.hits += 1
        return value

    def __getitem__(self, key):
        k = weakref.ref(key) if self.weak else key
        data = self._data
        value = data.get(k, _MISSING)
        if value is _MISSING:
            self.misses += 1
            raise KeyError(key)
        try:
            data.move_to_end(k)
        except KeyError:  # evicted by another thread meanwhile: still a valid value
            pass
        self.hits += 1
        return value

    def __setitem__(self, key, value) -> None:
        with self._lock:
            k = self._key(key, create=True)
            self._data.pop(k, None)  # a re-inserted weak key gets a fresh callback
            self._data[k] = value
            while len(self._data) > self.maxsize:
                self._data.popitem(last=False)

    def __delitem__(self, key) -> None:
        with self._lock:
            del self._data[self._key(key)]

    def __contains__(self, key) -> bool:
        return (weakref.ref(key) if self.weak else key) in self._data

    def __len__(self) -> int:
        return len(self._data)

    def setdefault(self, key, value):
        """The value for *key*, inserting *value* first when there is none."""
        with self._lock:
            got = self.get(key, _MISSING)
            if got is _MISSING:
                self[key] = value
                return value
            return got

    def pop(self, key, default=None):
        """Remove *key*'s entry and return its value (or *default*)."""
        with self._lock:
            return self._data.pop(self._key(key), default)

    def clear(self) -> None:
        """Remove every entry (the counters stay)."""
        with self._lock:
            self._data.clear()

    def info(self) -> CacheInfo:
        """Name, size, bound, hits and misses."""
        return CacheInfo(self.name, len(self._data), self.maxsize, self.hits, self.misses)

    def __repr__(self) -> str:
        return f"BoundedCache({self.name!r}, size={len(self._data)}, maxsize={self.maxsize})"


def bounded_cache(name: str | None, *, maxsize: int, weak: bool = False) -> BoundedCache:
    """A new :class:`BoundedCache`, registered under *name* in :data:`CACHES`.

    Parameters
    ----------
    name : str or None
        Unique name (by convention ``module.variable``); None for a per-object
        cache (tracked weakly, cleared by :func:`clear_caches` while it lives).
    maxsize : int
        The bound (>= 1); state why that many beside the call.
    weak : bool
        Hold keys by weak reference (keys must be weak-referenceable objects).
    """
    cache = BoundedCache(name, maxsize=maxsize, weak=weak)
    if name is None:
        _ANONYMOUS.add(cache)
        return cache
    if name in CACHES:
        raise ParameterError(f"a cache named {name!r} is already registered")
    CACHES[name] = cache
    return cache


def memo(*, maxsize: int, name: str | None = None) -> Callable:
    """Decorator: a bounded memo of the function, registered in :data:`CACHES`.

    The key is the call's arguments (hashable); the wrapper has ``cache`` (its
    :class:`BoundedCache`) and ``cache_clear()``, like :func:`functools.lru_cache`.

    Parameters
    ----------
    maxsize : int
        At most this many results are kept (least recently used evicted).
    name : str, optional
        Registry name; default ``module.qualname`` of the function.
    """
    def decorate(fn: Callable) -> Callable:
        cache = bounded_cache(name or f"{fn.__module__}.{fn.__qualname__}", maxsize=maxsize)

        @functools.wraps(fn)
        def wrapper(*args, **kwargs):
            key = args + (_KWMARK, *sorted(kwargs.items())) if kwargs else args
            value = cache.get(key, _MISSING)
            if value is _MISSING:
                value = fn(*args, **kwargs)
                cache[key] = value
            return value

        wrapper.cache = cache
        wrapper.cache_clear = cache.clear
        return wrapper

    return decorate


def _all() -> list[BoundedCache]:
    return [*CACHES.values(), *list(_ANONYMOUS)]


def clear_caches(prefix: str = "") -> int:
    """Empty every cache whose name starts with *prefix* (all by default); returns how many
    entries were dropped. Per-object caches are named ``<per-object>``."""
    dropped = 0
    for cache in _all():
        if cache.name.startswith(prefix):
            dropped += len(cache)
            cache.clear()
    return dropped


def cache_info() -> list[CacheInfo]:
    """The state of every cache, named ones first (sorted by name)."""
    named = sorted((c.info() for c in CACHES.values()), key=lambda i: i.name)
    return named + [c.info() for c in list(_ANONYMOUS)]


def disk_cache_dir(name: str) -> Path:
    """``ROOT/name``: ROOT is ``$BRDFKIT_CACHE_DIR`` if set, else ``$XDG_CACHE_HOME/brdfkit``
    (default ``~/.cache/brdfkit``); not created here."""
    root = os.environ.get("BRDFKIT_CACHE_DIR")
    if not root:
        xdg = os.environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"), ".cache")
        root = os.path.join(xdg, "brdfkit")
    return Path(root) / name


#: Hex digits of :func:`source_stamp` kept: 64 bits, no accidental collision between two
#: versions of the sources on one machine.
STAMP_HEX = 16


def _scan_sources() -> str:
    import numba  # here, not at import: the cache policy itself needs no compiler

    package = Path(__file__).resolve().parent
    h = hashlib.sha256(f"{sys.version}|{numba.__version__}|{package}".encode())
    for path in sorted(package.rglob("*.py")):
        st = path.stat()
        h.update(f"{path.relative_to(package)}|{st.st_size}|{st.st_mtime_ns}\n".encode())
    return h.hexdigest()[:STAMP_HEX]


_STAMP: list[str] = []  # the one value of this process (a constant, not a cache: never cleared)
_STAMP_LOCK = threading.Lock()


def source_stamp() -> str:
    """Stamp of brdfkit's sources: SHA-256 of every ``.py`` file of the package (relative
    path, size, modification time), its directory and Python's and Numba's versions.

    Computed once per process, at the first call, and never recomputed: it describes the
    code this process imported, so a key made with it names the code that computed the
    result. It is not a cache (:func:`clear_caches` does not reset it), for a recomputed
    stamp would key a result of the old code by the new files (the code in memory does
    not change with them), and a result stored before the clearing would be missed by a
    read after it. A changed source changes the stamp of the next process.
    """
    if not _STAMP:
        with _STAMP_LOCK:
            if not _STAMP:
                _STAMP.append(_scan_sources())
    return _STAMP[0]
