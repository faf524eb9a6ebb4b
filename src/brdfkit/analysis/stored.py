"""
Results of long analyses of a material, kept on disk
====================================================

The albedo curve of ``brdfkit check`` and the ambient table ρ(θ_V) of ``brdfkit render
sphere --ambient`` cost tens of seconds for a material (an NBRDF net is ~300 flops per
channel and value, and the verdict's tolerance needs millions of values). They depend on
nothing but the model's numbers, the request (angles, tolerance) and brdfkit's code, so
they are computed once and kept under :func:`brdfkit._cache.disk_cache_dir` ``("results")``.

- **key**: SHA-256 of the code stamp (:func:`brdfkit._cache.source_stamp`, once per
  process: every ``.py`` file of the package by path, size, mtime — a changed engine
  never reads an older result), the model's class, name,
  ``to_dict()``, symmetry flags and packed numbers (a measured table's values, a net's
  weights), and the request's numbers (arrays by their bytes).
- **what is kept**: only models that represent data (``model.provenance()`` non-empty:
  materials, measured tables) — an analytic model's results cost a fraction of a second.
- **bound**: at most :data:`MAX_ENTRIES` files; storing one more removes the oldest.
- **failures**: an unreadable or damaged entry is recomputed; an unwritable directory
  costs only the time of the next run (nothing is raised).

A result read back is bit-identical to the one stored (``.npz`` of float64/int arrays).

Public objects
--------------
- :func:`result_key` — the key of a model and a request.
- :func:`load`, :func:`store` — arrays by key.
- :func:`keeps` — whether results of this model are kept.
- :func:`stored_albedo` — the albedo engine through this store.
- :data:`MAX_ENTRIES`.
"""

from __future__ import annotations

import hashlib
import io
import os
import zipfile
from pathlib import Path

import numpy as np

from brdfkit import _io
from brdfkit._cache import disk_cache_dir, source_stamp
from brdfkit.errors import BrdfkitError

__all__ = ["result_key", "load", "store", "keeps", "stored_albedo", "MAX_ENTRIES"]

#: Most files kept: one entry is an albedo curve or an ambient table (≤ ~100 kB); 256
#: cover every material of the catalogue under a few parameter sets (≤ ~25 MB).
MAX_ENTRIES = 256


def _root() -> Path:
    return disk_cache_dir("results")


def keeps(model) -> bool:
    """Results are kept for a model representing data (``provenance()`` non-empty)."""
    return bool(model.provenance())


def result_key(kind: str, model, *request) -> str:
    """SHA-256 (32 hex digits) of the code stamp, *kind*, the model and the *request*."""
    h = hashlib.sha256(f"{source_stamp()}|{kind}|{type(model).__qualname__}|{model.name}|"
                       f"{model.to_dict()!r}|{model.isotropic}|{model.mirror_symmetric}|"
                       f"{model.reciprocal}".encode())
    h.update(np.ascontiguousarray(np.asarray(model.packed, dtype=np.float64)).tobytes())
    for part in request:
        if isinstance(part, np.ndarray):
            h.update(f"|{part.dtype}{part.shape}|".encode())
            h.update(np.ascontiguousarray(part).tobytes())
        else:
            h.update(f"|{part!r}".encode())
    return h.hexdigest()[:32]


def load(key: str) -> dict | None:
    """The arrays stored under *key*, or None (absent or damaged)."""
    path = _root() / f"{key}.npz"
    try:
        with np.load(path, allow_pickle=False) as data:
            return {name: data[name] for name in data.files}
    except (OSError, ValueError, zipfile.BadZipFile, EOFError):  # absent or damaged
        return None


def store(key: str, arrays: dict) -> None:
    """Keep *arrays* (name → ndarray or number) under *key*; drop the oldest beyond the bound."""
    root = _root()
    buf = io.BytesIO()
    np.savez(buf, **{k: np.asarray(v) for k, v in arrays.items()})
    try:
        root.mkdir(parents=True, exist_ok=True)
        _io.write_atomic(root / f"{key}.npz", lambda fh: fh.write(buf.getvalue()),
                         option="cache")
        entries = sorted(root.glob("*.npz"), key=lambda p: p.stat().st_mtime_ns)
        for old in entries[: max(0, len(entries) - MAX_ENTRIES)]:
            os.unlink(old)
    except (OSError, BrdfkitError):  # an unwritable cache costs only time on the next run
        pass


def stored_albedo(model, theta, *, phi: float = 0.0, tol: float = 1e-7):
    """:func:`~brdfkit.analysis.albedo` of *model* at *theta* (radians), from disk when
    it was computed before (:func:`keeps`), else computed (and kept)."""
    from brdfkit.analysis.albedo_engine import AlbedoResult, albedo

    if not keeps(model):
        return albedo(model, theta, phi=phi, tol=tol)
    th = np.asarray(theta, dtype=np.float64)
    key = result_key("albedo", model, th, float(phi), float(tol))
    hit = load(key)
    if hit is not None and set(hit) == {"theta", "albedo", "error", "status", "phi",
                                        "anisotropic"}:
        return AlbedoResult(theta=hit["theta"], albedo=hit["albedo"], error=hit["error"],
                            status=hit["status"], phi=hit["phi"][()],
                            anisotropic=bool(hit["anisotropic"]))
    r = albedo(model, th, phi=phi, tol=tol)
    store(key, {"theta": r.theta, "albedo": r.albedo, "error": r.error, "status": r.status,
                "phi": np.asarray(r.phi), "anisotropic": r.anisotropic})
    return r
