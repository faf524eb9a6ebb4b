"""
The report of ``brdfkit reproduce``: one document model, two renderers (HTML, Markdown)
======================================================================================

:func:`document` arranges a run's results (:class:`brdfkit.report.reproduce.Run`) into
papers → sections → figures, tables and claims, plus the summary and the list of printed
formulas found wrong; :func:`render_html` and :func:`render_markdown` print that same
structure, so the two cannot disagree. :func:`write_report` writes ``index.html`` (static,
self-contained: figures inline as PNG data, no script, no network), ``report.md`` (figures
under ``figures/``), ``claims.json`` (every claim record with its numbers and verdict, and
every failed item) and the figures, each file atomically.
"""

from __future__ import annotations

import base64
import html
import json
import re
from collections import Counter

from brdfkit.report.claim_record import VERDICTS, json_ready
from brdfkit.report.reproduce_items import PAPERS

__all__ = ["document", "render_html", "render_markdown", "write_report"]

_BADGE = {"confirmed": "ok", "confirmed with a correction": "fix", "refuted": "bad",
          "undetermined": "und", "failed": "bad"}


def _anchor(kind: str, name: str) -> str:
    return f"{kind}-{re.sub(r'[^a-z0-9-]+', '-', name.lower())}"


def _section_key(title: str, first: int) -> tuple:
    m = re.search(r"§(\d+)", title)
    return (int(m.group(1)) if m else 1000, first)


def document(run, *, ctx, only=None) -> dict:
    """The report's structure (module docstring) from the run's results."""
    from brdfkit import __version__
    from brdfkit.report.reproduce import code_version

    papers = []
    for key, paper in PAPERS.items():
        rs = [r for r in run.results if r["paper"] == key]
        if not rs:
            continue
        order: dict[str, int] = {}
        for i, r in enumerate(rs):
            order.setdefault(r["section"], i)
        sections = [{"title": s, "anchor": _anchor("sec", f"{key}-{s}"),
                     "items": [r for r in rs if r["section"] == s]}
                    for s in sorted(order, key=lambda s: _section_key(s, order[s]))]
        claims = [r for r in rs if r["kind"] == "claim"]
        verdicts = Counter(r["payload"]["verdict"] if r["status"] == "ok" else "failed"
                           for r in claims)
        kinds = Counter(r["kind"] for r in rs)
        papers.append({"key": key, "short": paper.short, "title": paper.title,
                       "citation": paper.citation, "anchor": _anchor("paper", key),
                       "sections": sections, "verdicts": verdicts, "n_claims": len(claims),
                       "n_figures": kinds["figure"], "n_tables": kinds["table"],
                       "n_failed": sum(1 for r in rs if r["status"] == "failed")})
    corrections = [r for r in run.results if r["kind"] == "claim" and r["status"] == "ok"
                   and r["payload"]["correction"]]
    return {"title": "brdfkit reproduce: Lewis 1993, Neumann et al. 1999, Nielsen et al. "
                     "2015, recomputed",
            "version": __version__, "code_version": code_version(),
            "settings": "full (refitted, paper quality)" if ctx.full else
            "preview (the shipped fitting-study batches re-scored, preview render settings)",
            "study_dir": ctx.study_dir, "seconds": run.seconds, "cached": run.cached,
            "n_items": len(run.results), "failed": run.failed, "papers": papers,
            "corrections": corrections, "only": only}


# --------------------------------------------------------------------------- HTML
_CSS = """
body{font:15px/1.5 system-ui,-apple-system,Segoe UI,Helvetica,Arial,sans-serif;margin:0;
color:#1b1b1b;background:#fafafa}
main{max-width:1100px;margin:0 auto;padding:1.5rem 2rem 4rem;background:#fff}
h1{font-size:1.6rem;margin:.2rem 0 .6rem}h2{border-bottom:2px solid #ddd;margin-top:2.5rem}
h3{margin-top:2rem;color:#333}h4{margin:.3rem 0}
nav ol{columns:2;font-size:.92rem}figure{margin:1.2rem 0;padding:.6rem;border:1px solid #e3e3e3}
figure img{max-width:100%;height:auto;display:block;margin:0 auto}
figcaption{font-size:.9rem;color:#333}code{background:#f2f2f2;padding:0 .25em;border-radius:3px}
table{border-collapse:collapse;font-size:.82rem;margin:.6rem 0;display:block;overflow-x:auto}
th,td{border:1px solid #ddd;padding:.2rem .45rem;text-align:left;vertical-align:top}
th{background:#f4f4f4}.claim{border-left:5px solid #999;padding:.4rem .9rem;margin:1rem 0;
background:#fcfcfc}.claim.ok{border-color:#2e7d32}.claim.fix{border-color:#ef8f00}
.claim.bad{border-color:#c62828}.claim.und{border-color:#777}
.badge{display:inline-block;padding:0 .5em;border-radius:3px;color:#fff;font-size:.85rem;
font-weight:600}.badge.ok{background:#2e7d32}.badge.fix{background:#c77700}
.badge.bad{background:#c62828}.badge.und{background:#666}
.failed{border:2px solid #c62828;padding:.5rem;background:#fff5f5}
.meta{color:#555;font-size:.9rem}details{margin:.3rem 0}pre{white-space:pre-wrap;
font-size:.78rem;background:#f6f6f6;padding:.5rem}a.self{color:#999;text-decoration:none}
"""


def _e(text) -> str:
    return html.escape(str(text), quote=True)


def _html_table(header, rows) -> str:
    head = "".join(f"<th>{_e(h)}</th>" for h in header)
    body = "".join("<tr>" + "".join(f"<td>{_e(c)}</td>" for c in row) + "</tr>" for row in rows)
    return f"<table><thead><tr>{head}</tr></thead><tbody>{body}</tbody></table>"


def _html_item(r: dict, pngs: dict) -> str:
    key = f"{r['kind']}:{r['name']}"
    aid = _anchor(r["kind"], r["name"])
    if r["status"] == "failed":
        return (f'<div class="failed" id="{aid}"><strong>{_e(r["kind"])} {_e(r["name"])}: '
                f'failed</strong> — <code>{_e(r["error"])}</code></div>')
    p = r["payload"]
    if r["kind"] == "figure":
        data = base64.b64encode(pngs[key]).decode("ascii") if pngs.get(key) else ""
        return (f'<figure id="{aid}"><img src="data:image/png;base64,{data}" alt="'
                f'{_e(r["name"] + ": " + p["caption"])}"><figcaption><strong>{_e(r["name"])}'
                f'</strong> — <em>paper:</em> {_e(p["caption"])}<br><em>Chosen where the paper '
                f'gives no value:</em> {_e(p["chosen"])}<br><em>Remake:</em> '
                f'<code>{_e(p["command"])}</code></figcaption></figure>')
    if r["kind"] == "table":
        notes = "".join(f"<li>{_e(n)}</li>" for n in p["notes"])
        return (f'<section id="{aid}"><h4>{_e(r["title"])}</h4>'
                + _html_table(p["header"], p["rows"])
                + (f"<details><summary>Notes ({len(p['notes'])})</summary><ul>{notes}</ul>"
                   "</details>" if notes else "")
                + f'<p class="meta">Remake: <code>{_e(p["command"])}</code></p></section>')
    v = p["verdict"]
    corr = (f"<p><strong>Correction:</strong> {_e(p['correction'])}</p>"
            if p["correction"] else "")
    tol = ("" if p["tolerance"] is None else
           f' <span class="meta">(tolerance {p["tolerance"]:g})</span>')
    return (f'<article class="claim {_BADGE[v]}" id="{aid}"><h4><a class="self" href="#{aid}">'
            f'#</a> {_e(p["location"])} <span class="badge {_BADGE[v]}">{_e(v)}</span></h4>'
            f'<p><em>The paper:</em> {_e(p["statement"])}</p><p><em>Computed:</em> '
            f'{_e(p["method"])}{tol}</p><p><em>Result:</em> {_e(p["reason"])}</p>{corr}'
            f'<details><summary>numbers ({_e(p["id"])}, {r["seconds"]:.1f} s'
            f'{", cached" if r.get("cached") else ""})</summary><pre>'
            f'{_e(json.dumps(p["numbers"], ensure_ascii=False, indent=1))}</pre></details>'
            "</article>")


_SUMMARY_HEAD = ("paper", "figures", "tables", "claims", *(f"claims {v}" for v in VERDICTS),
                 "items failed")


def _summary_cells(p: dict) -> list:
    return [p["n_figures"], p["n_tables"], p["n_claims"],
            *(p["verdicts"].get(v, 0) for v in VERDICTS), p["n_failed"]]


def render_html(doc: dict, pngs: dict) -> str:
    """The static page (no script, no external resource)."""
    toc = []
    body = []
    for p in doc["papers"]:
        counts = ", ".join(f"{p['verdicts'][v]} {v}" for v in (*VERDICTS, "failed")
                           if p["verdicts"].get(v))
        sub = "".join(f'<li><a href="#{s["anchor"]}">{_e(s["title"])}</a></li>'
                      for s in p["sections"])
        toc.append(f'<li><a href="#{p["anchor"]}">{_e(p["short"])}: {_e(p["title"])}</a>'
                   f"<ul>{sub}</ul></li>")
        body.append(f'<section id="{p["anchor"]}"><h2>{_e(p["short"])}: {_e(p["title"])}</h2>'
                    f'<p class="meta">{_e(p["citation"])}. Claims: {p["n_claims"]}'
                    + (f" ({_e(counts)})" if counts else "") + ".</p>")
        for s in p["sections"]:
            body.append(f'<section id="{s["anchor"]}"><h3>{_e(s["title"])}</h3>'
                        + "".join(_html_item(r, pngs) for r in s["items"]) + "</section>")
        body.append("</section>")
    fixes = "".join(f'<li><a href="#{_anchor("claim", r["name"])}">{_e(r["payload"]["location"])}'
                    f"</a> ({_e(PAPERS[r['paper']].short)}): {_e(r['payload']['correction'])}"
                    "</li>" for r in doc["corrections"])
    failed = "".join(f'<li><a href="#{_anchor(r["kind"], r["name"])}">{_e(r["kind"])} '
                     f'{_e(r["name"])}</a>: <code>{_e(r["error"])}</code></li>'
                     for r in doc["failed"])
    summary = "".join(
        f'<tr><td><a href="#{p["anchor"]}">{_e(p["short"])}</a></td>'
        + "".join(f"<td>{c}</td>" for c in _summary_cells(p)) + "</tr>"
        for p in doc["papers"])
    head = "".join(f"<th>{_e(v)}</th>" for v in _SUMMARY_HEAD)
    return (
        '<!DOCTYPE html><html lang="en"><head><meta charset="utf-8">'
        '<meta name="viewport" content="width=device-width,initial-scale=1">'
        f"<title>{_e(doc['title'])}</title><style>{_CSS}</style></head><body><main>"
        f"<h1>{_e(doc['title'])}</h1>"
        f'<p class="meta">brdfkit {_e(doc["version"])}, code {_e(doc["code_version"])}; '
        f'{_e(doc["settings"])}; study batches <code>{_e(doc["study_dir"])}</code>; '
        f'{doc["n_items"]} items ({doc["cached"]} from the cache) in {doc["seconds"]:.1f} s.'
        "</p><p>Every figure below was computed by brdfkit in this run; every verdict comes "
        "from a claim record (the paper, where, what it says, how it is computed, the "
        "tolerance) whose rule was applied to the numbers computed now, never typed by "
        "hand.</p>"
        f"<table><thead><tr>{head}</tr></thead><tbody>{summary}</tbody></table>"
        + (f'<section id="failed" class="failed"><h2>Failed items</h2><ul>{failed}</ul>'
           "</section>" if failed else "")
        + (f'<section id="corrections"><h2>Printed formulas and statements corrected</h2>'
           f"<ul>{fixes}</ul></section>" if fixes else "")
        + f'<nav id="contents"><h2>Contents</h2><ol>{"".join(toc)}</ol></nav>'
        + "".join(body) + "</main></body></html>\n")


# --------------------------------------------------------------------------- Markdown
def _md(text) -> str:
    return str(text).replace("|", "\\|").replace("\n", " ")


def _md_item(r: dict) -> list[str]:
    if r["status"] == "failed":
        return [f"> **{r['kind']} {r['name']}: failed** — `{_md(r['error'])}`", ""]
    p = r["payload"]
    if r["kind"] == "figure":
        return [f"![{_md(r['name'] + ': ' + p['caption'])}](figures/{r['name']}.png)", "",
                f"**{r['name']}** — *paper:* {p['caption']} *Chosen:* {p['chosen']} "
                f"*Remake:* `{p['command']}`", ""]
    if r["kind"] == "table":
        out = [f"**{r['title']}** (remake: `{p['command']}`)", "",
               "| " + " | ".join(_md(h) for h in p["header"]) + " |",
               "|" + "---|" * len(p["header"])]
        out += ["| " + " | ".join(_md(c) for c in row) + " |" for row in p["rows"]]
        return out + [""] + [f"- {_md(n)}" for n in p["notes"]] + [""]
    tol = "" if p["tolerance"] is None else f" (tolerance {p['tolerance']:g})"
    out = [f"#### {p['location']} — **{p['verdict']}** <a id=\"{_anchor('claim', r['name'])}\">"
           "</a>", "", f"- *The paper:* {p['statement']}",
           f"- *Computed:* {p['method']}{tol}", f"- *Result:* {p['reason']}"]
    if p["correction"]:
        out.append(f"- *Correction:* {p['correction']}")
    return out + [f"- *Record:* `{p['id']}` (numbers in `claims.json`)", ""]


def render_markdown(doc: dict) -> str:
    """The same document as Markdown (figures as ``figures/NAME.png``)."""
    L = [f"# {doc['title']}", "",
         f"brdfkit {doc['version']}, code {doc['code_version']}; {doc['settings']}; "
         f"{doc['n_items']} items. Generated by `brdfkit reproduce`: every verdict is "
         "computed from a claim record, never typed by hand.", "",
         "| " + " | ".join(_SUMMARY_HEAD) + " |", "|" + "---|" * len(_SUMMARY_HEAD)]
    L += ["| " + p["short"] + " | " + " | ".join(str(c) for c in _summary_cells(p)) + " |"
          for p in doc["papers"]]
    L.append("")
    if doc["failed"]:
        L += ["## Failed items", ""] + [f"- {r['kind']} {r['name']}: `{_md(r['error'])}`"
                                        for r in doc["failed"]] + [""]
    if doc["corrections"]:
        L += ["## Printed formulas and statements corrected", ""]
        L += [f"- {PAPERS[r['paper']].short}, {r['payload']['location']}: "
              f"{r['payload']['correction']}" for r in doc["corrections"]] + [""]
    for p in doc["papers"]:
        L += [f"## {p['short']}: {p['title']}", "", f"{p['citation']}.", ""]
        for s in p["sections"]:
            L += [f"### {s['title']}", ""]
            for r in s["items"]:
                L += _md_item(r)
    return "\n".join(L) + "\n"


# --------------------------------------------------------------------------- files
def write_report(run, *, pngs: dict, ctx, only=None) -> list[str]:
    """Write the report's files under ``run.out``; return their paths."""
    import os

    from brdfkit import _io

    doc = document(run, ctx=ctx, only=only)
    written = []
    fig_dir = os.path.join(run.out, "figures")
    os.makedirs(fig_dir, exist_ok=True)
    for r in run.results:
        png = pngs.get(f"{r['kind']}:{r['name']}")
        if r["kind"] == "figure" and png is not None:
            path = os.path.join(fig_dir, f"{r['name']}.png")
            written.append(_io.write_atomic(path, lambda fh, b=png: fh.write(b), option="--out"))
    claims = {"brdfkit": doc["version"], "code_version": doc["code_version"],
              "settings": doc["settings"], "study_dir": doc["study_dir"],
              "claims": [r["payload"] for r in run.results
                         if r["kind"] == "claim" and r["status"] == "ok"],
              "failed": [{k: r[k] for k in ("kind", "name", "paper", "error")}
                         for r in run.failed]}
    texts = {"claims.json": json.dumps(json_ready(claims), ensure_ascii=False, indent=1),
             "report.md": render_markdown(doc), "index.html": render_html(doc, pngs)}
    for name, text in texts.items():
        path = os.path.join(run.out, name)
        written.append(_io.write_atomic(path, lambda fh, t=text: fh.write(t.encode("utf-8")),
                                        option="--out"))
    return written
