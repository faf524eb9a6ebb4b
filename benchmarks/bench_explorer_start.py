"""Explorer start: from ``brdfkit explore`` started to the page's first views (issue 23).

    .venv/bin/python benchmarks/bench_explorer_start.py [--runs 3] [--spec modified-phong]

Each run starts a new ``brdfkit explore --no-browser`` process (the disk caches warm: a
second run of the program, as a user sees it), polls ``GET /api/catalog`` until the
server answers, then sends the page's first ``POST /api/views`` (its default state: one
model, θ_i = 30°, Φ_L = 30°) and times, from the process start:

- **server**: the first answer of the server (imports, uvicorn up);
- **views**: the first ``/api/views`` answer (what the page waits for; target ≤ 2 s);
- **verdict**: the first ``/api/verdict`` answer after it (the page asks it next).

Run it with ``BRDFKIT_CACHE_DIR`` pointing to a fresh directory to see a cold disk cache
(the generated loops and Numba's kernels compiled again).
"""

from __future__ import annotations

import argparse
import json
import os
import socket
import statistics
import subprocess
import sys
import time
import urllib.error
import urllib.request

#: Seconds a run may take before it is called failed (a cold disk cache compiles for ~1 min).
TIMEOUT_S = 300.0
#: Seconds between polls of a server that is not up yet.
POLL_S = 0.02
TARGET_S = 2.0


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def _post(url: str, body: dict) -> dict:
    req = urllib.request.Request(url, data=json.dumps(body).encode(), method="POST",
                                 headers={"Content-Type": "application/json"})
    with urllib.request.urlopen(req, timeout=TIMEOUT_S) as r:
        return json.loads(r.read())


def one_run(spec: str, src: str | None = None) -> dict:
    port = _free_port()
    env = dict(os.environ, **({"PYTHONPATH": src} if src else {}))
    base = f"http://127.0.0.1:{port}"
    t0 = time.perf_counter()
    proc = subprocess.Popen([sys.executable, "-m", "brdfkit", "explore", "--no-browser",
                             "--port", str(port), "--budget", str(TIMEOUT_S)], env=env,
                            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    try:
        while True:
            if time.perf_counter() - t0 > TIMEOUT_S or proc.poll() is not None:
                raise RuntimeError("the explorer did not start")
            try:
                with urllib.request.urlopen(base + "/api/catalog", timeout=TIMEOUT_S):
                    break
            except (urllib.error.URLError, ConnectionError):
                time.sleep(POLL_S)
        t_server = time.perf_counter() - t0
        state = {"models": [{"spec": spec, "params": {}, "pump": None, "times": 1}],
                 "theta_i": 30, "phi_i": 0, "phi_l": 30, "ambient": 0,
                 "mode": "luminance", "cosine": False}
        out = _post(base + "/api/views", state)
        assert "error" not in out["models"][0], out["models"][0]
        t_views = time.perf_counter() - t0
        _post(base + "/api/verdict", state)
        t_verdict = time.perf_counter() - t0
    finally:
        proc.terminate()
        proc.wait(timeout=30)
    return {"server": t_server, "views": t_views, "verdict": t_verdict}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--runs", type=int, default=3)
    ap.add_argument("--spec", default="modified-phong", help="the page's first model")
    ap.add_argument("--baseline", metavar="SRC", help="a baseline's source directory (its "
                    "PYTHONPATH, e.g. a `git archive` of the base commit's src): each run "
                    "starts it and this source alternately; the ratio is per pair")
    a = ap.parse_args()
    print(f"cache dir: {os.environ.get('BRDFKIT_CACHE_DIR', '(default)')}")
    sides = {"this": os.environ.get("PYTHONPATH")}
    if a.baseline:
        sides = {"baseline": a.baseline, **sides}
        for src in sides.values():  # once each: the drivers of a new source stamp
            one_run(a.spec, src)
    runs = {side: [] for side in sides}
    for k in range(a.runs):
        for side, src in sides.items():
            r = one_run(a.spec, src)
            runs[side].append(r)
            print(f"run {k + 1} {side:8s}: server {r['server']:.2f} s, first views "
                  f"{r['views']:.2f} s, first verdict {r['verdict']:.2f} s", flush=True)
    for side, rs in runs.items():
        med = {k: statistics.median(r[k] for r in rs) for k in rs[0]}
        print(f"{side:8s} median of {a.runs}: server {med['server']:.2f} s, first views "
              f"{med['views']:.2f} s, first verdict {med['verdict']:.2f} s")
    if a.baseline:
        ratio = statistics.median(b["views"] / t["views"]
                                  for b, t in zip(runs["baseline"], runs["this"], strict=True))
        print(f"first views: baseline / this = {ratio:.2f} (median of the pairs)")
    print(f"target: first views <= {TARGET_S:g} s")


if __name__ == "__main__":
    main()
