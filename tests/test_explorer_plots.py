"""The explorer's plots (issue 20): Plotly.js figures served from the installed ``plotly``
package (no CDN), checked in a real headless Chromium (tests/explorer_harness.py).

What is checked, and against what:
- each view is a Plotly figure whose axis titles lie inside the figure's box and overlap no
  tick label, and no two tick labels of a figure overlap (the bounding boxes the browser
  laid out: the hand-drawn canvas cut off the curves' x-label and put the albedo's y-label
  over a tick);
- tick labels are round: per axis, the values (parsed from the text the browser shows;
  powers of ten on a log axis) are whole multiples of their spacing, and the spacing is 1, 2
  or 5 times a power of ten or, for an angle, a multiple of 5° or 15 (the canvas labelled 1.05
  "1.1" and put 23° and 68° on an angle axis);
- the θ_h × θ_d image has a colour bar per model, the lobe is a WebGL 3-D scene;
- the numbers drawn are the server's: the polar figure's radii are the views' values;
- in R, G, B mode the channels are drawn red, green and blue.
"""

from __future__ import annotations

import json
import math
import re
import urllib.parse
import urllib.request

import pytest
from explorer_harness import open_page, wait_ready

from brdfkit.errors import BrdfkitError

MODELS = [{"spec": "nielsen", "params": {}},
          {"spec": "modified-phong", "params": {"n": 50, "rho_d": [0.5, 0.3, 0.1]}}]
PLOTS = ("polar", "curves", "albedo", "lobe")

# Every figure of the page: its box, its axis titles and its tick labels grouped by axis
# (the class of the label's group: xtick, x2tick, ytick, angularaxistick, a colour bar's ...).
GEOMETRY = """() => {
  const rect = e => { const r = e.getBoundingClientRect();
                      return [r.left, r.top, r.right, r.bottom]; };
  const figs = [...document.querySelectorAll('.js-plotly-plot')];
  return figs.map(f => {
    // axis, figure and colour-bar titles; notes
    const titles = [...f.querySelectorAll('.infolayer text')].filter(t =>
      t.textContent.trim() && /title$|annotation-text/.test(t.getAttribute('class') || ''))
      .map(t => ({ text: t.textContent, cls: t.getAttribute('class'), rect: rect(t) }));
    const ticks = {};
    f.querySelectorAll('g[class$="tick"] > text').forEach(t => {
      if (!t.textContent.trim()) return;
      const axis = t.parentNode.getAttribute('class');
      (ticks[axis] = ticks[axis] || []).push({ text: t.textContent, rect: rect(t) });
    });
    return { id: f.id || f.parentNode.id, box: rect(f), titles, ticks,
             type: f.data ? f.data.map(d => d.type) : [] };
  });
}"""


def _url(base, models, **extra):
    return base + "#" + urllib.parse.quote(json.dumps({"models": models, **extra}))


@pytest.fixture(scope="module")
def page(browser, server):
    page, errors = open_page(browser, _url(server, MODELS, theta_i=40))
    page.wait_for_function("lobeMs !== null", timeout=60_000)  # the lobe is drawn after
    yield page, errors
    page.close()


def _overlap(a, b, slack=0.5) -> bool:
    return (min(a[2], b[2]) - max(a[0], b[0]) > slack and
            min(a[3], b[3]) - max(a[1], b[1]) > slack)


def _inside(r, box, slack=1.0) -> bool:
    return (r[0] >= box[0] - slack and r[1] >= box[1] - slack and r[2] <= box[2] + slack
            and r[3] <= box[3] + slack)


def _value(text: str) -> float:
    """A tick label's number: "45°", "−0.5", "0.25", "10−3" (10 with a superscript −3)."""
    t = text.replace("\u2212", "-").replace("°", "").replace("\u200b", "").strip()
    m = re.fullmatch(r"10(-?\d+)", t)
    if m and t != "10":
        return 10.0 ** int(m.group(1))
    return float(t)


def _round_axis(texts: list[str]) -> str | None:
    """None when the labels are round (module docstring), else why not."""
    vals = sorted({_value(t) for t in texts})
    if len(vals) < 2:
        return None
    angle = any("°" in t for t in texts)
    positive = all(v > 0 for v in vals)
    if positive and all(abs(math.log10(v) - round(math.log10(v))) < 1e-9 for v in vals):
        vals = [round(math.log10(v)) for v in vals]  # a log axis: powers of ten
    step = min(b - a for a, b in zip(vals, vals[1:], strict=False))
    mant = step / 10 ** math.floor(math.log10(step))
    ok_step = (any(abs(mant - m) < 1e-9 for m in (1, 2, 5, 10))
               or abs(step / 15 - round(step / 15)) < 1e-9  # 15°, 30°, 45°: an angle
               or (angle and abs(step / 5 - round(step / 5)) < 1e-9))
    if not ok_step:
        return f"spacing {step:g} of {texts}"
    off = [v for v in vals if abs(v / step - round(v / step)) > 1e-6]
    return f"{off} not multiples of {step:g} in {texts}" if off else None


def test_plotly_is_served_from_the_package_not_a_cdn(server):
    from importlib import resources

    with urllib.request.urlopen(server + "static/plotly.min.js") as r:
        body = r.read()
    ref = (resources.files("plotly") / "package_data" / "plotly.min.js").read_bytes()
    assert body == ref
    html = urllib.request.urlopen(server).read().decode()
    srcs = re.findall(r'<script src="([^"]+)"', html)
    assert "/static/plotly.min.js" in srcs and all(s.startswith("/static/") for s in srcs)


def test_a_missing_plotly_is_one_line_naming_the_package(monkeypatch):
    from brdfkit.explorer import app

    def files(name):
        raise ModuleNotFoundError(f"No module named {name!r}")

    monkeypatch.setattr(app.resources, "files", files)
    with pytest.raises(BrdfkitError, match=r"'plotly' package.*pip install plotly$") as e:
        app.plotly_js()
    assert "\n" not in str(e.value)


def test_every_view_is_a_plotly_figure(page):
    page, errors = page
    figs = {f["id"]: f for f in page.evaluate(GEOMETRY)}
    for view in PLOTS:
        assert view in figs, view
    assert {"scatterpolar"} <= set(figs["polar"]["type"])
    assert set(figs["curves"]["type"]) == {"scatter"}
    # the lobe: a WebGL 3-D scene of one surface per model and the light's direction
    assert figs["lobe"]["type"] == ["surface", "surface", "scatter3d"]
    assert page.locator("#lobe .gl-container div[id^='scene'] canvas").count() >= 1
    # its render loop (~20% of a core with software WebGL) runs only under the pointer
    assert page.evaluate("glplotOf(document.getElementById('lobe'))._stopped") is True
    page.hover("#lobe")
    page.wait_for_function("glplotOf(document.getElementById('lobe'))._stopped === false")
    page.mouse.move(0, 0)
    page.wait_for_function("glplotOf(document.getElementById('lobe'))._stopped === true")
    # one θ_h × θ_d figure per model, each an image with a colour bar
    assert page.locator("#halfdiffs .js-plotly-plot").count() == len(MODELS)
    assert page.locator("#halfdiffs .colorbar").count() == len(MODELS)
    assert errors == []


def test_axis_titles_are_inside_the_figure_and_clear_of_the_ticks(page):
    page, _ = page
    for f in page.evaluate(GEOMETRY):
        if f["id"] == "lobe":
            continue  # WebGL: its axis labels are drawn in the canvas
        names = [t["text"] for t in f["titles"]]
        assert len(f["titles"]) >= 1, f["id"]
        labels = [t for ts in f["ticks"].values() for t in ts]
        for t in f["titles"]:
            assert _inside(t["rect"], f["box"]), (f["id"], t["text"], t["rect"], f["box"])
            for lab in labels:
                assert not _overlap(t["rect"], lab["rect"]), (f["id"], t["text"], lab["text"])
        for k, a in enumerate(labels):
            assert _inside(a["rect"], f["box"]), (f["id"], a["text"])
            for b in labels[k + 1:]:
                assert not _overlap(a["rect"], b["rect"]), (f["id"], a["text"], b["text"])
        if f["id"] in ("curves", "albedo"):  # x and y titled
            assert any("θ" in n for n in names) and len(names) >= 2, names


def test_tick_labels_are_round(page):
    page, _ = page
    seen = 0
    for f in page.evaluate(GEOMETRY):
        for axis, ticks in f["ticks"].items():
            why = _round_axis([t["text"] for t in ticks])
            assert why is None, (f["id"], axis, why)
            seen += 1
    assert seen >= 12  # polar 2, curves 4, albedo 2, θ_h × θ_d 3 per model


def test_round_tick_check_refuses_the_old_canvas_labels():
    # the hand-drawn axes' labels (docs/explorer before issue 20): 0, 23, 45, 68, 90 on
    # the albedo's θ_i axis and 0.0, 0.26, 0.53, 0.79, 1.1 on its y axis
    assert _round_axis(["0", "23", "45", "68", "90°"]) is not None
    assert _round_axis(["0.0", "0.26", "0.53", "0.79", "1.1"]) is not None
    assert _round_axis(["0°", "15°", "30°", "45°"]) is None
    assert _round_axis(["10\u200b\u22124\u200b", "10\u22123", "0.01", "0.1", "1"]) is None
    assert _round_axis(["0", "0.2", "0.4", "0.6"]) is None


def test_the_drawn_numbers_are_the_servers(page):
    page, _ = page
    drawn = json.loads(page.evaluate("drawnData('polar')"))
    served = page.evaluate("lastViews.models.map(v => v.polar.values[0])")
    assert [t[2] for t in drawn[:len(MODELS)]] == served


def test_rgb_channels_are_red_green_blue_and_a_move_is_timed(page):
    page, errors = page
    page.select_option("#mode", "rgb")
    page.wait_for_function("lastViews && lastViews.models[1].curves.theta_h.length === 3",
                           timeout=120_000)
    wait_ready(page)
    colours = page.evaluate("document.getElementById('albedo').data"
                            ".map(t => [t.name, t.line.color, t.line.dash])")
    # modified-phong's (coloured) R, G, B curves: red, green and blue
    rgb = [c for c in colours if c[0].startswith("modified-phong ")]
    assert [c[1] for c in rgb] == ["#d62728", "#2ca02c", "#1f77b4"]
    # one light move: the page's drawing time (printed for the record)
    page.evaluate("lobeMs = null; const e = document.getElementById('theta_i'); "
                  "e.value = 41; e.dispatchEvent(new Event('input'))")
    page.wait_for_function("lobeMs !== null && lastViews.models[0].lobe.wi[2] < "
                           f"{math.cos(math.radians(40.5))}", timeout=120_000)
    ms = page.evaluate("[drawMs, lobeMs]")
    print(f"drawing one move in the page: 2-D views {ms[0]:.0f} ms, 3-D lobe {ms[1]:.0f} ms")
    assert errors == []
