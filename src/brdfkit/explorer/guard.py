"""
The explorer's boundary: who may ask, what a request may hold, which files it may open
=====================================================================================

Everything a request brings is checked here, before any model is built, so that no
request — a page on another web site, a shared link, random JSON — can freeze the server,
exhaust its memory or read a file the user did not give (issue 19).

Who may ask (:func:`refusal`)
    ``Host``: one of the names the server answers to (:func:`served_names`: the loopback
    names 127.0.0.1, localhost, ::1, and the ``--host`` address with, for a wildcard
    address, this machine's names). A DNS-rebound name (``evil.example`` resolving to
    127.0.0.1) is refused, so a page on that name cannot read the replies. Only the name
    is checked, not the port (the rebinding attack changes the name).
    Writes (every non-GET request): an ``Origin`` header, when the browser sends one (a
    browser does on every POST), must be the explorer's own page (``http://HOST:PORT``
    with HOST a served name); a body must be ``application/json``, which a cross-origin
    page can send only after a CORS preflight the server never grants. A local program
    (curl, the tests) sends no ``Origin`` and is served.

What a request may hold (:func:`read_json`, :func:`check_entry`)
    Each limit below is a named constant with its reason; the error names the limit.

Which files (:class:`FileAccess`)
    A spec naming a file (``.binary``, ``.brdf``, ``.py[:NAME]``) is opened only when the
    user gave it: on the command line, typed into the page's "open file" box, or (data
    files, not ``.py``) under a directory given with ``--allow-dir``. An error about a
    file names the file and the field, never its content.
"""

from __future__ import annotations

import json
import math
import os
import socket
import urllib.parse

from brdfkit.errors import BrdfkitError
from brdfkit.explorer import files

__all__ = ["MAX_BODY_BYTES", "MAX_MODELS", "MAX_VALUES", "MAX_PARAMS", "MAX_SPEC_CHARS",
           "MAX_CHANNELS", "LOOPBACK", "RequestError", "served_names", "refusal", "read_json",
           "check_entry", "check_beta", "too_large", "FileAccess"]

#: A request body: the largest valid state is MAX_MODELS entries of MAX_PARAMS parameters
#: of MAX_VALUES numbers of ~24 characters each (8 × 64 × 64 × 24 B ≈ 786 KB, far beyond a
#: real page's few KB); the bytes are read at most once, so this bounds memory, not time.
MAX_BODY_BYTES = 1 << 20
#: Models in one request: the page draws at most 8 (its palette has 8 colours).
MAX_MODELS = 8
#: Values of one parameter (channels or lobes): RGB is 3, a fitted Lafortune uses ≤ 3
#: lobes; 64 nh-power-series terms draw every view in 0.04 s (measured), while 40 000
#: took 29 s and 100 000 channel values asked for 48.8 GiB (issue 19).
MAX_VALUES = 64
#: Parameters of one model entry: the built-in models have ≤ 12, a .brdf file a few more.
MAX_PARAMS = 64
#: A spec or parameter name, in characters: a path up to Linux's PATH_MAX (4096).
MAX_SPEC_CHARS = 4096
#: Channels a model may have in the explorer: its views are grey (1) or RGB (3) images and
#: curves; other channel counts are drawn by ``brdfkit render`` to .exr/.npy.
MAX_CHANNELS = 3

#: The names of this machine's loopback interface.
LOOPBACK = ("127.0.0.1", "localhost", "::1")
_WILDCARD = ("0.0.0.0", "::", "")


class RequestError(BrdfkitError):
    """A refused request, with its HTTP status (400 bad input, 403 refused, 413 too
    large, 415 not JSON)."""

    def __init__(self, message: str, status: int = 400):
        super().__init__(message)
        self.status = status


def served_names(host: str) -> frozenset[str]:
    """The host names a request may address the server by when it listens on *host*."""
    names = set(LOOPBACK)
    h = host.strip("[]").lower()
    names.add(h)
    if h in _WILDCARD:  # every interface: this machine's names and addresses too
        for name in {socket.gethostname(), socket.getfqdn()}:
            names.add(name.lower())
            try:
                names.update(a[4][0] for a in socket.getaddrinfo(name, None))
            except OSError:
                pass
    return frozenset(n for n in names if n)


def _hostname(host_header: str) -> str:
    return (urllib.parse.urlsplit("//" + host_header).hostname or "").lower()


def refusal(*, method: str, host: str, origin: str | None, content_type: str | None,
            names: frozenset[str]) -> RequestError | None:
    """Why a request must be refused (module docstring, "Who may ask"), or None."""
    name = _hostname(host)
    if name not in names:
        return RequestError(
            f"refused: the request names the server {host!r}, which is not an address this "
            f"explorer serves ({', '.join(sorted(names))}); open the page at the address "
            "brdfkit explore printed", 403)
    if method in ("GET", "HEAD"):
        return None
    if origin is not None:
        o = urllib.parse.urlsplit(origin)
        if o.scheme not in ("http", "https") or (o.hostname or "").lower() not in names:
            return RequestError(
                f"refused: a page from {origin!r} may not change this explorer; only its own "
                "page (the address brdfkit explore printed) may", 403)
    kind = (content_type or "").split(";", 1)[0].strip().lower()
    if kind != "application/json":
        return RequestError(f"the request body must be application/json (the explorer "
                            f"state); got content type {content_type!r}", 415)
    return None


def too_large(size: int) -> RequestError:
    """The error of a request body of *size* bytes, over :data:`MAX_BODY_BYTES`."""
    return RequestError(f"the request body is {size} bytes or more; the explorer takes at most "
                        f"{MAX_BODY_BYTES} (MAX_BODY_BYTES)", 413)


def read_json(body: bytes):
    """The request's JSON (at most :data:`MAX_BODY_BYTES`), or a RequestError."""
    if len(body) > MAX_BODY_BYTES:
        raise too_large(len(body))
    try:
        return json.loads(body)
    except RecursionError:
        raise RequestError("the request body nests too deeply to be an explorer state") from None
    except (ValueError, UnicodeDecodeError) as exc:
        raise RequestError(f"the request body must be JSON (the explorer state): {exc}") from None


def _scalar_ok(v) -> bool:
    return v is None or isinstance(v, bool | str | int | float)


def check_entry(entry, *, where: str = "model") -> dict:
    """One model entry ``{"spec", "params", "pump", "times", "compensate", ...}`` within
    the explorer's bounds: a dict, its spec a string of at most MAX_SPEC_CHARS, its
    params an object of at most MAX_PARAMS names whose values are numbers, strings,
    booleans, null or flat lists of at most MAX_VALUES numbers. Returns the entry."""
    if not isinstance(entry, dict) or not isinstance(entry.get("spec"), str):
        raise RequestError(f"{where}: each model entry is an object with a 'spec' string "
                           "(a model name, material or file)")
    spec = entry["spec"]
    if len(spec) > MAX_SPEC_CHARS or not spec.strip():
        raise RequestError(f"{where}: 'spec' must be 1 to {MAX_SPEC_CHARS} characters "
                           f"(MAX_SPEC_CHARS); got {len(spec)}")
    params = entry.get("params")
    if params is None:
        params = {}
    if not isinstance(params, dict):
        raise RequestError(f"{spec[:80]}: 'params' must be an object NAME: VALUE; got "
                           f"{type(params).__name__}")
    if len(params) > MAX_PARAMS:
        raise RequestError(f"{spec[:80]}: at most {MAX_PARAMS} parameters (MAX_PARAMS); "
                           f"got {len(params)}")
    for k, v in params.items():
        if len(k) > MAX_SPEC_CHARS:
            raise RequestError(f"{spec[:80]}: a parameter name longer than {MAX_SPEC_CHARS} "
                               "characters")
        if isinstance(v, list):
            if len(v) > MAX_VALUES:
                raise RequestError(f"{spec[:80]}: parameter {k[:80]!r} has {len(v)} values; the "
                                   f"explorer takes at most {MAX_VALUES} per parameter "
                                   "(MAX_VALUES: channels or lobes)")
            if not all(isinstance(x, int | float) and not isinstance(x, bool) for x in v):
                raise RequestError(f"{spec[:80]}: parameter {k[:80]!r} must be a number or a "
                                   "list of numbers")
        elif not _scalar_ok(v):
            raise RequestError(f"{spec[:80]}: parameter {k[:80]!r} must be a number, a word or "
                               f"a list of numbers; got {type(v).__name__}")
    for key in ("pump", "compensate", "times"):
        if not _scalar_ok(entry.get(key)):
            raise RequestError(f"{spec[:80]}: {key!r} must be a word or a number; got "
                               f"{type(entry.get(key)).__name__}")
    return entry


def check_beta(spec: str, value) -> float:
    """The page's half-angle β in degrees → radians; a clear error for anything but a
    number in (0, 90)."""
    if isinstance(value, bool) or not isinstance(value, int | float | str):
        raise RequestError(f"{spec[:80]}: 'beta' (half-angle, degrees) must be one number in "
                           f"(0, 90); got {value!r}"[:300])
    try:
        b = float(value)
    except ValueError:
        raise RequestError(f"{spec[:80]}: 'beta' (half-angle, degrees) must be a number in "
                           f"(0, 90); got {value!r}"[:300]) from None
    if not (math.isfinite(b) and 0.0 < b < 90.0):
        raise RequestError(f"{spec[:80]}: 'beta' (half-angle, degrees) must lie in (0, 90); "
                           f"got {b:g}")
    return math.radians(b)


class FileAccess:
    """The files requests may open (module docstring, "Which files"): *given* — the paths
    the user named (command line, "open file"); *dirs* — ``--allow-dir`` directories,
    whose data files (not ``.py``: it runs code) any request may open."""

    def __init__(self, *, given=(), dirs=()):
        self._given = {os.path.realpath(p) for p in given}
        self.dirs = tuple(os.path.realpath(d) for d in dirs)

    @property
    def given(self) -> frozenset[str]:
        return frozenset(self._given)

    def allow(self, path: str) -> None:
        """The user typed *path* into "open file"."""
        self._given.add(os.path.realpath(path))

    def _under_dir(self, real: str) -> bool:
        return any(os.path.commonpath([real, d]) == d for d in self.dirs)

    def check(self, spec: str) -> None:
        """Refuse a spec naming a file the user did not give (a RequestError naming it)."""
        path = files.spec_file(spec)
        if path is None:
            return
        real = os.path.realpath(path)
        if real in self._given:
            return
        if files.runs_code(path):
            raise RequestError(
                f"{spec[:200]}: a Python model file runs its code, so the explorer loads it "
                "only when you name it: type its path into 'open file' (or give it to brdfkit "
                "explore); a link cannot open it", 403)
        if self._under_dir(real):
            return
        raise RequestError(
            f"{path}: the explorer opens only the files you gave it: type the path into "
            "'open file', name it on the command line, or start brdfkit explore with "
            "--allow-dir DIR for a directory of model files", 403)
