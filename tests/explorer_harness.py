"""The explorer's browser-test harness: a live server on a free port and headless Chromium.

Shared by tests/test_explorer.py and tests/test_explorer_live.py (the module-scoped
``server`` and ``browser`` fixtures are imported into each). Chromium is the machine's
(``scripts/setup.sh --test`` installs it with apt-get as root); without it the browser
tests skip with the reason.
"""

from __future__ import annotations

import shutil
import socket
import threading
import time

import pytest

CHROMIUM = shutil.which("chromium") or shutil.which("chromium-browser")
#: The time budget of the page tests' server (seconds per request): the page's behaviour is
#: tested here, the budget in test_explorer_robust.py; a formula's compile holds the
#: worker's GIL for 2-5 s, several times that on a loaded 2-core CI machine.
TEST_BUDGET_S = 300.0


def free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def wait_answering(url: str, *, tries: int = 300, every: float = 0.1) -> None:
    """Wait until a GET of *url* answers (a server process starting: brdfkit and Numba
    import first); at most *tries* × *every* seconds, then the caller's request fails."""
    import urllib.request

    for _ in range(tries):
        try:
            urllib.request.urlopen(url, timeout=5)
            return
        except OSError:
            time.sleep(every)


@pytest.fixture(scope="module")
def server():
    import tempfile

    import uvicorn

    from brdfkit.explorer.app import create_app
    from brdfkit.explorer.worker import SHUTDOWN_GRACE_S

    port = free_port()
    # the tests' files are in the temporary directory: the user's --allow-dir; the budget is
    # tested in test_explorer_robust.py, here a compile on a loaded CI machine may take long
    app = create_app(allow_dirs=[tempfile.gettempdir()], budget_s=TEST_BUDGET_S)
    srv = uvicorn.Server(uvicorn.Config(app, host="127.0.0.1", port=port, log_level="warning",
                                        timeout_graceful_shutdown=SHUTDOWN_GRACE_S))
    thread = threading.Thread(target=srv.run, daemon=True)
    thread.start()
    for _ in range(200):
        if srv.started:
            break
        time.sleep(0.05)
    yield f"http://127.0.0.1:{port}/"
    srv.should_exit = True
    thread.join(timeout=10)


@pytest.fixture(scope="module")
def browser():
    if CHROMIUM is None:
        pytest.skip("no chromium on this machine: scripts/setup.sh --test installs it with "
                    "apt-get when run as root (apt-get install chromium)")
    from playwright.sync_api import sync_playwright

    with sync_playwright() as p:
        b = p.chromium.launch(executable_path=CHROMIUM, args=[
            "--no-sandbox", "--disable-gpu", "--disable-background-networking",
            "--disable-component-update", "--disable-sync", "--no-first-run"])
        yield b
        b.close()


def open_page(browser, url):
    page = browser.new_page(viewport={"width": 1400, "height": 1000})
    errors = []
    page.on("console", lambda m: errors.append(m.text) if m.type == "error" else None)
    page.on("pageerror", lambda e: errors.append(str(e)))
    page.goto(url)
    wait_ready(page)
    return page, errors


def wait_ready(page):
    page.wait_for_function("document.getElementById('status').textContent === 'ready'",
                           timeout=180_000)
