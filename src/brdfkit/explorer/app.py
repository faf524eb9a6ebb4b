"""
The explorer's web layer (FastAPI), thin over :mod:`brdfkit.explorer.views`
============================================================================

One page (``static/index.html`` + ``static/app.js``, plain JavaScript drawing with
Plotly.js — ``plotly.min.js`` served from the installed ``plotly`` package: no CDN, the
page works offline) and a JSON API:

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
in degrees, as on the command line), "mode": "luminance"|"rgb", "cosine": bool,
"draft": bool}`` (``draft`` true: a slow part of a model's views may be a draft, and the
model's answer says ``"draft": true``; :mod:`brdfkit.explorer.compute`, "Drafts").
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

Robust under a stranger's hands (issue 19): every request passes
:mod:`brdfkit.explorer.guard` (the ``Host`` a served name, writes from the explorer's own
page only, bounded sizes, files only those the user gave), and every computation runs in
the worker process within the request's time budget (:mod:`brdfkit.explorer.worker`): the
server keeps answering while a model computes, a model over the budget comes back as
``{"spec", "error"}`` naming the budget, and Ctrl-C stops the server at once. Bad input
is a 400 with one line ``{"error"}``, never a traceback.

Why FastAPI and not Panel: a slider move must redraw every view in 100 ms, and
measured (``benchmarks/bench_explorer.py``, one analytic model) a direction move
costs ~32 ms end to end, ~10 ms of it the views and the rest JSON encoding of the
lobe and curves plus the HTTP layer; a parameter move 44–62 ms with the albedo
curve. The thinnest layer that serves JSON and a static page keeps that margin;
the page stays plain HTML/JS with no CDN (the machine is offline) that Playwright
drives directly (Panel/Bokeh render in shadow DOM). Panel itself was not
benchmarked here.
"""

import json
import math
import time
import weakref
from contextlib import asynccontextmanager
from importlib import resources

from fastapi import FastAPI, Request
from fastapi.responses import HTMLResponse, JSONResponse, Response
from starlette.concurrency import run_in_threadpool

from brdfkit._cache import bounded_cache
from brdfkit.data import material_names
from brdfkit.data.catalog import MATERIAL_SOURCES
from brdfkit.errors import BrdfkitError
from brdfkit.explorer import files, guard
from brdfkit.explorer.compute import (
    JSONText,
    build_entry,
    entry_spec,
    error_entry,
    json_text,
    start_payload,
)
from brdfkit.explorer.worker import BUDGET_S, Fits, OverBudget, Worker
from brdfkit.models import MODELS
from brdfkit.spec import MAX_TIMES

__all__ = ["create_app", "build_entry", "entry_spec", "parse_state", "plotly_js"]

#: The page's own files served under /static/ (and plotly.min.js, from the plotly package).
_STATIC = ("app.js", "plots.js", "style.css")
PLOTLY_JS = "plotly.min.js"

#: Bytes of an oversized body read (and discarded) before answering 413: a client sending
#: a little too much gets the message rather than a broken pipe; beyond this, the reply.
_DRAIN_BYTES = 64 * guard.MAX_BODY_BYTES
#: Models remembered as over the budget (a page shows 8; a few pages, a few edits).
_COSTLY_SIZE = 64


def plotly_js():
    """The Plotly.js bundle the ``plotly`` wheel ships (``plotly/package_data``), as a
    resource path; a BrdfkitError naming the package and its pip command when missing."""
    try:
        path = resources.files("plotly") / "package_data" / PLOTLY_JS
    except ModuleNotFoundError:
        path = None
    if path is None or not path.is_file():
        raise BrdfkitError("brdfkit explore draws its plots with Plotly.js from the 'plotly' "
                           "package, which is not installed: pip install plotly")
    return path


def _number(state: dict, key: str, default: float, lo: float, hi: float) -> float:
    v = state.get(key, default)
    try:
        x = float(v)
    except (TypeError, ValueError, OverflowError):
        raise guard.RequestError(f"{key} must be a number in [{lo:g}, {hi:g}]; "
                                 f"got {v!r}"[:300]) from None
    if not lo <= x <= hi:
        raise guard.RequestError(f"{key} must lie in [{lo:g}, {hi:g}]; got {x:g}")
    return x


def parse_state(state: dict) -> dict:
    """Validate a state (module docstring); angles converted to radians."""
    if not isinstance(state, dict):
        raise guard.RequestError("the request body must be a JSON object (the explorer state)")
    models = state.get("models", [])
    if not isinstance(models, list) or len(models) > guard.MAX_MODELS:
        raise guard.RequestError(f"models must be a list of at most {guard.MAX_MODELS} entries "
                                 "(MAX_MODELS)")
    mode = state.get("mode", "luminance")
    if mode not in ("luminance", "rgb"):
        raise guard.RequestError(f"mode must be 'luminance' or 'rgb'; got {mode!r}"[:300])
    return {
        "models": models,
        "theta_i": math.radians(_number(state, "theta_i", 30.0, 0.0, 89.5)),
        "phi_i": math.radians(_number(state, "phi_i", 0.0, -360.0, 360.0)),
        "phi_l": math.radians(_number(state, "phi_l", 30.0, 0.0, 180.0)),
        "ambient": _number(state, "ambient", 0.0, 0.0, 10.0),
        "mode": mode,
        "cosine": bool(state.get("cosine", False)),
        # slow parts may come as drafts, marked "draft" (compute.py, "Drafts"); the page's
        # slider moves ask so, then ask again without
        "draft": state.get("draft", False) is True,
    }


def _from_this_machine(request: Request) -> bool:
    """The request comes from this machine (its client address is loopback); the Host
    and Origin checks of every write are :func:`guard.refusal`'s."""
    return request.client is not None and request.client.host in guard.LOOPBACK


async def _body(request: Request):
    """The request's JSON body (at most MAX_BODY_BYTES kept, read in chunks), or a
    RequestError saying what was wrong with it. A larger body is read to its end (up to
    _DRAIN_BYTES, discarded) so that the client receives the 413 instead of a broken pipe."""
    chunks, size = [], 0
    async for chunk in request.stream():
        size += len(chunk)
        if size <= guard.MAX_BODY_BYTES:
            chunks.append(chunk)
        elif size > _DRAIN_BYTES:
            break
    if size > guard.MAX_BODY_BYTES:
        raise guard.too_large(size)
    return guard.read_json(b"".join(chunks))


class _Guard:
    """ASGI middleware: refuse a request whose Host or Origin is not the explorer's, or a
    write that is not JSON (:func:`guard.refusal`), before any route runs."""

    def __init__(self, app, names: frozenset[str]):
        self.app, self.names = app, names

    async def __call__(self, scope, receive, send):
        if scope["type"] == "http":
            h = {k.decode("latin-1").lower(): v.decode("latin-1") for k, v in scope["headers"]}
            bad = guard.refusal(method=scope["method"], host=h.get("host", ""),
                                origin=h.get("origin"), content_type=h.get("content-type"),
                                names=self.names)
            if bad is not None:
                await JSONResponse({"error": str(bad)}, status_code=bad.status)(
                    scope, receive, send)
                return
        await self.app(scope, receive, send)


def _views_response(out: list, version: int, t0: float) -> Response:
    """The ``/api/views`` answer: the models' views are JSON text from the worker
    (:class:`~brdfkit.explorer.compute.JSONText`), spliced in as they are (encoding them
    again costs ~10 ms per model); error entries are encoded here."""
    models = ",".join(m if isinstance(m, JSONText) else json_text(m) for m in out)
    ms = round(1e3 * (time.perf_counter() - t0), 1)
    return Response(f'{{"models":[{models}],"version":{int(version)},"ms":{ms!r}}}',
                    media_type="application/json")


def create_app(*, opened=(), allow_dirs=(), host: str = "127.0.0.1",
               budget_s: float = BUDGET_S, worker: Worker | None = None):
    """The FastAPI application (one worker process per app, started at once by the
    lifespan, or *worker*, started by :func:`brdfkit.explorer.serve.serve` before the web
    server's imports; it computes the page's first request while the page loads);
    *opened*: files the user named (the command line's specs; a Python file among them may
    run code); *allow_dirs*: directories whose data files any request may open
    (``--allow-dir``); *host*: the address served (the Host names accepted,
    :func:`guard.served_names`); *budget_s*: seconds a request may compute."""
    if not (isinstance(budget_s, int | float) and 0 < budget_s <= 86400):
        raise BrdfkitError(f"--budget must be a number of seconds in (0, 86400]; "
                           f"got {budget_s!r}")
    access = guard.FileAccess(given=[p for p in map(files.spec_file, opened) if p],
                              dirs=allow_dirs)
    watcher = files.FileWatcher()
    if worker is None:
        worker = Worker(warm=start_payload(opened))
    worker.on_mark = watcher.mark
    # models that ran over the budget on a warm worker (LRU): the same model in the next
    # request (the page's verdict, a light move) is answered at once instead of stopping
    # the worker once more; another 'times' or parameter is another model
    too_costly = bounded_cache(None, maxsize=_COSTLY_SIZE)
    fits = Fits()

    @asynccontextmanager
    async def lifespan(app):
        worker.start()  # warm while the page loads
        yield
        worker.stop()
        fits.stop()

    app = FastAPI(title="brdfkit explorer", docs_url=None, redoc_url=None,
                  openapi_url=None, lifespan=lifespan)
    app.add_middleware(_Guard, names=guard.served_names(host))
    static = resources.files("brdfkit.explorer") / "static"
    app.state.worker, app.state.access, app.state.watcher = worker, access, watcher
    # an app dropped without its lifespan's end (a test client used without `with`): its
    # processes end with it
    weakref.finalize(app, worker.stop)
    weakref.finalize(app, fits.stop)
    app.state.budget_s = budget_s

    over = (f"not done: over the explorer's time budget of {budget_s:g} s per request, "
            "stopped (a pumped model with a large 'times' takes longest: lower 'times', "
            "or start brdfkit explore with a larger --budget)")

    async def run(kind: str, payload: dict, what: str):
        """One whole job within the budget; over it, a 503 naming the budget."""
        try:
            return (await worker.run(kind, payload, deadline=time.monotonic() + budget_s,
                                     what=what))[0]
        except OverBudget as exc:
            if not exc.started:
                raise
            raise OverBudget(f"{what}: {over}", {}, started=True) from None

    def checked(entries: list) -> tuple[list, dict]:
        """The entries a request may compute, and ``{index: error entry}`` of the others."""
        ok, refused = [], {}
        for i, e in enumerate(entries):
            try:
                guard.check_entry(e)
                access.check(e["spec"])
                ok.append((i, e))
            except guard.RequestError as exc:
                refused[i] = error_entry(e, str(exc))
        return ok, refused

    def digests(entries) -> dict:
        """The content hashes of the entries' files (watched from now on)."""
        out = {}
        for _, e in entries:
            path = files.spec_file(e["spec"])
            if path is not None:
                out[path] = watcher.digest(path)
        return out

    def costly_key(entry: dict, found: dict) -> str:
        path = files.spec_file(entry["spec"])
        return json.dumps([entry.get(k) for k in ("spec", "params", "pump", "times",
                                                  "compensate")] + [found.get(path)])

    async def per_model(kind: str, s: dict) -> tuple[list, int]:
        ok, out = checked(s["models"])
        version = watcher.version
        found = await run_in_threadpool(digests, ok)
        for i, e in ok:  # known to exceed the budget: answered at once (reason: too_costly)
            if costly_key(e, found) in too_costly:
                out[i] = error_entry(e, f"{e['spec'][:200]}: {over}")
        ok = [(i, e) for i, e in ok if i not in out]
        if not ok:
            return [out[i] for i in range(len(s["models"]))], version
        payload = {"entries": [e for _, e in ok], "state": s, "given": sorted(access.given),
                   "digests": found}
        deadline = time.monotonic() + budget_s
        try:
            _, parts = await worker.run(kind, payload, deadline=deadline, what=kind,
                                        low=kind == "verdicts")
            message = over
        except OverBudget as exc:
            parts, message = exc.parts, over if exc.started else str(exc)
            slow = next((k for k in range(len(ok)) if k not in exc.parts), None)
            if exc.warm and slow is not None:  # the model computing at the deadline
                too_costly[costly_key(ok[slow][1], found)] = True
        for k, (i, e) in enumerate(ok):
            out[i] = parts[k] if k in parts else error_entry(e, f"{e['spec'][:200]}: {message}")
        return [out[i] for i in range(len(s["models"]))], version

    @app.exception_handler(BrdfkitError)
    async def _brdfkit_error(request: Request, exc: BrdfkitError):
        status = 503 if isinstance(exc, OverBudget) else getattr(exc, "status", 400)
        return JSONResponse({"error": str(exc)}, status_code=status)

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
        if name == PLOTLY_JS:  # 4.8 MB, the browser caches it (the page's files are not)
            return Response(plotly_js().read_bytes(), media_type="text/javascript",
                            headers={"Cache-Control": "max-age=86400"})
        if name not in _STATIC:
            return JSONResponse({"error": f"no such file {name[:100]!r}"}, status_code=404)
        kind = "text/javascript" if name.endswith(".js") else "text/css"
        return Response((static / name).read_text(encoding="utf-8"), media_type=kind)

    @app.get("/api/catalog")
    def catalog():
        return {"models": [cls.describe() for cls in MODELS.values()],
                "materials": material_names(representations=True), "max_times": MAX_TIMES,
                "material_sources": list(MATERIAL_SOURCES)}

    @app.post("/api/views")
    async def all_views(request: Request):
        t0 = time.perf_counter()
        s = parse_state(await _body(request))
        out, version = await per_model("views", s)
        return _views_response(out, version, t0)

    @app.post("/api/verdict")
    async def verdicts(request: Request):
        s = parse_state(await _body(request))
        out, _ = await per_model("verdicts", s)
        return {"verdicts": out}

    async def one_model(entry, what: str):
        ok, refused = checked([entry])
        if refused:
            raise guard.RequestError(f"{what}: {refused[0]['error']}")
        return ok[0][1]

    @app.post("/api/open")
    async def open_file(request: Request):
        if not _from_this_machine(request):
            return JSONResponse({"error": "open file: only the explorer's own page on this "
                                          "machine (127.0.0.1) may open a file by path"},
                                status_code=403)
        body = await _body(request)
        spec, path = files.check_open(body.get("path") if isinstance(body, dict) else None)
        access.allow(path)  # the user typed it: it may be opened (and, a .py model, run)
        return {"spec": spec, "file": path}

    @app.get("/api/changes")
    def changes(since: int = -1):
        version = watcher.poll()
        return {"version": version, "changed": watcher.changes(since)}

    @app.post("/api/export/binary")
    async def export_binary(request: Request):
        entry = await one_model(await _body(request), "export")
        name, data = await run("export", {
            "entry": entry, "given": sorted(access.given),
            "digests": await run_in_threadpool(digests, [(0, entry)])}, "export")
        return Response(data, media_type="application/octet-stream",
                        headers={"Content-Disposition": f'attachment; filename="{name}"'})

    @app.post("/api/fit")
    async def start_fit(request: Request):
        body = await _body(request)
        if (not isinstance(body, dict) or not isinstance(body.get("target"), str)
                or not isinstance(body.get("model"), dict)):
            raise guard.RequestError("fit: give {'model': {'spec': ...}, 'target': SPEC, "
                                     "'loss': ...}")
        loss = body.get("loss", "l1")
        from brdfkit.fitting import LOSSES

        if not isinstance(loss, str) or loss not in LOSSES:
            raise guard.RequestError(f"fit: loss must be one of {', '.join(LOSSES)}; "
                                     f"got {loss!r}"[:300])
        model = await one_model(body["model"], "fit")
        target = await one_model({"spec": body["target"]}, "fit target")
        given = sorted(access.given)
        # built in the worker first (within the budget): a bad spec is a 400 here
        names = await run("names", {"entries": [model, target], "given": given}, "fit")
        return {"id": fits.start(model=model, target=target, loss=loss, given=given,
                                 names=names)}

    @app.get("/api/fit/{job_id}")
    def fit_status(job_id: int):
        out = fits.status(job_id)
        if out is None:
            return JSONResponse({"error": f"no fit {job_id}"}, status_code=404)
        return out

    return app
