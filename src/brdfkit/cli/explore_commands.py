"""
``brdfkit explore``: the browser app
====================================

Plain click command; :mod:`brdfkit.cli` adds it to the ``brdfkit`` group.
"""

from __future__ import annotations

import click

from brdfkit.explorer.serve import DEFAULT_PORT, LOCALHOST, serve
from brdfkit.explorer.worker import BUDGET_S, Worker

__all__ = ["explore_cmd"]


@click.command("explore")
@click.argument("specs", nargs=-1, metavar="[SPEC]...")
@click.option("--port", type=click.IntRange(1, 65535), default=DEFAULT_PORT, show_default=True,
              help="TCP port.")
@click.option("--host", default=LOCALHOST, show_default=True,
              help="Address to listen on. The default serves this machine only; give another "
                   "address (e.g. 0.0.0.0) only to allow remote access on purpose.")
@click.option("--no-browser", is_flag=True, help="Do not open a browser window.")
@click.option("--allow-dir", "allow_dirs", multiple=True, metavar="DIR",
              type=click.Path(exists=True, file_okay=False),
              help="A directory whose data files (.binary, .brdf; not .py) the page and "
                   "links may open (repeatable). Without it only the files named here or "
                   "typed into 'open file' are opened.")
@click.option("--budget", type=click.FloatRange(0, 86400, min_open=True), default=BUDGET_S,
              show_default=True, metavar="SECONDS",
              help="Time one request may compute; a model over it shows an error in the "
                   "page (the computation is stopped).")
def explore_cmd(specs, port, host, no_browser, allow_dirs, budget):
    """Open the explorer: models, pumped models and materials side by side in a browser.

    SPEC... are the models shown first (model names, material specs such as
    merl:nickel, or files: my.brdf, model.py[:NAME], a MERL .binary); more can be
    added in the page, a file by its path ("open file"). A file shown is watched:
    saving an edit redraws it within a second, keeping the parameter values the
    new version still has; a broken edit shows its error beside the last good
    version. A .py model runs its code: only files named here or typed into the
    page are loaded. Views: in-plane polar plot,
    3-D lobe, f against theta_h/theta_d/theta_o, theta_h x theta_d slice, the lit
    sphere of Lewis's test configuration, and the albedo curve with the
    plausibility verdict. Serves on 127.0.0.1 only unless --host is given, answers
    only requests addressed to this server from its own page, computes each request
    for at most --budget seconds in a worker process; Ctrl-C stops it at once.
    """
    # the worker process first: it imports and computes the page's first views while this
    # process imports the web server and the page loads (an invalid spec or a port in use
    # stops it again at once)
    from brdfkit.explorer.compute import start_payload

    worker = Worker(warm=start_payload(specs))
    worker.start()
    try:
        serve(specs=specs, host=host, port=port, open_browser=not no_browser,
              allow_dirs=allow_dirs, budget_s=budget, log=lambda s: click.echo(s, err=True),
              worker=worker)
    finally:
        worker.stop()
