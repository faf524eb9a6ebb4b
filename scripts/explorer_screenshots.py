"""Screenshots of the explorer's views for docs/explorer/ (headless Debian chromium).

    .venv/bin/python scripts/explorer_screenshots.py [--out docs/explorer]

Serves the app on a free 127.0.0.1 port, opens it with merl:nickel next to a Nielsen
model and the pumped modified Phong, and writes one PNG per view plus the whole page at
1400 px (page.png) and at a narrow 900 px (page-narrow.png).
"""

from __future__ import annotations

import argparse
import json
import shutil
import socket
import threading
import time
import urllib.parse
from pathlib import Path

import uvicorn
from playwright.sync_api import sync_playwright

from brdfkit.explorer.app import create_app

VIEWS = ("polar", "lobe", "curves", "albedo", "sphere", "halfdiff")
STATE = {"models": [
    {"spec": "merl:nickel", "params": {}},
    {"spec": "nielsen", "params": {}},
    {"spec": "modified-phong", "params": {"n": 50}, "pump": "max", "times": 1},
], "theta_i": 40, "phi_l": 40}
# no ambient light: render_sphere's rim average fails on merl:nickel with an ambient term
# today (a ValueError in render/sphere.py _rim_means: 3 channels of a table against 1)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", default="docs/explorer")
    out = Path(ap.parse_args().out)
    out.mkdir(parents=True, exist_ok=True)
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        port = s.getsockname()[1]
    srv = uvicorn.Server(uvicorn.Config(create_app(), host="127.0.0.1", port=port,
                                        log_level="warning"))
    threading.Thread(target=srv.run, daemon=True).start()
    while not srv.started:
        time.sleep(0.05)
    url = f"http://127.0.0.1:{port}/#" + urllib.parse.quote(json.dumps(STATE))
    with sync_playwright() as p:
        b = p.chromium.launch(executable_path=shutil.which("chromium"), args=[
            "--no-sandbox", "--disable-gpu", "--disable-background-networking",
            "--disable-component-update", "--disable-sync", "--no-first-run"])
        for width, name in ((1400, "page.png"), (900, "page-narrow.png")):
            page = b.new_page(viewport={"width": width, "height": 1000})
            page.goto(url)
            page.wait_for_function("document.getElementById('status').textContent === 'ready'",
                                   timeout=300_000)
            page.wait_for_function("!document.getElementById('verdicts').textContent"
                                   ".includes('computing') && lobeMs !== null", timeout=300_000)
            if width == 1400:
                for v in VIEWS:
                    page.locator(f"#view-{v}").screenshot(path=str(out / f"{v}.png"))
            page.screenshot(path=str(out / name), full_page=True)
            page.close()
        b.close()
    srv.should_exit = True
    print(f"wrote {len(VIEWS) + 2} screenshots to {out}/")


if __name__ == "__main__":
    main()
