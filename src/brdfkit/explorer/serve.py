"""
``brdfkit explore``: serve the explorer on this machine
=======================================================

:func:`serve` runs the app (:func:`brdfkit.explorer.app.create_app`) with
uvicorn on **127.0.0.1** only — nobody else on the network can reach it unless
``host`` is given explicitly — opens the browser unless told not to, and stops
cleanly on Ctrl-C or SIGTERM within :data:`~brdfkit.explorer.worker.SHUTDOWN_GRACE_S`
even while a model computes (uvicorn's shutdown, then the worker process killed; no
traceback). The specs given are the page's first models; those that are files
(``my.brdf``, ``model.py:NAME``, a MERL ``.binary``) are watched and reloaded in the open
page when saved, and a Python file named here may run (:mod:`brdfkit.explorer.files`).
Requests may open those files, files typed into the page's "open file", and data files
under ``allow_dirs`` (:mod:`brdfkit.explorer.guard`); each request computes for at most
*budget_s* seconds (:mod:`brdfkit.explorer.worker`).
"""

from __future__ import annotations

import logging
import threading
import urllib.parse
import webbrowser

from brdfkit.errors import BrdfkitError

__all__ = ["serve", "start_url", "DEFAULT_PORT", "LOCALHOST"]

DEFAULT_PORT = 8765
LOCALHOST = "127.0.0.1"


def start_url(host: str, port: int, specs=(), models=None) -> str:
    """The page's address, with *specs* as the initial models in the short URL state
    ``#m=SPEC,SPEC`` (each spec percent-encoded, a comma too), which the page expands to
    its full state (the models at their defaults); with *models* (ModelSpec dict forms:
    parameters, pumping, compensation) the full state ``#{"models": [...]}`` instead."""
    url = f"http://{host}:{port}/"
    if models:
        import json

        entries = [{"spec": d["model"], "params": d.get("params", {}),
                    "compensate": (d.get("compensate") or {}).get("method"),
                    "pump": (d.get("pump") or {}).get("g"),
                    "times": (d.get("pump") or {}).get("times", 1), "visible": True}
                   for d in models]
        return url + "#" + urllib.parse.quote(json.dumps({"models": entries}), safe="")
    if specs:
        url += "#m=" + ",".join(urllib.parse.quote(str(s), safe="") for s in specs)
    return url


def _check_free(host: str, port: int) -> None:
    """One clear error when the address is taken or invalid (uvicorn would log its own
    error and exit with status 3)."""
    import socket

    try:
        with socket.socket(socket.AF_INET6 if ":" in host else socket.AF_INET) as s:
            s.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
            s.bind((host, port))
    except OSError as exc:
        raise BrdfkitError(f"cannot serve on {host}:{port}: {exc.strerror or exc} (try another "
                           "--port, or stop the program using it)") from None


def serve(*, specs=(), models=None, host: str = LOCALHOST, port: int = DEFAULT_PORT,
          open_browser: bool = True, allow_dirs=(), budget_s: float | None = None,
          log=print, worker=None) -> None:
    """Serve until Ctrl-C. *specs* (model names or material specs) are validated first;
    *allow_dirs* must be directories. *models* (ModelSpec dict forms of *specs*, with their
    parameters and operators) open them so (:func:`start_url`). *worker*: the app's worker,
    started already (:func:`brdfkit.explorer.app.create_app`; the caller stops it)."""
    import os

    import uvicorn

    from brdfkit.explorer.app import create_app, plotly_js
    from brdfkit.explorer.worker import BUDGET_S, SHUTDOWN_GRACE_S
    from brdfkit.spec import canonical_name

    plotly_js()  # the page's plots: a missing plotly package is one line, before serving
    for d in allow_dirs:
        if not os.path.isdir(d):
            raise BrdfkitError(f"--allow-dir {d}: not a directory (give a directory whose "
                               "model files the page may open)")

    if not (isinstance(port, int) and 0 < port < 65536):
        raise BrdfkitError(f"--port must be an integer from 1 to 65535; got {port!r}")
    for s in specs:
        canonical_name(s)  # an unknown spec fails here, with the dispatcher's did-you-mean message
    _check_free(host, port)
    url = start_url(host, port, specs, models)
    where = ("this machine only" if host == LOCALHOST else
             f"every machine that can reach {host} (--host given)")
    log(f"brdfkit explore: serving on {url} ({where}); Ctrl-C stops")
    app = create_app(opened=specs, allow_dirs=allow_dirs, host=host,
                     budget_s=BUDGET_S if budget_s is None else budget_s, worker=worker)
    # the shutdown waits SHUTDOWN_GRACE_S for running requests, then cancels them (their
    # worker is killed): Ctrl-C stops the server at once even mid-computation
    config = uvicorn.Config(app, host=host, port=port, log_level="warning",
                            timeout_graceful_shutdown=SHUTDOWN_GRACE_S)
    # the requests cancelled at shutdown are ours to cancel (their worker is killed): not an
    # error for the user
    logging.getLogger("uvicorn.error").addFilter(
        lambda r: "timeout graceful shutdown exceeded" not in r.getMessage())
    server = uvicorn.Server(config)
    if open_browser:
        threading.Timer(1.0, lambda: webbrowser.open(url)).start()
    try:
        server.run()
    except KeyboardInterrupt:  # uvicorn handles SIGINT itself; this covers the rest
        pass
    except OSError as exc:
        raise BrdfkitError(f"cannot serve on {host}:{port}: {exc.strerror or exc} (try another "
                           "--port)") from None
    log("brdfkit explore: stopped")
