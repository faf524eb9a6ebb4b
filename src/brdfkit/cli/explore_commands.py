"""
``brdfkit explore``: the browser app
====================================

Plain click command; :mod:`brdfkit.cli` adds it to the ``brdfkit`` group.
"""

from __future__ import annotations

import click

from brdfkit.cli._common import model_entry, model_word_options
from brdfkit.errors import BrdfkitError
from brdfkit.explorer.serve import DEFAULT_PORT, LOCALHOST, serve
from brdfkit.explorer.worker import BUDGET_S, Worker

__all__ = ["explore_cmd"]


@click.command("explore")
@click.argument("specs", nargs=-1, metavar="[MODEL]...")
@model_word_options
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
def explore_cmd(specs, param, compensate, pump, times, port, host, no_browser, allow_dirs,
                budget):
    """Open the explorer: models, pumped models and materials side by side in a browser.

    MODEL... are the models shown first (model names, material specs such as
    merl:nickel, or files: my.brdf, model.py[:NAME], a MERL .binary); -p, --compensate,
    --pump and --times set the one MODEL's parameters and operators (with several,
    quote each with its own words as --compare takes them, e.g. 'nielsen -p k_s=5'
    merl:nickel). More can be
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
    words = bool(param or compensate or pump or times is not None)
    if words and len(specs) != 1:
        raise BrdfkitError("-p, --compensate, --pump and --times describe one MODEL; got "
                           f"{len(specs)} (quote each model with its own words instead, e.g. "
                           "brdfkit explore 'nielsen -p k_s=5' merl:nickel)")
    entries = [model_entry(s, param, pump, times, compensate, option="MODEL") for s in specs]
    if not words and all(set(e) == {"model", "params"} and not e["params"]
                         for e in entries):
        entries = None  # the short state #m=SPEC,... (the page's defaults)
    else:
        specs = [e["model"] for e in entries]
    # the worker process first: it imports and computes the page's first views while this
    # process imports the web server and the page loads (an invalid spec or a port in use
    # stops it again at once); models with words are computed when the page asks
    from brdfkit.explorer.compute import start_payload

    worker = Worker(warm=start_payload(specs if entries is None else ()))
    worker.start()
    try:
        serve(specs=specs, models=entries, host=host, port=port, open_browser=not no_browser,
              allow_dirs=allow_dirs, budget_s=budget, log=lambda s: click.echo(s, err=True),
              worker=worker)
    finally:
        worker.stop()
