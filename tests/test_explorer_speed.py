"""The explorer's first views and slider moves made cheaper (issue 23): what changed in
behaviour, not the speed itself (benchmarks/bench_explorer.py, bench_explorer_start.py).

- the worker computes the page's first request (the command line's specs or the page's
  default model, at the page's default state) before its first job;
- ``brdfkit explore`` starts the worker before the web server's imports;
- a θ_i move reuses the lit sphere (it depends on the model and the light only);
- the views cross from the worker as JSON text, the same JSON as before.
"""

from __future__ import annotations

import json
import math
import re
from importlib import resources

import numpy as np
import pytest

from brdfkit._io import to_jsonable
from brdfkit.explorer import compute, views, worker
from brdfkit.explorer.compute import PAGE_MODEL, PAGE_STATE, Session, json_text, start_payload


def _page_default() -> dict:
    """The page's ``defaultState()`` read from static/app.js (the page's own source, not
    from compute.py)."""
    js = (resources.files("brdfkit.explorer") / "static" / "app.js").read_text(encoding="utf-8")
    body = js[js.index("function defaultState()"):]
    body = body[:body.index("\n}\n")]
    found = {"spec": re.search(r'spec:\s*"([^"]+)"', body).group(1)}
    for key in ("theta_i", "phi_i", "phi_l", "ambient"):
        found[key] = float(re.search(rf"\b{key}:\s*(-?[\d.]+)", body).group(1))
    found["mode"] = re.search(r'mode:\s*"(\w+)"', body).group(1)
    found["cosine"] = re.search(r"cosine:\s*(true|false)", body).group(1) == "true"
    return found


def test_the_warm_up_state_is_the_pages_first_state():
    page = _page_default()
    assert PAGE_MODEL == page["spec"]
    for key in ("theta_i", "phi_i", "phi_l"):  # the page sends degrees; the state is radians
        assert PAGE_STATE[key] == pytest.approx(math.radians(page[key]), abs=1e-12), key
    assert (PAGE_STATE["ambient"], PAGE_STATE["mode"], PAGE_STATE["cosine"]) == (
        page["ambient"], page["mode"], page["cosine"])


def test_start_payload_is_the_command_lines_specs_without_files(tmp_path):
    brdf = tmp_path / "m.brdf"
    brdf.write_text("analytic\n::begin shader\nfloat3 BRDF(float3 L, float3 V, float3 N, "
                    "float3 X, float3 Y) { return float3(1.0); }\n::end shader\n")
    p = start_payload(["lambert", str(brdf), "merl:nickel"])
    assert [e["spec"] for e in p["entries"]] == ["lambert", "merl:nickel"]
    # as the page's #m=SPEC link sends them: the session's cache key is the same
    assert p["entries"][0] == {"spec": "lambert", "params": {}, "pump": None, "times": 1}
    assert [e["spec"] for e in start_payload()["entries"]] == [PAGE_MODEL]
    assert [e["spec"] for e in start_payload([str(brdf)])["entries"]] == [PAGE_MODEL]


def test_the_warm_up_leaves_the_first_requests_model_views_cached(monkeypatch):
    """After the warm-up, the page's first request computes neither the albedo curve, the
    θ_h × θ_d image nor the sphere again (each would raise here)."""
    session = Session()
    payload = start_payload(["lambert"])
    worker._warm_up(session, payload)

    def computed_again(*a, **k):
        raise AssertionError("computed again: not warmed")
    for name in ("albedo_curve", "halfdiff", "sphere"):
        monkeypatch.setattr(views, name, computed_again)
    out = json.loads(session.model_views(payload["entries"][0], payload["state"]))
    assert "error" not in out, out
    assert out["spec"] == "lambert" and len(out["albedo"]["values"][0]) == 90


def test_a_warm_up_error_is_left_to_the_first_request():
    session = Session()
    bad = {"entries": [{"spec": "no-such-model", "params": {}}], "state": dict(PAGE_STATE)}
    worker._warm_up(session, bad)  # no exception: the page's request shows the error
    worker._warm_up(session, None)


def test_a_theta_i_move_reuses_the_sphere_a_light_move_does_not(monkeypatch):
    session = Session()
    entry = {"spec": "modified-phong", "params": {"rho_d": 0.3}}
    calls = []
    real = views.sphere

    def counted(m, **k):
        calls.append(k["phi_l"])
        return real(m, **k)
    monkeypatch.setattr(views, "sphere", counted)
    first = json.loads(session.model_views(entry, PAGE_STATE))
    moved = json.loads(session.model_views(entry, {**PAGE_STATE, "theta_i": 0.2}))
    assert len(calls) == 1 and moved["sphere"] == first["sphere"]
    assert moved["polar"] != first["polar"]  # the direction's views are new
    lit = json.loads(session.model_views(entry, {**PAGE_STATE, "phi_l": 1.0}))
    assert calls == [PAGE_STATE["phi_l"], 1.0] and lit["sphere"] != first["sphere"]
    ambient = json.loads(session.model_views(entry, {**PAGE_STATE, "ambient": 0.5}))
    assert len(calls) == 3 and ambient["sphere"] != first["sphere"]


def test_the_views_json_equals_the_views_functions():
    """The worker's JSON text against the view functions called here directly."""
    session = Session()
    entry = {"spec": "ward", "params": {"m": 0.2}}
    s = {**PAGE_STATE, "mode": "rgb", "cosine": True}
    out = json.loads(session.model_views(entry, s))
    m = compute.build_entry(entry)
    assert out["polar"] == views.polar(m, s["theta_i"], s["phi_i"], cosine=True, mode="rgb")
    assert out["curves"] == views.curves(m, s["theta_i"], s["phi_i"], cosine=True, mode="rgb")
    assert out["lobe"] == views.lobe(m, s["theta_i"], s["phi_i"])
    assert out["albedo"] == views.albedo_curve(m, mode="rgb")
    png, sph = views.sphere(m, phi_l=s["phi_l"])
    assert out["sphere"] == compute._b64(png) and out["sphere_info"] == sph
    assert out["name"] == m.name and out["params"] == to_jsonable(m.to_dict()["params"])


def test_json_text_is_the_json_of_to_jsonable():
    """NaN and ±inf become null and NumPy values plain numbers, as before (to_jsonable and
    the web server's compact encoding), on the fast path and the slow one."""
    fast = {"a": [1.0, 2.5], "b": "µ", "c": [[0.0]], "d": True, "e": None}
    slow = {"a": [1.0, float("nan")], "b": np.float64(2.0), "c": (np.int64(3), float("inf")),
            "d": np.array([1.0, -np.inf]), "e": np.bool_(True)}
    for obj in (fast, slow):
        want = json.dumps(to_jsonable(obj), ensure_ascii=False, allow_nan=False,
                          separators=(",", ":"))
        assert json_text(obj) == want
    assert json.loads(json_text(slow)) == {"a": [1.0, None], "b": 2.0, "c": [3, None],
                                           "d": [1.0, None], "e": True}


def test_explore_starts_the_worker_before_serving(monkeypatch):
    """``brdfkit explore`` starts the worker (warming the specs given) before the server,
    hands it to serve, and stops it when serve returns."""
    from click.testing import CliRunner

    from brdfkit.cli import explore_commands

    seen = {}

    def fake_serve(**kw):
        w = kw["worker"]
        seen.update(pid=w.pid, warm=w.warm, alive=w._proc.poll() is None)

    monkeypatch.setattr(explore_commands, "serve", fake_serve)
    r = CliRunner().invoke(explore_commands.explore_cmd, ["lambert", "--no-browser"])
    assert r.exit_code == 0, r.output
    assert seen["pid"] is not None and seen["alive"]
    assert [e["spec"] for e in seen["warm"]["entries"]] == ["lambert"]
