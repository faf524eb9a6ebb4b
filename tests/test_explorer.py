"""The explorer (issue 12): the browser-free views, the JSON API, and the page in a real
headless Chromium (Debian's ``chromium`` driven by Playwright with ``executable_path``).

Reference values and their sources:
- Lambert f_r = ρ/π in every direction and albedo a(θ) = ρ (closed forms).
- Phong's in-plane slice peaks at the mirror direction θ_o = +θ_i (R·V = 1 there, the
  definition of the lobe).
- Rec. 709 luminance weights (0.2126, 0.7152, 0.0722) (ITU-R BT.709).
- Ward's albedo diverges at grazing incidence like (cos θ_i)^−½ (Neumann et al. 1999, §3;
  the page must show what ``check`` says).
"""

from __future__ import annotations

import json
import math
import socket
import urllib.parse

import numpy as np
import pytest
from explorer_harness import open_page, wait_ready

import brdfkit
from brdfkit.explorer import views


# --------------------------------------------------------------------------- views
def test_views_of_lambert_closed_form():
    m = brdfkit.model("lambert", rho_d=0.6)
    p = views.polar(m, math.radians(30))
    np.testing.assert_allclose(p["values"][0], 0.6 / math.pi, rtol=1e-12)
    c = views.curves(m, math.radians(30))
    for key in ("theta_h", "theta_d"):
        np.testing.assert_allclose(c[key][0], 0.6 / math.pi, rtol=1e-12)
    a = views.albedo_curve(m)
    np.testing.assert_allclose(a["values"][0], 0.6, atol=views.ALBEDO_TOL)
    assert a["success"] and len(a["theta_deg"]) == 90
    lob = views.lobe(m, 0.3, cosine=True)
    r = np.sqrt(np.square(lob["x"]) + np.square(lob["y"]) + np.square(lob["z"]))
    assert abs(r.max() - 1.0) < 1e-4  # normalised; f·cos θ_o peaks at the pole


def test_views_phong_peak_and_channels():
    m = brdfkit.model("modified-phong", rho_d=0.0, rho_s=0.5, n=200)
    p = views.polar(m, math.radians(40), n=161)
    k = int(np.argmax(p["values"][0]))
    assert abs(p["theta_o_deg"][k] - 40.0) < 1.2  # the mirror direction, within one step
    rgb = brdfkit.model("lambert", rho_d=[0.1, 0.5, 0.9])
    y = views.polar(rgb, 0.2, mode="luminance")["values"]
    want = (0.2126 * 0.1 + 0.7152 * 0.5 + 0.0722 * 0.9) / math.pi
    np.testing.assert_allclose(y[0], want, rtol=1e-12)
    assert len(views.polar(rgb, 0.2, mode="rgb")["values"]) == 3


def test_image_views_are_pngs():
    m = brdfkit.model("modified-phong")
    png, info = views.sphere(m, phi_l=0.3, size=32)
    assert png[:8] == b"\x89PNG\r\n\x1a\n" and info["exposure"] > 0
    png, info = views.halfdiff(m, size=16)
    assert png[:8] == b"\x89PNG\r\n\x1a\n" and info["vmax"] > info["vmin"]


# --------------------------------------------------------------------------- the API
@pytest.fixture(scope="module")
def client():
    from fastapi.testclient import TestClient

    from brdfkit.explorer.app import create_app

    with TestClient(create_app(), base_url="http://127.0.0.1:8765") as c:
        yield c


def test_api_views_and_errors(client):
    state = {"models": [{"spec": "lambert", "params": {"rho_d": 0.5}},
                        {"spec": "modifed-phong"},
                        {"spec": "modified-phong", "params": {"n": -3}}],
             "theta_i": 20}
    r = client.post("/api/views", json=state)
    assert r.status_code == 200
    ms = r.json()["models"]
    np.testing.assert_allclose(ms[0]["polar"]["values"][0], 0.5 / math.pi, rtol=1e-12)
    assert "did you mean 'modified-phong'" in ms[1]["error"]
    assert "n" in ms[2]["error"] and "-3" in ms[2]["error"]
    r = client.post("/api/views", json={"models": [], "theta_i": 95})
    assert r.status_code == 400 and "theta_i must lie in [0, 89.5]" in r.json()["error"]
    r = client.post("/api/views", content=b"not json",
                    headers={"content-type": "application/json"})
    assert r.status_code == 400 and "must be JSON" in r.json()["error"]
    cat = client.get("/api/catalog").json()
    assert {m["name"] for m in cat["models"]} == set(brdfkit.MODELS)
    assert "merl:nickel" in cat["materials"]


def test_api_export_binary(client, tmp_path):
    r = client.post("/api/export/binary", json={"spec": "lambert", "params": {"rho_d": 0.5}})
    assert r.status_code == 200
    path = tmp_path / "x.binary"
    path.write_bytes(r.content)
    back = brdfkit.model(str(path))
    wi = np.array([math.sin(0.3), 0.0, math.cos(0.3)])
    wo = np.array([-math.sin(0.5), 0.0, math.cos(0.5)])
    np.testing.assert_allclose(back.eval(wi, wo), 0.5 / math.pi, rtol=1e-12)


# --------------------------------------------------------------------------- the browser
def _url(base, models, **extra):
    return base + "#" + urllib.parse.quote(json.dumps({"models": models, **extra}))


def _informative(png: bytes) -> bool:
    """A screenshot with content: more than a handful of distinct grey levels."""
    import io

    from matplotlib.image import imread

    img = imread(io.BytesIO(png))
    return float(np.std(img[..., :3])) > 0.02


def test_page_loads_and_updates(browser, server, tmp_path):
    page, errors = open_page(browser, _url(server, [{"spec": "modified-phong", "params": {}}]))
    assert errors == []
    sphere0 = page.locator("#spheres img").first.get_attribute("src")
    albedo0 = page.evaluate("drawnData('albedo')")
    n = page.locator("#model-list input[data-param='n']").first
    n.fill("200")
    n.dispatch_event("change")
    page.wait_for_function(f"document.querySelector('#spheres img').src !== {sphere0!r}",
                           timeout=120_000)
    wait_ready(page)
    albedo1 = page.evaluate("drawnData('albedo')")
    assert albedo1 != albedo0  # the albedo curve moved with n
    # "ready" once the views are exact (a slow model's move is drawn as a draft first,
    # then asked again without: tests/test_explorer_draft.py)
    assert page.evaluate("lastViews.models.every(v => v.draft === false && "
                         "v.albedo.theta_deg.length === 90)")
    # the state is in the URL: a new page at that URL restores n = 200
    shared = page.url
    assert "200" in urllib.parse.unquote(shared)
    page2, errors2 = open_page(browser, shared)
    assert page2.locator("#model-list input[data-param='n']").first.input_value() == "200"
    assert errors2 == [] and errors == []
    # every view has content
    for view in ("polar", "lobe", "curves", "albedo", "sphere", "halfdiff"):
        png = page.locator(f"#view-{view}").screenshot(path=str(tmp_path / f"{view}.png"))
        assert _informative(png), view
    page.close()
    page2.close()


def test_page_shows_a_diverging_verdict_and_bad_input(browser, server):
    page, errors = open_page(browser, _url(server, [{"spec": "ward", "params": {}}]))
    page.wait_for_function("document.getElementById('verdicts').textContent.includes('diverges')",
                           timeout=180_000)
    assert "ward" in page.locator("#verdicts").text_content()
    # a parameter out of bounds: a message in the page, the page still works
    m = page.locator("#model-list input[type=number]").first
    m.fill("-5")
    m.dispatch_event("change")
    page.wait_for_function("!document.getElementById('message').hidden", timeout=60_000)
    assert "-5" in page.locator("#message").text_content()
    assert errors == []
    page.close()


def test_page_fits_a_model_to_a_material(browser, server):
    """The fit button: the first model fitted to the chosen material, with progress, and the
    fitted model added to the page. Reference: a Lambertian fit to a Lambertian MERL table
    of our own making gives its ρ_d back (closed form of the table, written in the test)."""
    import tempfile
    from pathlib import Path

    from brdfkit.data.export import export_merl

    path = Path(tempfile.mkdtemp()) / "lambert03.binary"
    export_merl(brdfkit.model("lambert", rho_d=0.3), path)
    page, errors = open_page(browser, _url(server, [{"spec": str(path), "params": {}},
                                                {"spec": "lambert", "params": {}}]))
    assert page.locator("#fit-target").input_value() == str(path)
    page.click("#fit-button")
    page.wait_for_function("document.getElementById('fit-status').textContent"
                           ".startsWith('fitted in')", timeout=120_000)
    wait_ready(page)
    fitted = page.locator("#model-list .model").nth(2).locator("input[data-param='rho_d']")
    rho = [float(x) for x in fitted.first.input_value().split(",")]
    np.testing.assert_allclose(rho, 0.3, rtol=1e-3)
    # the fitted entry is named apart from the model it was fitted from (issue 20: a second
    # entry with the same name)
    names = page.locator("#model-list .name").all_text_contents()
    assert names[1] == "lambert" and names[2] == f"lambert fitted to {path}", names
    assert errors == []
    page.close()


def test_page_refuses_an_unknown_spec_with_a_message(browser, server):
    """issue 20: an unknown spec typed into "add" stayed in the list. Now it is not added and
    the message says why (with the catalog's near names); a known one is added."""
    page, errors = open_page(browser, _url(server, [{"spec": "lambert", "params": {}}]))
    page.fill("#add-spec", "modifed-phong")
    page.press("#add-spec", "Enter")
    assert page.locator("#model-list .model").count() == 1
    msg = page.locator("#message").text_content()
    assert "unknown model or material 'modifed-phong'" in msg and "modified-phong" in msg
    page.fill("#add-spec", "/tmp/x.binary")
    page.press("#add-spec", "Enter")
    assert page.locator("#model-list .model").count() == 1
    assert "open file" in page.locator("#message").text_content()
    page.fill("#add-spec", "merl:nickel@abc")
    page.press("#add-spec", "Enter")
    assert page.locator("#model-list .model").count() == 2
    wait_ready(page)
    assert errors == []
    page.close()


def test_explore_command_errors():
    """`brdfkit explore`: an unknown spec or a taken port is one line, exit 2, no server."""
    from click.testing import CliRunner

    from brdfkit.cli import main

    r = CliRunner().invoke(main, ["explore", "--no-browser", "nikel"])
    assert r.exit_code == 2 and "merl:nickel" in r.output
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        s.listen()
        port = s.getsockname()[1]
        r = CliRunner().invoke(main, ["explore", "--no-browser", "--port", str(port)])
    assert r.exit_code == 2 and f"cannot serve on 127.0.0.1:{port}" in r.output, r.output
    assert r.output.count("\n") == 1
