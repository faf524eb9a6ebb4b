"""Screenshots of a `brdfkit reproduce` report in headless Chromium (issue 24: "the
screenshot of the report's first screen and of one claim section were looked at").

    PYTHONPATH=src python scripts/reproduce_screenshots.py report/ [--out shots/]
        [--claim neumann-2.1-cook-diverges]

Writes first-screen.png and claim-<id>.png, and prints the page's console errors, the
images that did not load and the internal links without a target (all should be empty).
"""

from __future__ import annotations

import argparse
import os
import re
import shutil
import sys


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("report", help="the directory holding index.html")
    ap.add_argument("--out", default=".", help="directory of the screenshots")
    ap.add_argument("--claim", default="neumann-2.1-cook-diverges", help="a claim id")
    a = ap.parse_args(argv)
    chromium = shutil.which("chromium") or shutil.which("chromium-browser")
    if chromium is None:
        print("no chromium on this machine (apt-get install chromium)", file=sys.stderr)
        return 1
    from playwright.sync_api import sync_playwright

    os.makedirs(a.out, exist_ok=True)
    url = "file://" + os.path.abspath(os.path.join(a.report, "index.html"))
    anchor = "claim-" + re.sub(r"[^a-z0-9-]+", "-", a.claim.lower())
    with sync_playwright() as p:
        browser = p.chromium.launch(executable_path=chromium,
                                    args=["--no-sandbox", "--disable-gpu"])
        page = browser.new_page(viewport={"width": 1280, "height": 900})
        errors = []
        page.on("console", lambda m: errors.append(m.text) if m.type == "error" else None)
        page.goto(url)
        page.screenshot(path=os.path.join(a.out, "first-screen.png"))
        page.goto(f"{url}#{anchor}")
        page.screenshot(path=os.path.join(a.out, f"claim-{a.claim}.png"))
        broken = page.eval_on_selector_all("img", "els => els.filter(e => !(e.naturalWidth "
                                                  "> 0)).map(e => e.alt)")
        links = page.eval_on_selector_all("a[href^='#']", "els => els.map(e => e.getAttribute("
                                          "'href').slice(1)).filter(i => !document"
                                          ".getElementById(i))")
        browser.close()
    print(f"console errors: {errors}\nimages not loaded: {broken}\nlinks without target: "
          f"{links}")
    return 0 if not (errors or broken or links) else 1


if __name__ == "__main__":
    sys.exit(main())
