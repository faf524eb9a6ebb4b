"""The explorer under a stranger's hands (issue 19, part B), through real HTTP to a real
``brdfkit explore`` server process.

Each case failed before the change (the old behaviour is in the test's docstring):
- a heavy request (``modified-phong`` pumped ``controlled`` 8 times) froze the server for
  over 12 minutes and Ctrl-C/SIGTERM went unanswered;
- 100 000 channel values asked for 48.8 GiB, 40 000 lobes took 29 s;
- any ``Host`` and cross-origin ``text/plain`` POSTs were served; a ``.binary`` spec opened
  any path and the error showed the file's first 12 bytes;
- ``beta: "abc"``, ``beta: [1, 2]``: HTTP 500 with a server traceback.

References: the limits are the named constants of :mod:`brdfkit.explorer.guard` and the
budget the server was started with; "within the budget" is measured with the wall clock
around each request; Lambert f_r = ρ/π (closed form) shows the server still computes.
"""

from __future__ import annotations

import json
import math
import os
import signal
import struct
import subprocess
import sys
import threading
import time
import urllib.error
import urllib.request

import pytest
from explorer_harness import free_port, wait_answering

from brdfkit.explorer import guard

#: The test server's time budget: a warm worker draws a new analytic model in ~0.1-2 s on
#: this shared 2-core machine; a model pumped 4 times (the bound, pumping.MAX_TIMES) with g2
#: takes 1-2.5 minutes (times 8, the bound before, over 12 minutes).
BUDGET_S = 6.0
#: Slack on top of the budget for a reply: the HTTP round trip and killing the worker.
SLACK_S = 3.0
HEAVY = {"spec": "modified-phong", "params": {}, "pump": "controlled", "times": 4}


def _start(tmp_path, *extra):
    port = free_port()
    allowed = tmp_path / "allowed"
    allowed.mkdir(exist_ok=True)
    proc = subprocess.Popen(
        [sys.executable, "-m", "brdfkit", "explore", "--no-browser", "--port", str(port),
         "--budget", str(BUDGET_S), "--allow-dir", str(allowed), *extra],
        cwd=tmp_path, stderr=subprocess.PIPE, text=True)
    base = f"http://127.0.0.1:{port}"
    wait_answering(base + "/api/catalog")
    return proc, base


def _call(base, path, body=None, *, headers=None, raw=None, timeout=120.0):
    """(status, JSON or bytes, seconds) of one request."""
    data = raw if raw is not None else (None if body is None else json.dumps(body).encode())
    h = {"Content-Type": "application/json"} if data is not None else {}
    h.update(headers or {})
    req = urllib.request.Request(base + path, data=data, headers=h,
                                 method="POST" if data is not None else "GET")
    t0 = time.perf_counter()
    try:
        with urllib.request.urlopen(req, timeout=timeout) as r:
            status, out = r.status, r.read()
    except urllib.error.HTTPError as exc:
        status, out = exc.code, exc.read()
    dt = time.perf_counter() - t0
    try:
        return status, json.loads(out), dt
    except ValueError:
        return status, out, dt


@pytest.fixture(scope="module")
def server(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("explore")
    proc, base = _start(tmp)
    try:
        # warm: the worker's first model (cold start ~5 s, more on a loaded machine) is not
        # what the tests measure
        assert _drawn(base), "the server never drew a Lambertian model"
        yield base, tmp / "allowed", tmp
    finally:
        proc.terminate()
        proc.wait(timeout=30)


def _drawn(base, rho: float = 0.5, tries: int = 10) -> bool:
    """The server draws Lambert's f_r = ρ/π (closed form) within *tries* requests (a fresh
    worker warms up first: on a loaded machine a request may run out of the budget)."""
    for _ in range(tries):
        status, got, _ = _call(base, "/api/views", {"models": [{"spec": "lambert",
                                                                "params": {"rho_d": rho}}]})
        m = got["models"][0] if status == 200 else {}
        if "polar" in m:
            return abs(m["polar"]["values"][0][90] - rho / math.pi) < 1e-12
    return False


def _children(pid: int) -> set[int]:
    out = set()
    for d in os.listdir("/proc"):
        if d.isdigit():
            try:
                with open(f"/proc/{d}/stat") as fh:
                    if int(fh.read().rsplit(")", 1)[1].split()[1]) == pid:
                        out.add(int(d))
            except (OSError, IndexError, ValueError):
                pass
    return out


# --------------------------------------------------------------------------- time budget
def test_heavy_request_stops_at_its_budget_and_the_server_keeps_answering(server):
    """Before: the request computed on the server for over 12 minutes and /api/catalog
    waited (the kernels hold the GIL). Now: the catalog, the page and a light model answer
    while it runs; the heavy model comes back within the budget as an error naming the
    budget; the next request is drawn (the worker was restarted)."""
    base, _, _ = server
    result = {}
    t = threading.Thread(target=lambda: result.update(
        r=_call(base, "/api/views", {"models": [HEAVY]})))
    t.start()
    time.sleep(0.5)
    waits = []
    while t.is_alive():
        for path in ("/api/catalog", "/", "/api/changes?since=0"):
            status, _, dt = _call(base, path, timeout=10)
            assert status == 200
            waits.append(dt)
        time.sleep(0.2)
    t.join()
    status, got, dt = result["r"]
    assert status == 200 and dt <= BUDGET_S + SLACK_S, (status, dt)
    err = got["models"][0]["error"]
    assert f"time budget of {BUDGET_S:g} s" in err and "--budget" in err, err
    print(f"heavy request answered in {dt:.2f} s; other requests meanwhile: max "
          f"{max(waits):.3f} s over {len(waits)}")
    assert len(waits) >= 6 and max(waits) < 2.0, waits
    # the same model again (the page's verdict request follows its views): answered at once
    status, got, dt = _call(base, "/api/verdict", {"models": [HEAVY]})
    assert status == 200 and dt < 1.0 and "time budget" in got["verdicts"][0]["error"], dt
    assert _drawn(base, 0.25)  # the worker was restarted: the server draws again


def test_a_views_request_goes_before_a_waiting_verdict():
    """The worker computes one job at a time; the page asks a verdict after each views
    answer, so a slider move's views must not wait behind a queued verdict. With the
    worker busy (its one job slot held), a verdict-priority job queued first and a views
    one second: the views job runs first. (Without the priority the two poll the slot
    alike and either may win.)"""
    import asyncio

    from brdfkit.explorer.worker import Worker

    async def scenario() -> list[str]:
        w = Worker()
        w.start()
        order: list[str] = []

        async def go(name: str, low: bool) -> None:
            await w.run("names", {"entries": [{"spec": "lambert"}]},
                        deadline=time.monotonic() + 120.0, what=name, low=low)
            order.append(name)
        try:
            w._slot.acquire()  # the worker busy with another request
            verdict = asyncio.create_task(go("verdict", True))
            await asyncio.sleep(0.1)
            views = asyncio.create_task(go("views", False))
            await asyncio.sleep(0.1)
            w._slot.release()
            await asyncio.gather(verdict, views)
        finally:
            w.stop()
        return order

    assert asyncio.run(scenario()) == ["views", "verdict"]


@pytest.mark.parametrize("sig", [signal.SIGINT, signal.SIGTERM])
def test_ctrl_c_and_sigterm_stop_the_server_mid_computation(tmp_path, sig):
    """Before: while busy the server ignored SIGINT and SIGTERM (SIGKILL only). Now it
    exits within 3 s of the signal, its worker process is gone and no traceback is printed."""
    proc, base = _start(tmp_path)
    try:
        t = threading.Thread(target=lambda: _call(base, "/api/views", {"models": [HEAVY]},
                                                  timeout=60), daemon=True)
        t.start()
        time.sleep(1.5)  # the request is computing (or waiting for the cold worker)
        kids = _children(proc.pid)
        assert kids, "the server runs its worker in a child process"
        t0 = time.perf_counter()
        proc.send_signal(sig)
        proc.wait(timeout=10)
        took = time.perf_counter() - t0
        err = proc.stderr.read()
    finally:
        if proc.poll() is None:
            proc.kill()
    print(f"{signal.Signals(sig).name}: stopped in {took:.2f} s")
    assert took <= 3.0, took
    assert "Traceback" not in err and "ERROR" not in err, err
    time.sleep(0.5)
    assert not [k for k in kids if os.path.exists(f"/proc/{k}")
                and open(f"/proc/{k}/stat").read().split()[2] != "Z"], kids


# --------------------------------------------------------------------------- sizes
def test_every_size_is_bounded(server):
    """Before: 100 000 channel values asked for 48.8 GiB (MemoryError, HTTP 500); 40 000
    nh-power-series lobes took 29 s. Now each is refused at once, naming the limit."""
    base, _, _ = server
    big = [0.5] * 100_000
    for entry in ({"spec": "lambert", "params": {"rho_d": big}},
                  {"spec": "nh-power-series", "params": {"k_s": [0.01] * 40_000,
                                                         "n": [10.0] * 40_000}}):
        status, got, dt = _call(base, "/api/views", {"models": [entry]})
        err = got["models"][0]["error"]
        assert status == 200 and f"at most {guard.MAX_VALUES}" in err and dt < 2.0, (err, dt)
    # channels the views cannot draw (the sphere is grey or RGB)
    status, got, _ = _call(base, "/api/views",
                           {"models": [{"spec": "lambert", "params": {"rho_d": [0.5] * 5}}]})
    assert "grey (1) or RGB (3)" in got["models"][0]["error"] and "has 5" in got["models"][0][
        "error"]
    status, got, _ = _call(base, "/api/views", raw=b" " * (guard.MAX_BODY_BYTES + 1))
    assert status == 413 and str(guard.MAX_BODY_BYTES) in got["error"]
    status, got, _ = _call(base, "/api/views", {"models": [{"spec": "lambert"}] * 9})
    assert status == 400 and f"at most {guard.MAX_MODELS}" in got["error"]
    status, got, _ = _call(base, "/api/views", raw=b"[" * 50_000)
    assert status == 400 and "nests too deeply" in got["error"]
    status, got, _ = _call(base, "/api/views", {"models": [{"spec": "x" * 5000}]})
    assert f"1 to {guard.MAX_SPEC_CHARS} characters" in got["models"][0]["error"]


# --------------------------------------------------------------------------- security
def test_host_and_origin_are_checked(server):
    """Before: any Host and cross-origin text/plain POSTs were served (a page on another
    site, or a DNS-rebound name, could drive the server and read its replies). Now: the
    loopback names are served; another name, another page's Origin and a non-JSON body
    are refused (403, 403, 415)."""
    base, _, _ = server
    port = base.rsplit(":", 1)[1]
    for host in (f"127.0.0.1:{port}", f"localhost:{port}", f"[::1]:{port}"):
        assert _call(base, "/api/catalog", headers={"Host": host})[0] == 200, host
        status, _, _ = _call(base, "/api/views", {"models": []},
                             headers={"Host": host, "Origin": f"http://{host}"})
        assert status == 200, host
    status, got, _ = _call(base, "/api/catalog", headers={"Host": f"rebound.example:{port}"})
    assert status == 403 and "rebound.example" in got["error"]
    status, got, _ = _call(base, "/api/views", {"models": []},
                           headers={"Origin": "http://evil.example"})
    assert status == 403 and "evil.example" in got["error"]
    status, got, _ = _call(base, "/api/views", raw=json.dumps({"models": []}).encode(),
                           headers={"Content-Type": "text/plain"})
    assert status == 415 and "application/json" in got["error"]


def test_file_specs_only_as_given_and_never_echoed(server):
    """Before: a spec ending in .binary opened any path and the error showed the file's
    first 12 bytes (as int32). Now: a file outside --allow-dir is refused naming the path;
    one inside with a bad header names the file and field, not the bytes; a .py file
    under --allow-dir is still refused (it runs code)."""
    base, allowed, tmp = server
    secret = b"TOPSECRETKEY" + b"x" * 100
    ints = [str(x) for x in struct.unpack("<3i", secret[:12])]
    outside = tmp / "secret.binary"
    outside.write_bytes(secret)
    inside = allowed / "secret.binary"
    inside.write_bytes(secret)
    (allowed / "m.py").write_text("raise SystemExit('ran')\n")
    got = _call(base, "/api/views", {"models": [{"spec": str(outside)}, {"spec": str(inside)},
                                                {"spec": str(allowed / "m.py")}]})[1]
    e_out, e_in, e_py = (m["error"] for m in got["models"])
    assert str(outside) in e_out and "--allow-dir" in e_out, e_out
    assert str(inside) in e_in and "header" in e_in, e_in
    assert "a link cannot open it" in e_py, e_py
    for e in (e_out, e_in, e_py):
        assert "TOPSECRET" not in e and not any(x in e for x in ints), e
    for path in ("/api/export/binary",):
        status, got, _ = _call(base, path, {"spec": str(outside)})
        assert status == 400 and "--allow-dir" in got["error"]


# --------------------------------------------------------------------------- bad values
def test_bad_values_are_one_line_errors(server):
    """Before: beta "abc" or [1, 2] gave HTTP 500 with a server traceback. Now: one line
    naming beta and its range (in the model's entry of /api/views, 400 for an export);
    the export of [1] or null and a fit without a model are 400 with one line."""
    base, _, _ = server
    for beta in ("abc", [1, 2]):
        entry = {"spec": "modified-phong", "params": {"beta": beta}}
        status, got, _ = _call(base, "/api/views", {"models": [entry]})
        err = got["models"][0]["error"]
        assert status == 200 and "'beta'" in err and "(0, 90)" in err and "\n" not in err
        status, got, _ = _call(base, "/api/export/binary", entry)
        assert status == 400 and "'beta'" in got["error"]
    for body in ([1], None):
        status, got, _ = _call(base, "/api/export/binary", raw=json.dumps(body).encode())
        assert status == 400 and "'spec'" in got["error"] and "\n" not in got["error"]
    status, got, _ = _call(base, "/api/fit", {"target": "merl:nickel"})
    assert status == 400 and "model" in got["error"] and "\n" not in got["error"]


# --------------------------------------------------------------------------- fuzz
def _fuzz_strategies():
    from hypothesis import strategies as st

    from brdfkit.models import MODELS

    leaf = st.none() | st.booleans() | st.integers(-10**6, 10**6) | st.floats() | st.text(
        max_size=12)
    anything = st.recursive(leaf, lambda c: st.lists(c, max_size=4) | st.dictionaries(
        st.text(max_size=8), c, max_size=4), max_leaves=12)
    names = sorted(MODELS) + ["merl:nickel", "nikel", "/etc/passwd", "", "x.binary"]
    params = st.dictionaries(
        st.sampled_from(["rho_d", "rho_s", "n", "beta", "k_s", "alpha", "m", "zz"]),
        st.floats(-2, 200) | st.lists(st.floats(0, 1), max_size=5) | anything, max_size=3)
    entry = st.fixed_dictionaries({"spec": st.sampled_from(names)},
                                  optional={"params": params,
                                            "pump": st.none() | st.text(max_size=6),
                                            "times": anything, "visible": anything})
    state = st.fixed_dictionaries(
        {"models": st.lists(entry, min_size=1, max_size=3)},
        optional={"theta_i": st.floats(-10, 100) | anything, "phi_i": anything,
                  "phi_l": st.floats(0, 200), "ambient": anything,
                  "mode": st.sampled_from(["luminance", "rgb", "x"]), "cosine": anything})
    return st, anything, entry, state


def test_fuzz_random_json_never_500_and_within_budget(server):
    """Random JSON (and random near-valid states) at every endpoint: never a 500 or an
    internal error, always a reply within the budget (plus the round trip)."""
    pytest.importorskip("hypothesis")
    from hypothesis import HealthCheck, given, settings

    st, anything, entry, state = _fuzz_strategies()
    base, _, _ = server
    requests = st.one_of(  # near-valid states where a state goes, random JSON everywhere
        st.tuples(st.sampled_from(["/api/views", "/api/verdict"]),
                  st.one_of(state, state, state, anything)),
        st.tuples(st.sampled_from(["/api/export/binary", "/api/fit", "/api/open"]),
                  st.one_of(anything, entry)))

    @settings(max_examples=100, deadline=None, derandomize=True, database=None,
              suppress_health_check=list(HealthCheck))
    @given(request=requests, since=st.integers(-10**9, 10**9))
    def check(request, since):
        path, body = request
        status, got, dt = _call(base, path, body, timeout=BUDGET_S + 30)
        assert status != 500 and dt <= BUDGET_S + SLACK_S, (path, body, status, got, dt)
        text = json.dumps(got) if isinstance(got, dict) else ""
        assert "internal error" not in text, (path, body, text[:500])
        for p in (f"/api/changes?since={since}", f"/api/fit/{since}"):
            assert _call(base, p)[0] in (200, 404)

    check()


def test_one_fit_at_a_time_in_a_process_of_its_own(server):
    """Before: every POST /api/fit started a thread in the server (each a core for up to
    minutes, on the server's GIL). Now a fit runs in a process of its own, one at a time:
    a second is refused with one line naming the limit; the server answers meanwhile.
    (Last in this module: the server's shutdown stops the fit.)"""
    from brdfkit.explorer.worker import MAX_FITS

    base, _, _ = server
    body = {"model": {"spec": "lambert"}, "target": "merl:nickel", "loss": "l1"}
    status, got, _ = _call(base, "/api/fit", body)
    assert status == 200, got
    status, second, _ = _call(base, "/api/fit", body)
    assert status == 400 and f"{MAX_FITS} fit is running already" in second["error"], second
    status, job, _ = _call(base, f"/api/fit/{got['id']}")
    assert status == 200 and job["state"] in ("running", "done"), job
    assert _call(base, "/api/catalog", timeout=5)[0] == 200
