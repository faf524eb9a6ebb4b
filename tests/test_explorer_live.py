"""The explorer, live (issue 21 §4): models from files shown side by side, reloaded in the
open page when the file is saved, the last good version kept with a broken edit's error,
files opened by path — through the API and in a real headless Chromium (Debian's
``chromium`` driven by Playwright with ``executable_path``, as ``tests/test_explorer.py``).

Reference values and their sources:
- Lambert f_r = ρ/π in every direction (closed form): a Lambertian MERL table of our own
  making (:func:`brdfkit.data.export.export_merl`) gives back ρ/π, so a saved edit of ρ
  shows as a change of the in-plane slice from ρ₀/π to ρ₁/π;
- the content hash of a file is SHA-256 of its bytes (:mod:`hashlib`, independent of the
  watcher's reading): a ``touch`` changes no hash, a same-size rewrite does;
- the latency is measured: from the moment the new file is in place to the moment the
  page holds the new value; the issue asks ≤ 1 s.

The ``.brdf`` and ``.py`` tests run once those kinds exist (``importorskip`` of their
loaders, ``brdfkit.user.brdf_file`` and ``brdfkit.user.python_file``); until then the
mechanism is tested with MERL ``.binary`` files, a file-backed kind like any other.
"""

from __future__ import annotations

import json
import math
import os
import re
import threading
import time
import urllib.parse

import numpy as np
import pytest
from explorer_harness import TEST_BUDGET_S, free_port, open_page, wait_answering, wait_ready

import brdfkit
from brdfkit.data.export import export_merl
from brdfkit.explorer import files

#: Seconds after which a save not yet drawn counts as a frozen page. The explorer's speed
#: targets (a save drawn within 1 s) are measured in benchmarks/bench_explorer_edit.py.
FROZEN_S = 10.0
LOCAL = {"client": ("127.0.0.1", 50000), "headers": {"host": "127.0.0.1:8765"}}

LAMBERT_BRDF = """analytic
::begin parameters
float rho 0 1 0.5
::end parameters
::begin shader
vec3 BRDF(vec3 L, vec3 V, vec3 N, vec3 X, vec3 Y) { return vec3(rho / 3.14159265358979); }
::end shader
"""
LAMBERT_PY = """from brdfkit.formula import Param, define, formula

PI = 3.141592653589793


@formula
def lam(ix, iy, iz, ox, oy, oz, {name}):
    return {scale} * {name} / PI


MODEL = define("lam", eval=lam, params=[Param("{name}", 0.5, 0.0, 1.0, doc="albedo")])
"""


def _lambert_binary(path, rho: float) -> None:
    export_merl(brdfkit.model("lambert", rho_d=rho), path)  # atomic: written, then renamed


def _slice0(model_view) -> float:
    """The in-plane slice at θ_o = 0 (index 90 of 181) of one model's views."""
    return model_view["polar"]["values"][0][90]


# --------------------------------------------------------------------------- the file seam
def test_spec_file_names_the_file_a_target_reads(tmp_path):
    b = tmp_path / "a.binary"
    b.write_bytes(b"x")
    py = tmp_path / "m.py"
    py.write_text("")
    assert files.spec_file(str(b)) == str(b)
    assert files.spec_file(f"{py}:NAME") == str(py)  # PATH.py:NAME reads PATH.py
    assert files.spec_file(str(py)) == str(py) and files.runs_code(str(py))
    assert not files.runs_code(str(b))
    for not_a_file in ("merl:nickel", "lambert", str(tmp_path), str(tmp_path / "no.brdf"),
                       f"{b}:NAME"):  # only a .py takes a :NAME
        assert files.spec_file(not_a_file) is None, not_a_file


def test_watcher_sees_content_changes_not_touches(tmp_path, monkeypatch):
    import hashlib

    p = tmp_path / "m.brdf"
    p.write_text("one")
    now = time.time_ns()
    os.utime(p, ns=(now, now - 10_000_000_000))  # 10 s old: past the racy window
    w = files.FileWatcher()
    assert w.digest(str(p)) == hashlib.sha256(b"one").hexdigest()
    v0 = w.poll()
    os.utime(p, ns=(now, now - 9_000_000_000))  # a touch: a new stamp, the same bytes
    time.sleep(files.POLL_INTERVAL_S)
    assert w.poll() == v0 and w.changes(v0) == []
    # two writes of one size within one timestamp tick (the stamp does not move): hashed
    # once more when the stamp has aged past the racy window, and the change is seen
    monkeypatch.setattr(files, "RACY_NS", 300_000_000)
    young = time.time_ns()
    os.utime(p, ns=(young, young))
    time.sleep(files.POLL_INTERVAL_S)
    assert w.poll() == v0  # hashed now, the same bytes
    p.write_text("two")
    os.utime(p, ns=(young, young))  # the same stamp as the hash saw
    time.sleep(files.POLL_INTERVAL_S)
    assert w.poll() == v0  # the stamp did not move: not seen yet
    time.sleep(0.3)
    assert w.poll() == v0 + 1 and w.changes(v0) == [str(p)]
    assert w.digest(str(p)) == hashlib.sha256(b"two").hexdigest()
    time.sleep(0.3)
    assert w.poll() == v0 + 1  # hashed once after the window, not on every poll
    p.unlink()  # deleted: a change, no hash
    time.sleep(files.POLL_INTERVAL_S)
    assert w.poll() == v0 + 2 and w.digest(str(p)) is None


def test_a_compile_superseded_by_a_save_is_skipped(tmp_path):
    """Compiles run one at a time; one whose file was saved again before its turn is
    skipped (no compile, no version raised) and queued again if that content returns."""
    pytest.importorskip("brdfkit.user.brdf_file")
    p = tmp_path / "lam.brdf"
    p.write_text(LAMBERT_BRDF)
    marks = []

    class Marks:
        def mark(self, path):
            marks.append(path)

    fm = files.FileModels(watcher=Marks())
    target = str(p)
    d1 = files.content_digest(target)
    m, info = fm.build(target, target, d1, {}, lambda kept: brdfkit.ModelSpec(target, kept))
    assert info["compiled"] is False  # the draft, its compile queued
    with fm._compiling:  # another compile is running: this one waits for its turn
        fm.start_compiles()
        p.write_text(LAMBERT_BRDF.replace("0 1 0.5", "0 1 0.7"))  # saved again meanwhile
    for t in fm.threads:
        t.join(60)
    assert marks == [] and fm.stage(target, target, d1) == "interpreted"
    p.write_text(LAMBERT_BRDF)  # the first content again: its compile is queued anew
    fm.build(target, target, d1, {}, lambda kept: brdfkit.ModelSpec(target, kept))
    fm.start_compiles()
    for t in fm.threads:
        t.join(120)
    assert marks == [target] and fm.stage(target, target, d1) == "compiled"


# --------------------------------------------------------------------------- the API
@pytest.fixture
def client(tmp_path):
    from fastapi.testclient import TestClient

    from brdfkit.explorer.app import create_app

    with TestClient(create_app(allow_dirs=[tmp_path], budget_s=TEST_BUDGET_S), **LOCAL) as c:
        yield c


def test_api_reloads_a_file_model_and_keeps_the_last_good(client, tmp_path):
    p = tmp_path / "lam.binary"
    _lambert_binary(p, 0.3)
    state = {"models": [{"spec": str(p), "params": {"lookup": "linear", "rho_x": 1}}]}

    def views():
        r = client.post("/api/views", json=state)
        assert r.status_code == 200, r.text
        return r.json()

    v0 = views()
    m = v0["models"][0]
    np.testing.assert_allclose(_slice0(m), 0.3 / math.pi, rtol=1e-9)
    assert m["file"] == str(p) and m["reload_error"] is None
    assert m["params"] == {"lookup": "linear"} and m["dropped"] == ["rho_x"]
    assert [d["name"] for d in m["decl"]["params"]] == ["lookup"]
    _lambert_binary(p, 0.6)  # saved: the cache keys on the content, never the stale model
    changed = client.get(f"/api/changes?since={v0['version']}").json()
    assert changed["version"] > v0["version"] and changed["changed"] == [str(p)]
    m = views()["models"][0]
    np.testing.assert_allclose(_slice0(m), 0.6 / math.pi, rtol=1e-9)
    assert m["params"] == {"lookup": "linear"}  # the value that still exists is kept
    p.write_bytes(b"not a MERL table")  # a broken edit: its error, the last good drawn
    m = views()["models"][0]
    assert str(p) in m["reload_error"] and "header" in m["reload_error"]
    np.testing.assert_allclose(_slice0(m), 0.6 / math.pi, rtol=1e-9)
    _lambert_binary(p, 0.2)  # fixed: the error clears
    m = views()["models"][0]
    assert m["reload_error"] is None
    np.testing.assert_allclose(_slice0(m), 0.2 / math.pi, rtol=1e-9)
    # a file broken from the start: the model's error, no drawing; it stays watched
    q = tmp_path / "bad.binary"
    q.write_bytes(b"xx")
    bad = client.post("/api/views", json={"models": [{"spec": str(q)}]}).json()["models"][0]
    assert "polar" not in bad and str(q) in bad["error"] and bad["file"] == str(q)


def test_api_opens_a_file_by_path_from_this_machine_only(tmp_path, monkeypatch):
    from fastapi.testclient import TestClient

    from brdfkit.explorer.app import create_app

    app = create_app()
    local = TestClient(app, **LOCAL)
    remote = TestClient(app, client=("10.1.2.3", 50000), headers=LOCAL["headers"])
    p = tmp_path / "lam.binary"
    _lambert_binary(p, 0.3)
    r = local.post("/api/open", json={"path": str(p)})
    assert r.status_code == 200 and r.json() == {"spec": str(p), "file": str(p)}
    for path, says in ((str(tmp_path), "is a directory"),
                       (str(tmp_path / "no.brdf"), "no such file"),
                       ("", "type the path"), (f"{tmp_path}/no.py:lam", "no such file")):
        r = local.post("/api/open", json={"path": path})
        assert r.status_code == 400 and says in r.json()["error"], (path, r.text)
    monkeypatch.setenv("HOME", str(tmp_path))  # ~ expanded: the loaders read specs as paths
    assert local.post("/api/open", json={"path": "~/lam.binary"}).json()["spec"] == str(p)
    r = remote.post("/api/open", json={"path": str(p)})  # not from 127.0.0.1
    assert r.status_code == 403 and "this machine" in r.json()["error"]
    r = local.post("/api/open", json={"path": str(p)}, headers={"origin": "http://evil.example"})
    assert r.status_code == 403  # another site open in the browser
    r = local.post("/api/open", json={"path": str(p)},
                   headers={"host": "rebound.example:8765", "origin": "http://rebound.example:8765"})
    assert r.status_code == 403  # a DNS-rebound name


def test_a_python_file_runs_only_once_the_user_named_it(tmp_path):
    """A ``.py`` spec from a link (the state) is refused until opened by path or given on
    the command line; after that it is built (its loader's own message, whatever it is)."""
    from fastapi.testclient import TestClient

    from brdfkit.explorer.app import create_app

    py = tmp_path / "lam.py"
    marker = tmp_path / "ran"
    py.write_text(f"open({str(marker)!r}, 'w').close()\n"
                  + LAMBERT_PY.format(scale=1.0, name="rho"))
    c = TestClient(create_app(allow_dirs=[tmp_path], budget_s=TEST_BUDGET_S), **LOCAL)
    state = {"models": [{"spec": str(py)}]}
    m = c.post("/api/views", json=state).json()["models"][0]
    assert "a link cannot open it" in m["error"] and not marker.exists()
    r = c.post("/api/fit", json={"model": {"spec": "lambert"}, "target": str(py)})
    assert r.status_code == 400 and "a link cannot open it" in r.json()["error"]
    assert not marker.exists()  # nor as a fit's target
    assert c.post("/api/open", json={"path": str(py)}).status_code == 200
    m = c.post("/api/views", json=state).json()["models"][0]
    assert "a link cannot open it" not in m.get("error", "")
    # the command line's files are named by the user too
    c2 = TestClient(create_app(opened=[f"{py}:lam"]), **LOCAL)
    m = c2.post("/api/views", json={"models": [{"spec": f"{py}:lam"}]}).json()["models"][0]
    assert "a link cannot open it" not in m.get("error", "")


def test_api_brdf_file_reload_keeps_values_and_shows_line_col(client, tmp_path):
    pytest.importorskip("brdfkit.user.brdf_file")
    p = tmp_path / "lambert.brdf"
    p.write_text(LAMBERT_BRDF)
    state = {"models": [{"spec": str(p), "params": {"rho": 0.25}}]}
    m = client.post("/api/views", json=state).json()["models"][0]
    np.testing.assert_allclose(_slice0(m), 0.25 / math.pi, rtol=1e-6)
    assert [d["name"] for d in m["decl"]["params"]] == ["rho"]
    # an edit of the formula: the page's rho = 0.25 still exists, so it is kept
    p.write_text(LAMBERT_BRDF.replace("rho / 3.14", "2.0 * rho / 3.14"))
    m = client.post("/api/views", json=state).json()["models"][0]
    np.testing.assert_allclose(_slice0(m), 0.5 / math.pi, rtol=1e-6)
    # a broken edit (a syntax error): file:line:col, the last good version drawn
    p.write_text(LAMBERT_BRDF.replace("return vec3(", "return vec3(("))
    m = client.post("/api/views", json=state).json()["models"][0]
    assert re.search(re.escape(str(p)) + r":\d+:\d+", m.get("reload_error") or ""), m
    np.testing.assert_allclose(_slice0(m), 0.5 / math.pi, rtol=1e-6)
    # a rename: rho dropped (named), the new parameter at its default
    p.write_text(LAMBERT_BRDF.replace("rho", "kd").replace("0 1 0.5", "0 1 0.7"))
    m = client.post("/api/views", json=state).json()["models"][0]
    assert m["reload_error"] is None and m["dropped"] == ["rho"]
    np.testing.assert_allclose(_slice0(m), 0.7 / math.pi, rtol=1e-6)


def test_api_python_file_reload(tmp_path):
    pytest.importorskip("brdfkit.user.python_file")
    from fastapi.testclient import TestClient

    from brdfkit.explorer.app import create_app

    py = tmp_path / "lam.py"
    py.write_text(LAMBERT_PY.format(scale=1.0, name="rho"))
    c = TestClient(create_app(opened=[str(py)], budget_s=TEST_BUDGET_S), **LOCAL)
    state = {"models": [{"spec": str(py), "params": {"rho": 0.4}}]}
    m = c.post("/api/views", json=state).json()["models"][0]
    np.testing.assert_allclose(_slice0(m), 0.4 / math.pi, rtol=1e-9)
    py.write_text(LAMBERT_PY.format(scale=2.0, name="rho"))
    m = c.post("/api/views", json=state).json()["models"][0]
    np.testing.assert_allclose(_slice0(m), 0.8 / math.pi, rtol=1e-9)
    py.write_text(LAMBERT_PY.format(scale=2.0, name="rho") + "\ndef broken(:\n")
    m = c.post("/api/views", json=state).json()["models"][0]
    assert m["reload_error"] and str(py) in m["reload_error"]
    np.testing.assert_allclose(_slice0(m), 0.8 / math.pi, rtol=1e-9)
    py.write_text(LAMBERT_PY.format(scale=1.0, name="rho_d"))
    m = c.post("/api/views", json=state).json()["models"][0]
    assert m["reload_error"] is None and m["dropped"] == ["rho"]
    np.testing.assert_allclose(_slice0(m), 0.5 / math.pi, rtol=1e-9)


# --------------------------------------------------------------------------- the browser
def _url(base, specs):
    """The short address the command prints (serve.start_url: ``#m=SPEC,SPEC``); the page
    expands it to its full state (so these browser tests check the expansion too)."""
    return base + "#m=" + ",".join(urllib.parse.quote(s, safe="") for s in specs)


def _wait_verdict(page):
    page.wait_for_function("!document.getElementById('verdicts').textContent"
                           ".includes('computing')", timeout=180_000)


SLICE0 = ("k => (lastViews && lastViews.models[k] && lastViews.models[k].polar) ? "
          "lastViews.models[k].polar.values[0][90] : null")


def _wait_value(page, k: int, want: float, timeout_ms: int) -> float:
    """Seconds until model k's slice at θ_o = 0 is *want* (the page's own data)."""
    t0 = time.perf_counter()
    page.wait_for_function(f"Math.abs(({SLICE0})({k}) - {want!r}) < {1e-9 * want!r}",
                           timeout=timeout_ms, polling=10)
    return time.perf_counter() - t0


def test_page_reloads_a_saved_file(browser, server, tmp_path):
    p = tmp_path / "lam.binary"
    _lambert_binary(p, 0.3)
    page, errors = open_page(browser, _url(server, [str(p)]))
    _wait_value(page, 0, 0.3 / math.pi, 10_000)
    assert str(p) in page.locator("#model-file-0").text_content()
    latencies, draws = [], []
    for rho in (0.6, 0.7, 0.45):
        staged = tmp_path / "staged.binary"
        _lambert_binary(staged, rho)
        _wait_verdict(page)  # the latency of a reload, not of a verdict still computing
        polar0 = page.evaluate("drawnData('polar')")
        t0 = time.perf_counter()
        os.replace(staged, p)  # the save (an editor's atomic rename)
        page.wait_for_function(f"Math.abs(({SLICE0})(0) - {rho / math.pi!r}) < 1e-9",
                               timeout=20_000, polling=10)
        latencies.append(time.perf_counter() - t0)
        draws.append(page.evaluate("[drawMs, lobeMs].map(Math.round)"))
        # drawn: the polar plot's radii moved with ρ (the sphere is exposed to its
        # brightest pixel, so a Lambertian sphere looks the same at every ρ)
        assert page.evaluate("drawnData('polar')") != polar0
    print(f"reload latency (save → new values in the page): {latencies} s; drawing "
          f"[2-D views, 3-D lobe] in the page: {draws} ms")
    # Every save is drawn, and none waits as long as a frozen page would (10 s). The
    # one-second target is a speed claim, measured by benchmarks/bench_explorer_edit.py
    # on an idle machine, not here: CI shares 2 cores with the rest of the suite.
    assert max(latencies) <= FROZEN_S, latencies
    assert "reloaded" in page.locator("#model-file-0").text_content()
    # a broken edit: its error at the model's place, the last good drawing stays (the
    # exact one: a slow model's save is drawn as a draft first, then exact, then "ready")
    wait_ready(page)
    src_good = page.locator("#spheres img").first.get_attribute("src")
    p.write_bytes(b"not a MERL table")
    page.wait_for_function("document.getElementById('model-error-0').textContent"
                           ".includes('not reloaded')", timeout=5_000)
    err = page.locator("#model-error-0").text_content()
    assert str(p) in err and "header" in err
    assert str(p) in page.locator("#message").text_content()
    assert page.locator("#spheres img").count() == 1
    assert page.locator("#spheres img").first.get_attribute("src") == src_good
    assert abs(page.evaluate(f"({SLICE0})(0)") - 0.45 / math.pi) < 1e-12
    _lambert_binary(p, 0.2)  # fixed: the error clears, the new version drawn
    _wait_value(page, 0, 0.2 / math.pi, 5_000)
    page.wait_for_function("document.getElementById('model-error-0').textContent === ''",
                           timeout=5_000)
    assert errors == []
    page.close()


def test_page_opens_a_file_by_path(browser, server, tmp_path):
    p = tmp_path / "lam.binary"
    _lambert_binary(p, 0.35)
    page, errors = open_page(browser, _url(server, ["lambert"]))
    for path, says in ((str(tmp_path), "is a directory"), (str(tmp_path / "nope.brdf"),
                                                          "no such file")):
        page.fill("#open-path", path)
        page.click("#open-button")
        page.wait_for_function(f"document.getElementById('open-error').textContent"
                               f".includes({says!r})", timeout=5_000)
    assert page.locator("#model-list .model").count() == 1
    page.fill("#open-path", str(p))
    page.click("#open-button")
    page.wait_for_function("document.querySelectorAll('#model-list .model').length === 2",
                           timeout=5_000)
    _wait_value(page, 1, 0.35 / math.pi, 60_000)
    assert page.locator("#open-error").text_content() == ""
    assert page.locator("#spheres img").count() == 2
    # its parameter (MeasuredBRDF's lookup) comes from the server's declaration
    box = page.locator("#model-list .model").nth(1)
    assert box.locator("select[data-param='lookup']").count() == 1
    assert str(p) in urllib.parse.unquote(page.url)  # in the state: a link reopens it
    # Chromium logs the two refused opens (HTTP 400) as failed loads; nothing else
    assert [e for e in errors if "status of 400" not in e] == [] and len(errors) == 2
    page.close()


def test_page_brdf_file_live(browser, server, tmp_path):
    """A ``.brdf`` in the page: a saved edit of its default reloads it; a
    formula edit (its speed: benchmarks/bench_explorer_edit.py); a
    syntax error shows file:line:col and keeps the drawing."""
    pytest.importorskip("brdfkit.user.brdf_file")
    p = tmp_path / "lambert.brdf"
    p.write_text(LAMBERT_BRDF)
    page, errors = open_page(browser, _url(server, [str(p)]))
    _wait_value(page, 0, 0.5 / math.pi, 60_000)
    assert page.locator("#model-list input[data-param='rho']").count() >= 1
    t0 = time.perf_counter()
    p.write_text(LAMBERT_BRDF.replace("0 1 0.5", "0 1 0.8"))
    _wait_value(page, 0, 0.8 / math.pi, 20_000)
    latency = time.perf_counter() - t0
    assert latency <= FROZEN_S, latency  # the 1-s target: benchmarks/bench_explorer_edit.py
    t0 = time.perf_counter()
    p.write_text(LAMBERT_BRDF.replace("0 1 0.5", "0 1 0.8")
                 .replace("rho / 3.14", "0.5 * rho / 3.14"))
    _wait_value(page, 0, 0.4 / math.pi, 60_000)
    print(f".brdf reload: default edit {latency:.2f} s, formula edit "
          f"{time.perf_counter() - t0:.2f} s")
    p.write_text(LAMBERT_BRDF.replace("return vec3(", "return vec3(("))
    # no latency claim here: the views may wait behind a running verdict job and the
    # earlier versions' compiles (seconds each on a loaded CI machine)
    page.wait_for_function("document.getElementById('model-error-0').textContent"
                           ".includes('not reloaded')", timeout=60_000)
    assert re.search(re.escape(str(p)) + r":\d+:\d+", page.locator("#model-error-0").text_content())
    assert abs(page.evaluate(f"({SLICE0})(0)") - 0.4 / math.pi) < 1e-9
    assert errors == []
    page.close()


def test_page_brdf_bool_is_a_checkbox(browser, server, tmp_path):
    """A ``.brdf``'s ``bool NAME DEFAULT`` is a checkbox; ticking it redraws with the other
    branch of the formula (reference: the file's own closed form, ρ/π or 2ρ/π)."""
    pytest.importorskip("brdfkit.user.brdf_file")
    p = tmp_path / "doubled.brdf"
    p.write_text(LAMBERT_BRDF.replace("float rho 0 1 0.5", "float rho 0 1 0.5\nbool doubled 0")
                 .replace("vec3(rho", "vec3((doubled ? 2.0 : 1.0) * rho"))
    page, errors = open_page(browser, _url(server, [str(p)]))
    _wait_value(page, 0, 0.5 / math.pi, 60_000)
    box = page.locator("#model-list input[type=checkbox][data-param='doubled']")
    assert box.count() == 1 and not box.is_checked()
    box.check()
    _wait_value(page, 0, 1.0 / math.pi, 60_000)
    assert errors == []
    page.close()


def test_page_python_file_opened_by_path_and_live(browser, server, tmp_path):
    """A ``.py`` model: refused from a link, loaded once its path is typed into "open
    file", then reloaded when saved (a parameter-default edit)."""
    pytest.importorskip("brdfkit.user.python_file")
    py = tmp_path / "lam.py"
    py.write_text(LAMBERT_PY.format(scale=1.0, name="rho"))
    page, errors = open_page(browser, _url(server, [str(py)]))
    assert "a link cannot open it" in page.locator("#model-error-0").text_content()
    page.fill("#open-path", str(py))
    page.click("#open-button")
    _wait_value(page, 1, 0.5 / math.pi, 60_000)
    wait_ready(page)  # idle (a slow model's exact views follow its draft): one save timed
    t0 = time.perf_counter()
    py.write_text(LAMBERT_PY.format(scale=1.0, name="rho").replace('"rho", 0.5', '"rho", 0.9'))
    _wait_value(page, 1, 0.9 / math.pi, 60_000)
    # the .py loader compiles a file's formulas on every load (a new content: a new module);
    # the explorer draws the interpreted draft meanwhile (3.9-7.4 s before it)
    latency = time.perf_counter() - t0
    print(f".py reload (a default edit): {latency:.2f} s")
    # drawn, not frozen; its speed (a .py save drawn by the draft within 1 s) is measured by
    # benchmarks/bench_explorer_edit.py: a timed bound fails on a loaded CI machine
    assert latency <= FROZEN_S, latency
    assert errors == []
    page.close()


def test_explore_command_serves_file_specs(tmp_path):
    """``brdfkit explore A.binary B.binary``: the printed address holds both as the page's
    first models, and the server watches them (a save is one change for /api/changes)."""
    import subprocess
    import sys
    import urllib.request

    a, b = tmp_path / "a.binary", tmp_path / "b.binary"
    _lambert_binary(a, 0.3)
    _lambert_binary(b, 0.6)
    port = free_port()
    proc = subprocess.Popen([sys.executable, "-m", "brdfkit", "explore", "--no-browser",
                             "--port", str(port), "a.binary", str(b)], cwd=tmp_path,
                            stderr=subprocess.PIPE, text=True)
    try:
        line = proc.stderr.readline()
        url = line.split("serving on ", 1)[1].split(" ", 1)[0]
        # the short form (issue 20: a ~700-character state was printed before)
        short = url.split("#", 1)[1]
        assert short.startswith("m=") and len(url) < 60 + len(str(b)) * 2, url
        specs = [urllib.parse.unquote(s) for s in short[2:].split(",")]
        assert specs == ["a.binary", str(b)]
        state = {"models": [{"spec": s, "params": {}, "pump": None, "times": 1,
                             "visible": True} for s in specs]}
        base = f"http://127.0.0.1:{port}"
        wait_answering(base + "/api/changes", tries=100)
        req = urllib.request.Request(base + "/api/views", data=json.dumps(state).encode(),
                                     headers={"Content-Type": "application/json"})
        got = json.load(urllib.request.urlopen(req, timeout=120))
        np.testing.assert_allclose([_slice0(m) for m in got["models"]],
                                   [0.3 / math.pi, 0.6 / math.pi], rtol=1e-9)
        assert got["models"][0]["file"] == str(a)  # relative to the server's directory
        _lambert_binary(a, 0.4)
        ch = json.load(urllib.request.urlopen(base + f"/api/changes?since={got['version']}"))
        assert ch["changed"] == [str(a)]
    finally:
        proc.terminate()
        proc.wait(timeout=30)


# --------------------------------------------------------------------------- formula edits
# A formula edit builds a new kernel: the explorer draws the interpreted draft at once
# (the kernel's NumPy version, brdfkit._dual.numpy_version) and compiles in a background
# thread, then the page draws the compiled model (files module docstring). Each edit puts a
# random constant in the formula, so no disk cache holds its kernel.
PRINCIPLED = os.path.join(os.path.dirname(__file__), os.pardir, "benchmarks", "brdf",
                          "principled.brdf")
WALTER = os.path.join(os.path.dirname(__file__), "brdf_files", "walter_ggx.brdf")


def _scaled_principled(k: float) -> str:
    """principled.brdf with its result multiplied by *k* (f = k·f₁: the reference)."""
    with open(PRINCIPLED) as fh:
        text = fh.read()
    assert text.count("    return (INV_PI") == 1 and text.count("* dr;\n}") == 1
    return (text.replace("    return (INV_PI", f"    return {k!r} * ((INV_PI")
            .replace("* dr;\n}", "* dr);\n}"))


def _random_pairs(n, seed):
    rng = np.random.default_rng(seed)
    w = rng.normal(size=(2, n, 3))
    w[..., 2] = np.abs(w[..., 2]) + 1e-3
    return w / np.linalg.norm(w, axis=-1, keepdims=True)


def test_interpreted_model_equals_the_compiled_one(tmp_path):
    """The draft (``compiled=False``: kernel None, the NumPy version) gives the compiled
    model's values bit for bit on principled.brdf (anisotropic, 3 channels), Walter GGX and
    a Python file's model; the generic engines (albedo, check, the sphere) take it."""
    pytest.importorskip("brdfkit.user.brdf_file")
    from brdfkit.analysis import albedo, check
    from brdfkit.render import render_sphere
    from brdfkit.user import brdf_file, python_file
    from brdfkit.user.model import FormulaBRDF

    py = tmp_path / "lam.py"
    py.write_text(LAMBERT_PY.format(scale=1.25, name="rho"))
    wi, wo = _random_pairs(4000, 3)
    cases = [(brdf_file.definition, PRINCIPLED, {"roughness": 0.3, "anisotropic": 0.6,
                                                   "sheen": 0.4, "clearcoat": 0.7}),
             (brdf_file.definition, WALTER, {}),
             (python_file.definition, str(py), {"rho": 0.7})]
    for load, path, values in cases:
        compiled = FormulaBRDF(load(path), **values)
        draft = FormulaBRDF(load(path, compiled=False), **values)
        assert draft.definition.interpreted and draft.kernel is None, path
        assert compiled.kernel is not None and not compiled.definition.interpreted
        np.testing.assert_array_equal(draft.eval(wi, wo), compiled.eval(wi, wo), err_msg=path)
        theta = np.radians([5.0, 45.0, 80.0])
        np.testing.assert_allclose(albedo(draft, theta).albedo, albedo(compiled, theta).albedo,
                                   rtol=1e-15, atol=0)
        assert check(draft).to_dict() == check(compiled).to_dict()
        np.testing.assert_array_equal(render_sphere(draft, phi_l=0.5, size=48).radiance,
                                      render_sphere(compiled, phi_l=0.5, size=48).radiance)
        assert brdfkit.ModelSpec.of(draft).build().kernel is not None  # rebuilt compiled
    with pytest.raises(brdfkit.BrdfkitError, match="unit vectors"):
        draft.eval(np.array([0.0, 0.0, 2.0]), np.array([0.0, 0.0, 1.0]))


def _views(c, state):
    r = c.post("/api/views", json=state)
    assert r.status_code == 200, r.text
    return r.json()


def _join_compiles(c):
    import asyncio

    # the compiling threads are in the worker process: a job that joins them (in a thread
    # of its own: Playwright's sync API may hold an event loop in this one)
    job = c.app.state.worker.run("join", {"timeout": 300.0},
                                 deadline=time.monotonic() + 310.0, what="join")
    t = threading.Thread(target=asyncio.run, args=(job,))
    t.start()
    t.join()


def test_api_formula_edit_draft_then_compiled(tmp_path):
    """A formula edit: the first answer is the interpreted draft (``compiled`` false), the
    compile raises the file's version (``/api/changes`` names the file) and the next answer
    is the compiled model with the same values; a .py formula Numba cannot compile (an int
    constant beyond 64 bits) is drawn as a draft, then its error shown with the last
    compiled version drawn."""
    pytest.importorskip("brdfkit.user.python_file")
    from fastapi.testclient import TestClient

    from brdfkit.explorer.app import create_app

    rng = np.random.default_rng()
    p, py = tmp_path / "lam.brdf", tmp_path / "lam.py"
    k = 1.0 + float(rng.random())
    p.write_text(LAMBERT_BRDF.replace("rho / 3.14", f"{k!r} * rho / 3.14"))
    py.write_text(LAMBERT_PY.format(scale=k, name="rho"))
    c = TestClient(create_app(opened=[str(py)], allow_dirs=[tmp_path],
                              budget_s=TEST_BUDGET_S), **LOCAL)
    for f, rtol in ((p, 1e-6), (py, 1e-12)):
        state = {"models": [{"spec": str(f), "params": {"rho": 0.4}}]}
        first = _views(c, state)
        m = first["models"][0]
        assert m.get("compiled") is False and m["reload_error"] is None, (f, m.get("error"))
        np.testing.assert_allclose(_slice0(m), k * 0.4 / math.pi, rtol=rtol)
        _join_compiles(c)
        ch = c.get(f"/api/changes?since={first['version']}").json()
        assert ch["changed"] == [str(f)] and ch["version"] > first["version"]
        m2 = _views(c, state)["models"][0]
        assert m2["compiled"] is True and m2["digest"] == m["digest"]
        for got, want in ((m["polar"]["values"], m2["polar"]["values"]),
                          (m["curves"]["theta_h"], m2["curves"]["theta_h"]),
                          (m["albedo"]["values"], m2["albedo"]["values"])):
            np.testing.assert_allclose(got, want, rtol=1e-12, atol=0)
    bad = LAMBERT_PY.format(scale=k, name="rho").replace("PI = ", "BIG = 2 ** 70\nPI = ") \
        .replace("return ", "return BIG / BIG * 2.0 * ")
    py.write_text(bad)
    state = {"models": [{"spec": str(py), "params": {"rho": 0.4}}]}
    m = _views(c, state)["models"][0]
    assert m["compiled"] is False and m["reload_error"] is None
    np.testing.assert_allclose(_slice0(m), 2 * k * 0.4 / math.pi, rtol=1e-12)
    _join_compiles(c)
    m = _views(c, state)["models"][0]
    assert "does not compile" in m["reload_error"] and str(py) in m["reload_error"], m
    assert m["compiled"] is True
    np.testing.assert_allclose(_slice0(m), k * 0.4 / math.pi, rtol=1e-12)  # the last compiled


def _edit_and_time(page, k_index, path, text, want, staged):
    """Save *text* to *path* atomically; (seconds until the page draws *want* from the
    interpreted draft, the draft's polar values)."""
    staged.write_text(text)
    _wait_verdict(page)
    t0 = time.perf_counter()
    os.replace(staged, path)
    page.wait_for_function(
        f"(({SLICE0})({k_index}) !== null) && Math.abs(({SLICE0})({k_index}) - {want!r}) "
        f"< {1e-9 * want!r} && lastViews.models[{k_index}].compiled === false",
        timeout=20_000, polling=10)
    latency = time.perf_counter() - t0
    return latency, page.evaluate(f"lastViews.models[{k_index}].polar.values")


def _wait_compiled(page, k_index, draft_values, file_id):
    page.wait_for_function(f"lastViews.models[{k_index}].compiled === true",
                           timeout=300_000, polling=50)
    np.testing.assert_allclose(page.evaluate(f"lastViews.models[{k_index}].polar.values"),
                               draft_values, rtol=1e-12, atol=0)
    assert "interpreted" not in page.locator(file_id).text_content()


def test_page_formula_edit_drawn_by_the_draft(browser, server, tmp_path):
    """In Chromium: three saves of a new formula of principled.brdf (each × a random
    constant: f = k·f₁, f₁ the page's value before) and three of a .py model's formula
    (k·ρ/π) are drawn by the interpreted draft (its speed, ≤ 1 s:
    benchmarks/bench_explorer_edit.py); then the page draws
    the compiled model, the same values to 1e-12; a broken edit keeps the last good one."""
    pytest.importorskip("brdfkit.user.python_file")
    rng = np.random.default_rng()
    p = tmp_path / "principled.brdf"
    p.write_text(_scaled_principled(1.0))
    py = tmp_path / "lam.py"
    py.write_text(LAMBERT_PY.format(scale=1.0, name="rho"))
    page, errors = open_page(browser, _url(server, [str(p)]))
    page.wait_for_function(f"(({SLICE0})(0)) > 0", timeout=120_000)
    page.fill("#open-path", str(py))
    page.click("#open-button")
    _wait_value(page, 1, 0.5 / math.pi, 120_000)
    page.wait_for_function("lastViews.models.every(v => v.compiled === true)", timeout=300_000)
    base = page.evaluate(f"({SLICE0})(0)")
    measured = {".brdf": [], ".py": []}
    for _ in range(3):
        k = 1.0 + float(rng.random())
        lat, draft = _edit_and_time(page, 0, p, _scaled_principled(k), k * base,
                                    tmp_path / "staged.brdf")
        assert "interpreted (compiling" in page.locator("#model-file-0").text_content()
        measured[".brdf"].append(lat)
        _wait_compiled(page, 0, draft, "#model-file-0")
        k = 1.0 + float(rng.random())
        lat, draft = _edit_and_time(page, 1, py, LAMBERT_PY.format(scale=k, name="rho"),
                                    k * 0.5 / math.pi, tmp_path / "staged.py")
        measured[".py"].append(lat)
        _wait_compiled(page, 1, draft, "#model-file-1")
    print(f"formula edit → drawn (s): {measured}")
    # drawn by the draft, not frozen (the 1-s target: benchmarks/bench_explorer_edit.py)
    for kind, lat in measured.items():
        assert max(lat) <= FROZEN_S, (kind, lat)
    drawn = page.evaluate(f"({SLICE0})(0)")
    p.write_text(_scaled_principled(2.0).replace("return ", "return (", 1))  # broken
    page.wait_for_function("document.getElementById('model-error-0').textContent"
                           ".includes('not reloaded')", timeout=10_000)
    assert re.search(re.escape(str(p)) + r":\d+:\d+",
                     page.locator("#model-error-0").text_content())
    assert page.evaluate(f"({SLICE0})(0)") == drawn
    assert errors == []
    page.close()
