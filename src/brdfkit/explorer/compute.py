"""
What the explorer computes, in its worker process
=================================================

:class:`Session` holds one worker's models (an LRU cache keyed on the full description
and, for a file, its content hash) and its file models (:class:`~brdfkit.explorer.files.
FileModels`), and computes one model's views, verdict or MERL export. It runs in the
worker process (:mod:`brdfkit.explorer.worker`), never on the web server's event loop:
Numba's kernels hold the GIL, so a long computation there would stop every other request.
The requests reaching it were checked by :mod:`brdfkit.explorer.guard`.
"""

from __future__ import annotations

import base64
import json
import math
import tempfile
import time
from pathlib import Path

from brdfkit._cache import bounded_cache
from brdfkit._io import to_jsonable
from brdfkit.data.export import export_merl
from brdfkit.errors import BrdfkitError
from brdfkit.explorer import files, guard, views
from brdfkit.spec import ModelSpec

__all__ = ["Session", "entry_spec", "build_entry", "warm", "JSONText", "json_text",
           "PAGE_STATE", "start_payload"]

#: Models and view sets kept per session (LRU): a session flips between a few models; a
#: pumped model holds its tables (up to a few MB)
_CACHE_SIZE = 64

#: The page's first state (``defaultState()`` in static/app.js, parsed as
#: :func:`brdfkit.explorer.app.parse_state` parses it: angles in radians): the worker
#: computes its views while the page loads (:func:`start_payload`).
PAGE_STATE = {"theta_i": math.radians(30.0), "phi_i": 0.0, "phi_l": math.radians(30.0),
              "ambient": 0.0, "mode": "luminance", "cosine": False}
#: The page's first model when no spec is given (``defaultState()`` in static/app.js).
PAGE_MODEL = "modified-phong"

# Drafts (issue 23: a slider move drawn within 100 ms). A request with ``"draft": true``
# (the page's) may get a slow part of a model's views as a draft, marked ``"draft": true``
# in the model's answer; the page then asks again with ``"draft": false`` and draws the
# exact views. A part is drafted when the exact one of the same *family* (the spec, its
# operators and, for a file, its stage: a slider move changes only the parameters) took
# longer than DRAFT_ABOVE_S the last time it was computed (so a fast model is never
# drafted, and a slow one is on every move of its sliders). The parts:
#: - a pumped model: built on coarser tables (:func:`brdfkit.pumping.draft.draft_pump`,
#:   within :data:`~brdfkit.pumping.draft.DRAFT_REL_TOL` of the exact model);
#: - the albedo curve: DRAFT_ALBEDO_ANGLES angles to DRAFT_ALBEDO_TOL (the exact: 90 to
#:   :data:`~brdfkit.explorer.views.ALBEDO_TOL`);
#: - the lit sphere: DRAFT_SPHERE_SIZE pixels across (the exact: 256), the same renderer.
#: A quarter of the 100-ms budget of a slider move, which the other views (~10-30 ms), the
#: transfer and the drawing share.
DRAFT_ABOVE_S = 0.025
#: Angles of the draft albedo curve (every 10 degrees from 0 to 89.5; the cost of the
#: curve is per angle): a(θ_i) is smooth between its declared kinks, the plot joins them.
DRAFT_ALBEDO_ANGLES = 10
#: Accuracy of the draft albedo curve: a third of a pixel of the 0-1 plot, ~300 px high.
DRAFT_ALBEDO_TOL = 1e-3
#: Pixels across the draft sphere: about the 150 CSS pixels the page shows it at.
DRAFT_SPHERE_SIZE = 128
#: Families whose costs are remembered (LRU): a page shows a few models at a time.
_COSTS_SIZE = 256


def start_payload(specs=()) -> dict:
    """The "views" job of the page's first request: the *specs* given on the command line
    (each at its defaults, as the page's ``#m=SPEC,...`` link sends them) or the page's
    default model, at :data:`PAGE_STATE`. Files are left out (they load and compile
    through :mod:`brdfkit.explorer.files` when the page asks)."""
    named = [s for s in specs if isinstance(s, str) and files.spec_file(s) is None]
    entries = [{"spec": s, "params": {}, "pump": None, "times": 1}
               for s in (named or [PAGE_MODEL])]
    return {"entries": entries[:guard.MAX_MODELS], "state": {**PAGE_STATE, "models": entries}}


class JSONText(str):
    """One model's views already encoded as JSON (the worker encodes them: a string crosses
    the process boundary faster than nested lists, and the web server sends it as it is)."""


def json_text(obj) -> str:
    """*obj* as the web server sends JSON (compact, UTF-8, no NaN: a non-finite number or
    a NumPy value goes through :func:`~brdfkit._io.to_jsonable`, NaN and ±inf → null).
    The views are lists of Python floats already, so the fast path is the common one."""
    try:
        return json.dumps(obj, ensure_ascii=False, allow_nan=False, separators=(",", ":"))
    except (TypeError, ValueError):
        return json.dumps(to_jsonable(obj), ensure_ascii=False, allow_nan=False,
                          separators=(",", ":"))


def entry_spec(entry: dict) -> ModelSpec:
    """The :class:`~brdfkit.spec.ModelSpec` of one state entry ``{"spec", "params",
    "compensate", "pump", "times"}``: the spec's flat dict form with the page's
    conventions — the name under ``spec``, empty fields dropped, ``beta`` in degrees (as
    on the command line)."""
    params = page_params(entry)
    if "beta" in params:  # degrees in the UI, as on the command line
        params["beta"] = guard.check_beta(entry["spec"], params["beta"])
    return ModelSpec.from_dict({"model": entry["spec"], "params": params,
                                **{k: entry[k] for k in ("compensate", "pump", "times")
                                   if k in entry}})


def page_params(entry: dict) -> dict:
    """An entry's parameters as the page sends them, empty fields dropped."""
    guard.check_entry(entry)
    params = entry.get("params") or {}
    return {k: v for k, v in params.items() if v is not None and v != ""}


def build_entry(entry: dict):
    """A model from one state entry (:func:`entry_spec`, built)."""
    return entry_spec(entry).build()


def _b64(png: bytes) -> str:
    return "data:image/png;base64," + base64.b64encode(png).decode("ascii")


def warm(m) -> None:
    """Evaluate a just-compiled file model as the page will (the views at one direction:
    Numba compiles their loops in the compiling thread, not in the page's request)."""
    views.sphere(m, phi_l=0.5)
    views.polar(m, 0.5), views.lobe(m, 0.5), views.curves(m, 0.5), views.halfdiff(m)
    views.albedo_curve(m)


def _check_channels(m) -> None:
    n = m.n_channels or 1
    if n not in (1, guard.MAX_CHANNELS):
        raise BrdfkitError(f"{m.name}: the explorer draws grey (1) or RGB ({guard.MAX_CHANNELS})"
                           f" channels; this model has {n} (give 1 or 3 values per colour "
                           "parameter; brdfkit render draws other counts to .exr/.npy)")


class Session:
    """One worker's models (module docstring). *mark(path)*: called when a file's compiled
    model is ready (the web server raises that file's watch version)."""

    def __init__(self, *, mark=None):
        self.cache = bounded_cache(None, maxsize=_CACHE_SIZE)
        # family|part -> seconds of its last exact computation (module comment, "Drafts")
        self.costs = bounded_cache(None, maxsize=_COSTS_SIZE)
        self._digests: dict[str, str | None] = {}
        watcher = _Marks(self, mark)
        self.files = files.FileModels(warm=warm, watcher=watcher)

    def allow(self, paths) -> None:
        """The files the user named (they may run code)."""
        for p in paths:
            self.files.allow(p)

    def set_digests(self, digests: dict) -> None:
        """The content hashes the web server's watcher gave this request's files."""
        self._digests = dict(digests)

    @staticmethod
    def _key(entry: dict) -> str:
        return json.dumps({k: entry.get(k) for k in ("spec", "params", "pump", "times",
                                                     "compensate")}, sort_keys=True)

    @staticmethod
    def _family(entry: dict, info: dict | None = None) -> str:
        """The key of an entry without its parameters (module comment, "Drafts")."""
        return json.dumps({k: entry.get(k) for k in ("spec", "pump", "times", "compensate")},
                          sort_keys=True) + ("|interpreted" if (info or {}).get("compiled")
                                             is False else "")

    def _cached(self, key, make):
        got = self.cache.get(key)
        if got is None:
            got = self.cache[key] = make()
        return got

    def _slow(self, family: str, part: str) -> bool:
        """The exact *part* of this family took longer than DRAFT_ABOVE_S the last time."""
        return self.costs.get(family + "|" + part, 0.0) > DRAFT_ABOVE_S

    def _exact_or_draft(self, key: str, family: str, part: str, draft: bool, exact, rough):
        """``(value, drafted)``: the cached exact value, else the draft *rough()* when
        *draft* and this part is slow in its family, else *exact()* (timed: the family's
        cost). Drafts are cached under their own key."""
        got = self.cache.get(key)
        if got is not None:
            return got, False
        if draft and self._slow(family, part):
            return self._cached(key + "|draft", rough), True
        t0 = time.perf_counter()
        got = self.cache[key] = exact()
        self.costs[family + "|" + part] = time.perf_counter() - t0
        return got, False

    def get_built(self, entry: dict, *, draft: bool = False) -> tuple:
        """``(model, info)``: *info* empty for a model not from a file (app docstring), and
        ``{"draft": True}`` for a pumped model's draft (*draft* allowed: module comment,
        "Drafts")."""
        page_params(entry)
        path = files.spec_file(entry["spec"])
        if path is None:
            def rough():  # the same spec unpumped, then pumped on the draft's tables
                from brdfkit.pumping.draft import draft_pump

                spec = entry_spec(entry)
                *inner, last = spec.operators
                if last.kind != "pump":  # compensated after pumping: no draft of that
                    return build_entry(entry), {}
                args = last.arguments
                root = ModelSpec(spec.target, spec.params, inner).build()
                return draft_pump(root, args["g"], times=args["times"]), {"draft": True}

            (m, info), _ = self._exact_or_draft(
                self._key(entry), self._family(entry), "build",
                draft and bool(entry.get("pump")), lambda: (build_entry(entry), {}), rough)
        else:
            digest = (self._digests[path] if path in self._digests
                      else files.content_digest(path))
            stage = self.files.stage(entry["spec"], path, digest)  # a draft, then compiled
            key = self._key(entry) + "|file|" + str(digest) + "|" + stage
            m, info = self._cached(key, lambda: self.files.build(
                entry["spec"], path, digest, page_params(entry),
                lambda kept: entry_spec({**entry, "params": kept})))
        _check_channels(m)
        return m, info

    @staticmethod
    def _model_key(entry: dict, info: dict) -> str:
        """The cache key of one built model: the entry, its file's content and stage."""
        return (Session._key(entry) + "|" + info.get("digest", "")
                + ("" if info.get("compiled", True) else "|interpreted")
                + ("|draft" if info.get("draft") else ""))

    def model_only(self, entry: dict, m, info: dict, mode: str, phi_i: float,
                   draft: bool = False) -> tuple[dict, bool]:
        """Views that depend on the model alone (not on the direction or the light):
        computed once per model and channel mode, so moving θ_i, φ_i or Φ_L skips them
        (an anisotropic model's albedo curve is at φ_i: computed once per φ_i); and whether
        the albedo curve is a draft (module comment, "Drafts")."""
        phi = 0.0 if m.isotropic else phi_i
        key = self._model_key(entry, info) + "|" + mode + ("" if m.isotropic else f"|{phi!r}")

        def halfdiff():
            png_h, hd = views.halfdiff(m)
            return {"halfdiff": _b64(png_h), "halfdiff_info": hd}
        curve, drafted = self._exact_or_draft(
            key + "|albedo", self._family(entry, info), "albedo", draft,
            lambda: views.albedo_curve(m, mode=mode, phi=phi),
            lambda: views.albedo_curve(m, mode=mode, phi=phi, n=DRAFT_ALBEDO_ANGLES,
                                       tol=DRAFT_ALBEDO_TOL))
        return {"albedo": curve, **self._cached(key + "|halfdiff", halfdiff)}, drafted

    def lit_sphere(self, entry: dict, m, info: dict, s: dict, draft: bool = False) -> tuple:
        """The sphere view ``(PNG as a data URL, info, drafted)``: it depends on the model
        and the light (Φ_L, ambient) alone, so a θ_i or φ_i move takes it from the cache."""
        def make(size=256):
            png, sph = views.sphere(m, phi_l=s["phi_l"], ambient=s["ambient"], size=size)
            return _b64(png), sph
        (png, sph), drafted = self._exact_or_draft(
            self._model_key(entry, info) + f"|sphere|{float(s['phi_l'])!r}|"
            f"{float(s['ambient'])!r}", self._family(entry, info), "sphere", draft, make,
            lambda: make(DRAFT_SPHERE_SIZE))
        return png, sph, drafted

    def model_views(self, entry: dict, s: dict) -> JSONText | dict:
        """Every view of one entry for the state *s* (:func:`app.parse_state`) as JSON
        text, or ``{"spec", "error"}``."""
        try:
            draft = bool(s.get("draft", False))
            m, info = self.get_built(entry, draft=draft)
            png_s, sph, rough_sphere = self.lit_sphere(entry, m, info, s, draft)
            only, rough_albedo = self.model_only(entry, m, info, s["mode"], s["phi_i"], draft)
            drafted = bool(info.get("draft")) or rough_sphere or rough_albedo
            return JSONText(json_text({
                **to_jsonable({**info, "spec": entry.get("spec"), "name": m.name,
                               "params": m.to_dict()["params"], "draft": drafted}),
                "polar": views.polar(m, s["theta_i"], s["phi_i"], cosine=s["cosine"],
                                     mode=s["mode"]),
                "lobe": views.lobe(m, s["theta_i"], s["phi_i"]),
                "curves": views.curves(m, s["theta_i"], s["phi_i"], cosine=s["cosine"],
                                       mode=s["mode"]),
                "sphere": png_s, "sphere_info": sph,
                "reciprocal_claim": m.reciprocal, **only,
            }))
        except BrdfkitError as exc:
            return error_entry(entry, str(exc))

    def model_verdict(self, entry: dict, s: dict) -> dict:
        """The plausibility verdict of one entry (a direction move asks it again: the
        albedo engine's cache answers it in milliseconds)."""
        try:
            m, _ = self.get_built(entry)
            return to_jsonable(views.verdict(m, phi=s["phi_i"]))
        except BrdfkitError as exc:
            return {"spec": entry.get("spec") if isinstance(entry, dict) else None,
                    "error": str(exc)}

    def export_binary(self, entry: dict) -> tuple[str, bytes]:
        """``(file name, bytes)`` of one model on the MERL grid."""
        m, _ = self.get_built(entry)
        with tempfile.TemporaryDirectory() as d:
            path = Path(d) / "model.binary"
            export_merl(m, path)
            data = path.read_bytes()
        name = "".join(c if c.isalnum() or c in "-_." else "_" for c in m.name) + ".binary"
        return name, data


def error_entry(entry, message: str) -> dict:
    """A model that could not be drawn: ``{"spec", "error"}`` (and ``file``)."""
    spec = entry.get("spec") if isinstance(entry, dict) else None
    path = files.spec_file(spec) if isinstance(spec, str) and len(spec) <= 4096 else None
    return {"spec": spec, "error": message, **({"file": path} if path else {})}


class _Marks:
    """The watcher face a :class:`~brdfkit.explorer.files.FileModels` sees in a worker: the
    digests come from the web server, a compiled model is reported to it."""

    def __init__(self, session: Session, mark):
        self._session, self._mark = session, mark

    def mark(self, path: str) -> None:
        if self._mark is not None:
            self._mark(path)

