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
==========================  =================================================

A state is ``{"models": [{"spec", "params", "pump", "times", "visible"}],
"theta_i", "phi_i", "phi_l" (Φ_L of the sphere test, 0–180), "ambient" (angles
in degrees, as on the command line), "mode": "luminance"|"rgb", "cosine": bool}``.
A model that cannot be built (unknown spec, parameter out of bounds, unreadable file) comes back as
``{"spec", "error"}`` and the page shows the message; the other models are
drawn. Models are cached by their full description (a pumped model's tables
are built once).

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
from importlib import resources
from pathlib import Path

from fastapi import FastAPI, Request
from fastapi.responses import HTMLResponse, JSONResponse, Response

from brdfkit._cache import bounded_cache
from brdfkit._io import to_jsonable
from brdfkit.data import material_names
from brdfkit.data.export import export_merl
from brdfkit.errors import BrdfkitError
from brdfkit.explorer import views
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
    "pump", "times"}``: the spec's flat dict form with the page's conventions — the
    name under ``spec``, empty fields dropped, ``beta`` in degrees (as on the command
    line)."""
    if not isinstance(entry, dict) or not isinstance(entry.get("spec"), str):
        raise BrdfkitError("each model entry needs a 'spec' string (a model name or material)")
    params = entry.get("params") or {}
    if not isinstance(params, dict):
        raise BrdfkitError(f"{entry['spec']}: params must be an object NAME: VALUE")
    params = {k: v for k, v in params.items() if v is not None and v != ""}
    if "beta" in params:  # degrees in the UI, as on the command line
        params["beta"] = math.radians(float(params["beta"]))
    return ModelSpec.from_dict({"model": entry["spec"], "params": params,
                                **{k: entry[k] for k in ("pump", "times") if k in entry}})


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


def create_app():
    """The FastAPI application (one model cache per app)."""
    app = FastAPI(title="brdfkit explorer", docs_url=None, redoc_url=None)
    cache = bounded_cache(None, maxsize=_CACHE_SIZE)  # this app's models and views
    static = resources.files("brdfkit.explorer") / "static"

    def _key(entry: dict) -> str:
        return json.dumps({k: entry.get(k) for k in ("spec", "params", "pump", "times")},
                          sort_keys=True)

    def _cached(key, make):
        got = cache.get(key)
        if got is None:
            got = cache[key] = make()
        return got

    def get_model(entry: dict):
        return _cached(_key(entry), lambda: build_entry(entry))

    def model_only(entry: dict, m, mode: str, phi_i: float) -> dict:
        """Views that depend on the model alone (not on the direction or the light):
        computed once per model and channel mode, so moving θ_i, φ_i or Φ_L skips them
        (an anisotropic model's albedo curve is at φ_i: computed once per φ_i)."""
        phi = 0.0 if m.isotropic else phi_i

        def make():
            png_h, hd = views.halfdiff(m)
            return {"albedo": views.albedo_curve(m, mode=mode, phi=phi),
                    "halfdiff": _b64(png_h), "halfdiff_info": hd}
        return _cached(_key(entry) + "|views|" + mode + ("" if m.isotropic else f"|{phi!r}"),
                       make)

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
                "materials": material_names(representations=True), "max_times": MAX_TIMES}

    @app.post("/api/views")
    async def all_views(request: Request):
        s = parse_state(await _body(request))
        t0 = time.perf_counter()
        out = []
        for entry in s["models"]:
            try:
                m = get_model(entry)
                png_s, sph = views.sphere(m, phi_l=s["phi_l"], ambient=s["ambient"])
                out.append({
                    "spec": entry.get("spec"), "name": m.name, "params": m.to_dict()["params"],
                    "polar": views.polar(m, s["theta_i"], s["phi_i"], cosine=s["cosine"],
                                         mode=s["mode"]),
                    "lobe": views.lobe(m, s["theta_i"], s["phi_i"]),
                    "curves": views.curves(m, s["theta_i"], s["phi_i"], cosine=s["cosine"],
                                           mode=s["mode"]),
                    "sphere": _b64(png_s), "sphere_info": sph,
                    "reciprocal_claim": m.reciprocal,
                    **model_only(entry, m, s["mode"], s["phi_i"]),
                })
            except BrdfkitError as exc:
                out.append({"spec": entry.get("spec"), "error": str(exc)})
        return to_jsonable({"models": out, "ms": round(1e3 * (time.perf_counter() - t0), 1)})

    @app.post("/api/verdict")
    async def verdicts(request: Request):
        s = parse_state(await _body(request))
        out = []
        for entry in s["models"]:
            try:
                out.append(views.verdict(get_model(entry), phi=s["phi_i"]))
            except BrdfkitError as exc:
                out.append({"spec": entry.get("spec"), "error": str(exc)})
        return to_jsonable({"verdicts": out})

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
        target = ModelSpec(body["target"]).build()
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
