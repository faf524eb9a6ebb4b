"""
``brdfkit explore``: serve the explorer on this machine
=======================================================

:func:`serve` runs the app (:func:`brdfkit.explorer.app.create_app`) with
uvicorn on **127.0.0.1** only — nobody else on the network can reach it unless
``host`` is given explicitly — opens the browser unless told not to, and stops
cleanly on Ctrl-C (uvicorn's shutdown; no traceback). The specs given are the
page's first models; those that are files (``my.brdf``, ``model.py:NAME``, a MERL
``.binary``) are watched and reloaded in the open page when saved, and a Python file
named here may run (:mod:`brdfkit.explorer.files`).
"""

from __future__ import annotations

import json
import threading
import urllib.parse
import webbrowser

from brdfkit.errors import BrdfkitError

__all__ = ["serve", "start_url", "DEFAULT_PORT", "LOCALHOST"]

DEFAULT_PORT = 8765
LOCALHOST = "127.0.0.1"


def start_url(host: str, port: int, specs=()) -> str:
    """The page's address, with *specs* as the initial models in the URL state."""
    url = f"http://{host}:{port}/"
    if specs:
        state = {"models": [{"spec": s, "params": {}, "pump": None, "times": 1, "visible": True}
                            for s in specs]}
        url += "#" + urllib.parse.quote(json.dumps(state))
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


def serve(*, specs=(), host: str = LOCALHOST, port: int = DEFAULT_PORT, open_browser: bool = True,
          log=print) -> None:
    """Serve until Ctrl-C. *specs* (model names or material specs) are validated first."""
    import uvicorn

    from brdfkit.explorer.app import create_app
    from brdfkit.spec import canonical_name

    if not (isinstance(port, int) and 0 < port < 65536):
        raise BrdfkitError(f"--port must be an integer from 1 to 65535; got {port!r}")
    for s in specs:
        canonical_name(s)  # an unknown spec fails here, with the dispatcher's did-you-mean message
    _check_free(host, port)
    url = start_url(host, port, specs)
    where = ("this machine only" if host == LOCALHOST else
             f"every machine that can reach {host} (--host given)")
    log(f"brdfkit explore: serving on {url} ({where}); Ctrl-C stops")
    config = uvicorn.Config(create_app(opened=specs), host=host, port=port,
                            log_level="warning")
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
