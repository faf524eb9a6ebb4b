"""A screenshot of the live explorer: models from files side by side, one with a broken edit.

    .venv/bin/python scripts/explorer_live_screenshot.py [--out /tmp/explorer-live.png]
                                                         [--formula-edit]

Writes, in a temporary directory, a Lambertian and a modified-Phong MERL ``.binary``
table and (when the ``.brdf`` kind exists) a Lambert ``.brdf`` file; serves the app on a
free 127.0.0.1 port, opens the page on them, then breaks the last file (a syntax error in
the ``.brdf``, or a truncated table) and, once the page shows the error beside the last
good drawing, takes a full-page screenshot. ``--formula-edit``: the last file is
``benchmarks/brdf/principled.brdf`` and its formula is edited (× a random constant):
one screenshot as soon as the page draws the interpreted draft, one (``-compiled``)
once it draws the compiled model. Not for the repository: PNGs are not committed.
"""

from __future__ import annotations

import argparse
import importlib.util
import json
import shutil
import socket
import tempfile
import threading
import time
import urllib.parse
from pathlib import Path

import uvicorn
from playwright.sync_api import sync_playwright

import brdfkit
from brdfkit.data.export import export_merl
from brdfkit.explorer.app import create_app

LAMBERT_BRDF = """analytic
::begin parameters
float rho 0 1 0.5
::end parameters
::begin shader
vec3 BRDF(vec3 L, vec3 V, vec3 N, vec3 X, vec3 Y) { return vec3(rho / 3.14159265358979); }
::end shader
"""


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", default=str(Path(tempfile.gettempdir()) / "explorer-live.png"))
    ap.add_argument("--formula-edit", action="store_true",
                    help="edit principled.brdf's formula instead of breaking a file")
    args = ap.parse_args()
    out = Path(args.out)
    d = Path(tempfile.mkdtemp(prefix="brdfkit-live-"))
    lam, phong = d / "lambert-table.binary", d / "phong-table.binary"
    export_merl(brdfkit.model("lambert", rho_d=[0.6, 0.4, 0.2]), lam)
    export_merl(brdfkit.model("modified-phong", rho_d=0.1, rho_s=0.4, n=40), phong)
    has_brdf = importlib.util.find_spec("brdfkit.user") is not None and \
        importlib.util.find_spec("brdfkit.user.brdf_file") is not None
    broken = d / "lambert.brdf" if has_brdf else d / "broken.binary"
    if has_brdf:
        broken.write_text(LAMBERT_BRDF)
    else:
        export_merl(brdfkit.model("lambert", rho_d=0.3), broken)
    principled = Path(__file__).resolve().parents[1] / "benchmarks" / "brdf" / "principled.brdf"
    if args.formula_edit:
        broken = d / "principled.brdf"
        broken.write_text(principled.read_text())
    specs = [str(lam), str(phong), str(broken)]
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        port = s.getsockname()[1]
    srv = uvicorn.Server(uvicorn.Config(create_app(opened=specs), host="127.0.0.1", port=port,
                                        log_level="warning"))
    threading.Thread(target=srv.run, daemon=True).start()
    while not srv.started:
        time.sleep(0.05)
    state = {"models": [{"spec": s, "params": {}} for s in specs], "theta_i": 40, "phi_l": 40}
    url = f"http://127.0.0.1:{port}/#" + urllib.parse.quote(json.dumps(state))
    with sync_playwright() as p:
        b = p.chromium.launch(executable_path=shutil.which("chromium"), args=[
            "--no-sandbox", "--disable-gpu", "--disable-background-networking",
            "--disable-component-update", "--disable-sync", "--no-first-run"])
        page = b.new_page(viewport={"width": 1500, "height": 1100})
        page.goto(url)
        page.wait_for_function("document.getElementById('status').textContent === 'ready'",
                               timeout=300_000)
        if args.formula_edit:
            _formula_edit(page, broken, out)
            b.close()
            srv.should_exit = True
            return
        if has_brdf:  # a syntax error: the loader names file:line:col
            broken.write_text(LAMBERT_BRDF.replace("return vec3(", "return vec3(("))
        else:
            broken.write_bytes(broken.read_bytes()[:1000])  # a truncated table
        page.wait_for_function("document.getElementById('model-error-2').textContent"
                               ".includes('not reloaded')", timeout=60_000)
        page.wait_for_function("!document.getElementById('verdicts').textContent"
                               ".includes('computing')", timeout=300_000)
        page.screenshot(path=str(out), full_page=True)
        print(f"wrote {out}; the page said: {page.locator('#model-error-2').text_content()}")
        b.close()
    srv.should_exit = True


def _formula_edit(page, path: Path, out: Path) -> None:
    """Multiply the file's result by a random constant; screenshot the draft, then the
    compiled model."""
    import random

    page.wait_for_function("lastViews.models.every(v => v.compiled !== false)", timeout=300_000)
    k = 1.0 + random.random()
    text = path.read_text().replace("    return (INV_PI", f"    return {k!r} * ((INV_PI")
    path.write_text(text.replace("* dr;\n}", "* dr);\n}"))
    t0 = time.perf_counter()
    page.wait_for_function("lastViews.models[2].compiled === false", timeout=60_000, polling=10)
    drawn = time.perf_counter() - t0
    page.screenshot(path=str(out), full_page=True)
    page.wait_for_function("lastViews.models[2].compiled === true", timeout=300_000)
    compiled = time.perf_counter() - t0
    page.wait_for_function("!document.getElementById('verdicts').textContent"
                           ".includes('computing')", timeout=300_000)
    second = out.with_name(out.stem + "-compiled" + out.suffix)
    page.screenshot(path=str(second), full_page=True)
    print(f"× {k:.6f}: draft drawn {drawn:.2f} s after the save ({out}), compiled model "
          f"{compiled:.2f} s ({second}); {page.locator('#model-file-2').text_content()}")


if __name__ == "__main__":
    main()
