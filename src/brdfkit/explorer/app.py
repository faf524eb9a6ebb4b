"""
The explorer's web layer (FastAPI), thin over :mod:`brdfkit.explorer.views`
============================================================================

One page (``static/index.html`` + ``static/app.js``, plain JavaScript drawing on
canvases: no CDN, the page works offline) and a JSON API:

==========================  =================================================
``GET  /``                  the page
``GET  /api/catalog``       models (parameter declarations), materials
``POST /api/views``         every view of every model for one state
``POST /api/verdict``       plausibility verdicts (slower; fetched after)
``POST /api/export/binary`` one model on the MERL grid (a ``.binary`` file)
``POST /api/fit``           start fitting a model to a material (background)
``GET  /api/fit/{id}``      its progress (stage, evaluations, loss) and result
``POST /api/open``          ``{"path"}`` → ``{"spec"}``: a model file by path
``GET  /api/changes``       ``?since=N`` → ``{"version", "changed"}``: watched files
==========================  =================================================

A state is ``{"models": [{"spec", "params", "pump", "times", "visible"}],
"theta_i", "phi_i", "phi_l" (Φ_L of the sphere test, 0–180), "ambient" (angles
in degrees, as on the command line), "mode": "luminance"|"rgb", "cosine": bool}``.
A model that cannot be built (unknown spec, parameter out of bounds, unreadable file) comes back as
``{"spec", "error"}`` and the page shows the message; the other models are
drawn. Models are cached by their full description (a pumped model's tables
are built once) and, for a model from a file, the file's content hash.

Models from files (:mod:`brdfkit.explorer.files`): a spec whose target is a file
(``.binary``, ``.brdf``, ``.py[:NAME]``) is watched; its entry in ``/api/views`` also
has ``file``, ``digest``, ``decl`` (its parameter declarations: the page builds the
controls from them), ``dropped`` (parameters the page sent that this version of the
file does not declare; the page forgets them), ``reload_error`` (the newest
version's error while the last good version is drawn) and ``compiled`` (false: the
version's interpreted draft, drawn while its kernel compiles in the background; the
watch version moves when the compiled model is ready, ``files`` module docstring).
``version`` in the answer is the watch version before the models were built: the page
polls ``/api/changes`` with it and redraws when a file changed. ``/api/open`` takes a
request from this machine only and is the one way a Python file (which runs code) is
loaded besides the command line (``files`` module docstring, "Security").

Why FastAPI and not Panel: a slider move must redraw every view in 100 ms, and
measured (``benchmarks/bench_explorer.py``, one analytic model) a direction move
costs ~32 ms end to end, ~10 ms of it the views and the rest JSON encoding of the
lobe and curves plus the HTTP layer; a parameter move 44–62 ms with the albedo
curve. The thinnest layer that serves JSON and a static page keeps that margin;
the page stays plain HTML/JS with no CDN (the machine is offline) that Playwright
drives directly (Panel/Bokeh render in shadow DOM). Panel itself was not
benchmarked here.
"""

import base64
import itertools
import json
import math
import tempfile
import threading
import time
import urllib.parse
from importlib import resources
from pathlib import Path

from fastapi import FastAPI, Request
from fastapi.responses import HTMLResponse, JSONResponse, Response
from starlette.concurrency import run_in_threadpool

from brdfkit._cache import bounded_cache
from brdfkit._io import to_jsonable
from brdfkit.data import material_names
from brdfkit.data.catalog import MATERIAL_SOURCES
from brdfkit.data.export import export_merl
from brdfkit.errors import BrdfkitError
from brdfkit.explorer import files, views
from brdfkit.models import MODELS
from brdfkit.spec import MAX_TIMES, ModelSpec

__all__ = ["create_app", "build_entry", "entry_spec", "parse_state"]

#: Models and view sets kept per app (LRU): a session flips between a few models; a pumped
#: model holds its tables (up to a few MB)
_CACHE_SIZE = 64


def _number(state: dict, key: str, default: float, lo: float, hi: float) -> float:
    v = state.get(key, default)
    try:
        x = float(v)
    except (TypeError, ValueError):
        raise BrdfkitError(f"{key} must be a number in [{lo:g}, {hi:g}]; got {v!r}") from None
    if not lo <= x <= hi:
        raise BrdfkitError(f"{key} must lie in [{lo:g}, {hi:g}]; got {x:g}")
    return x


def parse_state(state: dict) -> dict:
    """Validate a state (module docstring); angles converted to radians."""
    if not isinstance(state, dict):
        raise BrdfkitError("the request body must be a JSON object (the explorer state)")
    models = state.get("models", [])
    if not isinstance(models, list) or len(models) > 8:
        raise BrdfkitError("models must be a list of at most 8 entries")
    mode = state.get("mode", "luminance")
    if mode not in ("luminance", "rgb"):
        raise BrdfkitError(f"mode must be 'luminance' or 'rgb'; got {mode!r}")
    return {
        "models": models,
        "theta_i": math.radians(_number(state, "theta_i", 30.0, 0.0, 89.5)),
        "phi_i": math.radians(_number(state, "phi_i", 0.0, -360.0, 360.0)),
        "phi_l": math.radians(_number(state, "phi_l", 30.0, 0.0, 180.0)),
        "ambient": _number(state, "ambient", 0.0, 0.0, 10.0),
        "mode": mode,
        "cosine": bool(state.get("cosine", False)),
    }


def entry_spec(entry: dict) -> ModelSpec:
    """The :class:`~brdfkit.spec.ModelSpec` of one state entry ``{"spec", "params",
    "compensate", "pump", "times"}``: the spec's flat dict form with the page's
    conventions — the name under ``spec``, empty fields dropped, ``beta`` in degrees (as
    on the command line)."""
    params = _page_params(entry)
    if "beta" in params:  # degrees in the UI, as on the command line
        params["beta"] = math.radians(float(params["beta"]))
    return ModelSpec.from_dict({"model": entry["spec"], "params": params,
                                **{k: entry[k] for k in ("compensate", "pump", "times")
                                   if k in entry}})


def _page_params(entry: dict) -> dict:
    """An entry's parameters as the page sends them, empty fields dropped."""
    if not isinstance(entry, dict) or not isinstance(entry.get("spec"), str):
        raise BrdfkitError("each model entry needs a 'spec' string (a model name or material)")
    params = entry.get("params") or {}
    if not isinstance(params, dict):
        raise BrdfkitError(f"{entry['spec']}: params must be an object NAME: VALUE")
    return {k: v for k, v in params.items() if v is not None and v != ""}


#: Names a request from this machine uses for the server (Host) and comes from (client).
_LOOPBACK = ("127.0.0.1", "::1", "localhost")


def _from_this_machine(request: Request) -> bool:
    """The request comes from this machine, to a loopback name, and — when a browser
    says which page sent it (``Origin``) — from the explorer's own page: another site
    open in the browser cannot post it, nor a DNS-rebound name reach it."""
    host = request.headers.get("host", "")
    hostname = urllib.parse.urlsplit("//" + host).hostname or ""
    origin = request.headers.get("origin")
    return (request.client is not None and request.client.host in _LOOPBACK
            and hostname in _LOOPBACK and origin in (None, f"http://{host}"))


def build_entry(entry: dict):
    """A model from one state entry ``{"spec", "params", "pump", "times"}``
    (:func:`entry_spec`, built)."""
    return entry_spec(entry).build()


async def _body(request: Request):
    """The request's JSON body, or a BrdfkitError saying what was wrong with it."""
    try:
        return json.loads(await request.body())
    except (ValueError, UnicodeDecodeError) as exc:
        raise BrdfkitError(f"the request body must be JSON (the explorer state): {exc}") from None


def _b64(png: bytes) -> str:
    return "data:image/png;base64," + base64.b64encode(png).decode("ascii")


def _warm(m) -> None:
    """Evaluate a just-compiled file model as the page will (the views at one direction:
    Numba compiles their loops in the compiling thread, not in the page's request)."""
    views.sphere(m, phi_l=0.5)
    views.polar(m, 0.5), views.lobe(m, 0.5), views.curves(m, 0.5), views.halfdiff(m)
    views.albedo_curve(m)


def create_app(*, opened=()):
    """The FastAPI application (one model cache per app); *opened*: files the user named
    (the command line's specs), which may run code (:mod:`brdfkit.explorer.files`)."""
    app = FastAPI(title="brdfkit explorer", docs_url=None, redoc_url=None)
    cache = bounded_cache(None, maxsize=_CACHE_SIZE)  # this app's models and views
    static = resources.files("brdfkit.explorer") / "static"
    from_files = files.FileModels(opened=[p for p in map(files.spec_file, opened) if p],
                                  warm=_warm)
    app.state.files = from_files  # the tests join its compiling threads

    def _key(entry: dict) -> str:
        return json.dumps({k: entry.get(k) for k in ("spec", "params", "pump", "times")},
                          sort_keys=True)

    def _cached(key, make):
        got = cache.get(key)
        if got is None:
            got = cache[key] = make()
        return got

    def get_built(entry: dict) -> tuple:
        """``(model, info)``: *info* empty for a model not from a file (module docstring)."""
        _page_params(entry)
        path = files.spec_file(entry["spec"])
        if path is None:
            return _cached(_key(entry), lambda: (build_entry(entry), {}))
        digest = from_files.watcher.digest(path)
        stage = from_files.stage(entry["spec"], path, digest)  # a draft, then compiled
        key = _key(entry) + "|file|" + str(digest) + "|" + stage
        return _cached(key, lambda: from_files.build(
            entry["spec"], path, digest, _page_params(entry),
            lambda kept: entry_spec({**entry, "params": kept})))

    def get_model(entry: dict):
        return get_built(entry)[0]

    def model_only(entry: dict, m, info: dict, mode: str, phi_i: float) -> dict:
        """Views that depend on the model alone (not on the direction or the light):
        computed once per model and channel mode, so moving θ_i, φ_i or Φ_L skips them
        (an anisotropic model's albedo curve is at φ_i: computed once per φ_i)."""
        phi = 0.0 if m.isotropic else phi_i

        def make():
            png_h, hd = views.halfdiff(m)
            return {"albedo": views.albedo_curve(m, mode=mode, phi=phi),
                    "halfdiff": _b64(png_h), "halfdiff_info": hd}
        return _cached(_key(entry) + "|" + info.get("digest", "") + "|views|" + mode
                       + ("" if info.get("compiled", True) else "|interpreted")
                       + ("" if m.isotropic else f"|{phi!r}"), make)

    @app.exception_handler(BrdfkitError)
    async def _brdfkit_error(request: Request, exc: BrdfkitError):
        return JSONResponse({"error": str(exc)}, status_code=400)

    @app.exception_handler(Exception)
    async def _any_error(request: Request, exc: Exception):  # never a traceback in the page
        return JSONResponse({"error": f"internal error: {type(exc).__name__}: {exc}"},
                            status_code=500)

    @app.get("/", response_class=HTMLResponse)
    def index():
        return (static / "index.html").read_text(encoding="utf-8")

    @app.get("/favicon.ico")
    def favicon():
        return Response(status_code=204)

    @app.get("/static/{name}")
    def static_file(name: str):
        if name not in ("app.js", "style.css"):
            return JSONResponse({"error": f"no such file {name!r}"}, status_code=404)
        kind = "text/javascript" if name.endswith(".js") else "text/css"
        return Response((static / name).read_text(encoding="utf-8"), media_type=kind)

    @app.get("/api/catalog")
    def catalog():
        return {"models": [cls.describe() for cls in MODELS.values()],
                "materials": material_names(representations=True), "max_times": MAX_TIMES,
                "material_sources": list(MATERIAL_SOURCES)}

    @app.post("/api/views")
    async def all_views(request: Request):
        s = parse_state(await _body(request))
        # computed in a worker thread: the event loop keeps answering /api/changes
        return await run_in_threadpool(compute_views, s)

    def compute_views(s: dict) -> dict:
        t0 = time.perf_counter()
        version = from_files.watcher.version
        out = []
        for entry in s["models"]:
            try:
                m, info = get_built(entry)
                png_s, sph = views.sphere(m, phi_l=s["phi_l"], ambient=s["ambient"])
                out.append({
                    **info,
                    "spec": entry.get("spec"), "name": m.name, "params": m.to_dict()["params"],
                    "polar": views.polar(m, s["theta_i"], s["phi_i"], cosine=s["cosine"],
                                         mode=s["mode"]),
                    "lobe": views.lobe(m, s["theta_i"], s["phi_i"]),
                    "curves": views.curves(m, s["theta_i"], s["phi_i"], cosine=s["cosine"],
                                           mode=s["mode"]),
                    "sphere": _b64(png_s), "sphere_info": sph,
                    "reciprocal_claim": m.reciprocal,
                    **model_only(entry, m, info, s["mode"], s["phi_i"]),
                })
            except BrdfkitError as exc:
                spec = entry.get("spec") if isinstance(entry, dict) else None
                path = files.spec_file(spec)
                out.append({"spec": spec, "error": str(exc),
                            **({"file": path} if path else {})})
        from_files.start_compiles()  # the drafts drawn: compile them now (files docstring)
        return to_jsonable({"models": out, "version": version,
                            "ms": round(1e3 * (time.perf_counter() - t0), 1)})

    @app.post("/api/verdict")
    async def verdicts(request: Request):
        s = parse_state(await _body(request))
        return await run_in_threadpool(compute_verdicts, s)

    def compute_verdicts(s: dict) -> dict:
        out = []
        for entry in s["models"]:
            try:
                out.append(views.verdict(get_model(entry), phi=s["phi_i"]))
            except BrdfkitError as exc:
                out.append({"spec": entry.get("spec"), "error": str(exc)})
        return to_jsonable({"verdicts": out})

    @app.post("/api/open")
    async def open_file(request: Request):
        if not _from_this_machine(request):
            return JSONResponse({"error": "open file: only the explorer's own page on this "
                                          "machine (127.0.0.1) may open a file by path"},
                                status_code=403)
        body = await _body(request)
        spec, path = files.check_open(body.get("path") if isinstance(body, dict) else None)
        from_files.allow(path)  # the user typed it: it may run (a .py model)
        return {"spec": spec, "file": path}

    @app.get("/api/changes")
    def changes(since: int = -1):
        version = from_files.watcher.poll()
        return {"version": version, "changed": from_files.watcher.changes(since)}

    @app.post("/api/export/binary")
    async def export_binary(request: Request):
        entry = await _body(request)
        m = get_model(entry)
        with tempfile.TemporaryDirectory() as d:
            path = Path(d) / "model.binary"
            export_merl(m, path)
            data = path.read_bytes()
        name = "".join(c if c.isalnum() or c in "-_." else "_" for c in m.name) + ".binary"
        return Response(data, media_type="application/octet-stream",
                        headers={"Content-Disposition": f'attachment; filename="{name}"'})

    fits: dict[int, dict] = {}
    fit_ids = itertools.count(1)

    def run_fit(job_id: int, m, target, loss: str) -> None:
        from brdfkit.fitting import fit

        job = fits[job_id]

        def progress(stage, evaluations, value):
            job.update(stage=stage, evaluations=int(evaluations), loss=float(value))

        try:
            r = fit(m, target, loss=loss, progress=progress)
            d = r.to_dict()
            job.update(state="done", params=d["params"], metrics=d["metrics"],
                       message=r.message, success=r.success)
        except BrdfkitError as exc:
            job.update(state="error", error=str(exc))
        except Exception as exc:  # noqa: BLE001 - reported in the page, never a traceback
            job.update(state="error", error=f"internal error: {type(exc).__name__}: {exc}")
        finally:
            job["seconds"] = round(time.perf_counter() - job["t0"], 2)

    @app.post("/api/fit")
    async def start_fit(request: Request):
        body = await _body(request)
        if not isinstance(body, dict) or not isinstance(body.get("target"), str):
            raise BrdfkitError("fit: give {'model': {...}, 'target': SPEC, 'loss': ...}")
        loss = body.get("loss", "l1")
        m = get_model(body.get("model"))
        # through the model cache and, for a file, its guard (a .py target runs only opened)
        target = get_model({"spec": body["target"]})
        job_id = next(fit_ids)
        fits[job_id] = {"state": "running", "stage": "starting", "evaluations": 0,
                        "t0": time.perf_counter(), "model": m.name, "target": target.name}
        threading.Thread(target=run_fit, args=(job_id, m, target, loss), daemon=True).start()
        return {"id": job_id}

    @app.get("/api/fit/{job_id}")
    def fit_status(job_id: int):
        job = fits.get(job_id)
        if job is None:
            return JSONResponse({"error": f"no fit {job_id}"}, status_code=404)
        out = {k: v for k, v in job.items() if k != "t0"}
        out.setdefault("seconds", round(time.perf_counter() - job["t0"], 2))
        return to_jsonable(out)

    return app
