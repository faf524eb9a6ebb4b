// brdfkit explorer: plain JavaScript over the JSON API of brdfkit.explorer.app; the plots
// are drawn by plots.js (Plotly.js).
// The state lives in the URL hash (a shared link reopens the same view).
// Models from files (.brdf, .py[:NAME], MERL .binary) carry their parameter declarations in
// each /api/views answer; the page polls /api/changes and redraws when a shown file changes.
"use strict";

let catalog = null;
let state = null;
let lastViews = null;
let pending = null;
let inflight = false;
// spec -> {file, digest, decl, reload_error, reloaded, compiled}: what the server said of a
// file model (compiled false: its interpreted draft, drawn while the server compiles it)
const fileInfo = {};
// Watched files are polled, not pushed (server-sent events): a poll every 100 ms (a stat
// per shown file, ~1 ms a request) keeps a saved edit well under a second away (poll +
// reload + redraw: a 33 MB MERL table reads in ~0.1-0.2 s), holds no connection open,
// needs no server thread and survives a server restart.
const POLL_MS = 100;
let since = null;  // the watch version the drawn views were built at
let drawMs = null;  // the time the last drawAll took in the page (ms; the lobe: lobeMs)

function defaultState() {
  return { models: [{ spec: "modified-phong", params: {}, pump: null, times: 1, visible: true }],
           theta_i: 30, phi_i: 0, phi_l: 30, ambient: 0, mode: "luminance", log: true,
           cosine: false, solo: null };
}

function readHash() {
  if (!location.hash || location.hash.length < 2) return defaultState();
  // the short form the command line prints: #m=SPEC,SPEC (each percent-encoded)
  if (location.hash.startsWith("#m=")) {
    const specs = location.hash.slice(3).split(",").filter(s => s).map(decodeURIComponent);
    return Object.assign(defaultState(), {
      models: specs.map(spec => ({ spec, params: {}, pump: null, times: 1, visible: true })) });
  }
  try {
    return Object.assign(defaultState(), JSON.parse(decodeURIComponent(location.hash.slice(1))));
  } catch (e) {
    showMessage("the link's state could not be read (" + e.message + "); showing the defaults");
    return defaultState();
  }
}

function writeHash() {
  history.replaceState(null, "", "#" + encodeURIComponent(JSON.stringify(state)));
}

function showMessage(text) {
  const el = document.getElementById("message");
  if (!text) { el.hidden = true; el.textContent = ""; return; }
  el.hidden = false;
  el.textContent = text;
}

async function api(path, body) {
  const res = await fetch(path, body === undefined ? {} : {
    method: "POST", headers: { "Content-Type": "application/json" }, body: JSON.stringify(body) });
  const data = await res.json();
  if (!res.ok) throw new Error(data.error || ("HTTP " + res.status));
  return data;
}

// ------------------------------------------------------------------ model list and controls
function declOf(spec) {
  if (!catalog) return null;
  const key = spec.trim().toLowerCase().replace(/_/g, "-");
  return catalog.models.find(m => m.name === key || (m.aliases || []).includes(key)) || null;
}

function declFor(entry) {
  const info = fileInfo[entry.spec];
  return info && info.decl ? info.decl : declOf(entry.spec);
}

function isMaterial(spec) {
  const s = spec.trim().toLowerCase(), i = s.indexOf(":");
  return s.endsWith(".binary") ||
    (i > 0 && ((catalog && catalog.material_sources) || []).includes(s.slice(0, i)));
}

function truthy(v) { return v === true || v === 1 || v === "true" || v === "1"; }

function visibleEntries() {
  return state.models.map((m, i) => [m, i]).filter(([m, i]) =>
    state.solo === null ? m.visible !== false : state.solo === i);
}

function paramControl(entry, p) {
  const label = document.createElement("label");
  label.textContent = p.name + " ";
  let input;
  const current = entry.params[p.name];
  if (p.kind === "bool") {  // a .brdf's `bool NAME DEFAULT`: a checkbox, sent as true/false
    input = document.createElement("input");
    input.type = "checkbox";
    input.checked = truthy(current !== undefined ? current : p.default);
    input.dataset.param = p.name;
    input.title = p.doc || "";
    input.addEventListener("change", () => { entry.params[p.name] = input.checked; update(); });
    label.appendChild(input);
    return label;
  }
  if (p.kind === "choice") {
    input = document.createElement("select");
    for (const c of p.choices) {
      const o = document.createElement("option");
      o.value = c; o.textContent = c; input.appendChild(o);
    }
    input.value = current !== undefined ? current : p.default;
  } else if (p.kind === "scalar") {
    input = document.createElement("input");
    input.type = "number"; input.step = "any";
    input.value = current !== undefined ? current : (p.default === null ? "" : p.default);
  } else {
    input = document.createElement("input");
    input.type = "text";
    const v = current !== undefined ? current : p.default;
    input.value = Array.isArray(v) ? v.join(",") : (v === null ? "" : v);
  }
  input.dataset.param = p.name;
  input.title = (p.doc || "") + " bounds " + p.bounds + (p.unit ? " (" + p.unit + ")" : "");
  input.addEventListener("change", () => {
    const text = String(input.value).trim();
    if (p.clears && text !== "") {  // beta and the width it sets exclude each other
      delete entry.params[p.clears];
      const other = input.closest(".model").querySelector(`input[type=number][data-param="${p.clears}"], input[type=text][data-param="${p.clears}"]`);
      if (other) other.value = "";
    }
    if (text === "") delete entry.params[p.name];
    else if (p.kind === "choice") entry.params[p.name] = text;
    else if (text.includes(",")) entry.params[p.name] = text.split(",").map(Number);
    else entry.params[p.name] = Number(text);
    update();
  });
  label.appendChild(input);
  const slider = paramSlider(p, input);
  if (slider) label.appendChild(slider);
  const hint = document.createElement("small");
  hint.textContent = p.bounds ? " " + p.bounds : "";
  label.appendChild(hint);
  return label;
}

// A slider for a numeric parameter with finite bounds: linear over [lower, upper] when the
// range is narrow, logarithmic for wide ones (exponents up to 1e6, k_s): the slider moves
// the value live, the text box shows it (and still takes per-channel lists).
function paramSlider(p, input) {
  if (!(p.kind === "scalar" || p.kind === "colour") || p.lower === undefined ||
      p.upper === undefined || !isFinite(p.lower) || !isFinite(p.upper)) return null;
  const wide = p.upper > 100 * Math.max(1, Math.abs(p.lower));
  const lo = wide ? Math.max(p.lower, 0.01) : p.lower, hi = p.upper;
  const toT = v => wide ? (Math.log10(Math.max(v, lo)) - Math.log10(lo)) / (Math.log10(hi) - Math.log10(lo))
                        : (v - lo) / (hi - lo);
  const fromT = t => wide ? Math.pow(10, Math.log10(lo) + t * (Math.log10(hi) - Math.log10(lo)))
                          : lo + t * (hi - lo);
  const slider = document.createElement("input");
  slider.type = "range"; slider.min = 0; slider.max = 1000; slider.step = 1;
  slider.className = "param-slider"; slider.dataset.param = p.name;
  const v0 = parseFloat(String(input.value).split(",")[0]);
  slider.value = isFinite(v0) ? Math.round(1000 * Math.min(1, Math.max(0, toT(v0)))) : 500;
  slider.addEventListener("input", () => {
    const v = fromT(slider.value / 1000);
    input.value = Number(v.toPrecision(4));
    input.dispatchEvent(new Event("change"));
  });
  return slider;
}

// Why *spec* cannot be added by name (null: it can): not a registered model, alias or
// built-in material of the catalog. A file is added by path through "open file".
function unknownSpec(spec) {
  if (!catalog) return null;  // the server checks it then (the model's error in the list)
  const key = spec.toLowerCase().replace(/_/g, "-");
  const names = [];
  for (const m of catalog.models) names.push(m.name, ...(m.aliases || []));
  if (names.includes(key) || catalog.materials.includes(spec)) return null;
  if (/[\\/]|\.(binary|brdf|py)(:|$)/i.test(spec)) {
    return "'" + spec + "' is a file: open it with 'open file' (by its path on this machine)";
  }
  const close = names.concat(catalog.materials).filter(n => n.startsWith(key.slice(0, 3)));
  return "unknown model or material '" + spec + "'" +
    (close.length ? " (did you mean " + close.slice(0, 3).join(", ") + "?)" : "") +
    "; not added";
}

function renderModelList() {
  const list = document.getElementById("model-list");
  list.innerHTML = "";
  state.models.forEach((entry, i) => {
    const box = document.createElement("div");
    box.className = "model";
    box.style.borderLeftColor = COLOURS[i % COLOURS.length];
    const head = document.createElement("div");
    const info = fileInfo[entry.spec];
    const name = document.createElement("span");
    // a file model by its file's name (the whole path on the line below and in the title)
    name.className = "name"; name.title = entry.spec;
    name.textContent = (info && info.file ? entry.spec.split("/").pop() : entry.spec) +
      (entry.fitted_to ? " fitted to " + entry.fitted_to : "");
    head.appendChild(name);
    const vis = document.createElement("input");
    vis.type = "checkbox"; vis.checked = entry.visible !== false; vis.title = "show";
    vis.addEventListener("change", () => { entry.visible = vis.checked; update(); });
    head.appendChild(vis);
    const solo = document.createElement("button");
    solo.textContent = state.solo === i ? "unsolo" : "solo";
    solo.addEventListener("click", () => { state.solo = state.solo === i ? null : i; renderModelList(); update(); });
    head.appendChild(solo);
    const rm = document.createElement("button");
    rm.textContent = "remove";
    rm.addEventListener("click", () => { state.models.splice(i, 1); state.solo = null; renderModelList(); update(); });
    head.appendChild(rm);
    box.appendChild(head);
    if (info && info.file) {
      const file = document.createElement("div");
      file.className = "file"; file.id = "model-file-" + i;
      file.textContent = "file " + info.file + (info.digest ? " · " + info.digest : "") +
        (info.reloaded ? " · reloaded " + info.reloaded : "") +
        (info.compiled === false ? " · interpreted (compiling…)" : "");
      box.appendChild(file);
    }
    const decl = declFor(entry);
    if (decl) {
      for (const p of decl.params) {
        box.appendChild(paramControl(entry, decl.beta === p.name ? Object.assign({ clears: "beta" }, p) : p));
      }
      if (decl.beta) {
        box.appendChild(paramControl(entry, { name: "beta", kind: "scalar", default: null,
          lower: 0.5, upper: 89.5, bounds: "(0, 90) deg, sets " + decl.beta, unit: "deg",
          doc: "lobe half-angle", clears: decl.beta }));
      }
    }
    const pumpLabel = document.createElement("label");
    pumpLabel.textContent = "pump ";
    const pump = document.createElement("select");
    for (const v of ["none", "max", "controlled"]) {
      const o = document.createElement("option"); o.value = v; o.textContent = v; pump.appendChild(o);
    }
    pump.value = entry.pump || "none";
    pump.dataset.role = "pump";
    pump.addEventListener("change", () => { entry.pump = pump.value === "none" ? null : pump.value; update(); });
    pumpLabel.appendChild(pump);
    const times = document.createElement("input");
    times.type = "number"; times.min = 1; times.max = catalog ? catalog.max_times : 8;
    times.value = entry.times || 1; times.style.width = "40px"; times.title = "times";
    times.addEventListener("change", () => { entry.times = parseInt(times.value, 10); update(); });
    pumpLabel.appendChild(document.createTextNode(" × "));
    pumpLabel.appendChild(times);
    box.appendChild(pumpLabel);
    const err = document.createElement("div");
    err.className = "error"; err.id = "model-error-" + i;
    box.appendChild(err);
    list.appendChild(box);
  });
  refreshFitTargets();
}

function bindGlobal(id, parse) {
  const el = document.getElementById(id);
  const out = document.getElementById(id + "-out");
  const set = () => { if (out) out.textContent = el.value; };
  if (el.type === "checkbox") el.checked = !!state[id]; else el.value = state[id];
  set();
  el.addEventListener("input", () => {
    state[id] = el.type === "checkbox" ? el.checked : parse(el.value);
    set();
    update();
  });
}

// ------------------------------------------------------------------ drawing (plots.js)
function drawImages(id, items, key) {
  const box = document.getElementById(id);
  box.innerHTML = "";
  for (const [v, i] of items) {
    const f = document.createElement("figure");
    const img = document.createElement("img");
    img.src = v[key]; img.alt = key + " of " + v.name;
    img.style.borderColor = COLOURS[i % COLOURS.length];
    img.dataset.model = i;
    if (key === "sphere") attachLightDrag(img);
    const cap = document.createElement("figcaption");
    cap.textContent = v.name;
    f.appendChild(img); f.appendChild(cap); box.appendChild(f);
  }
}

function attachLightDrag(img) {
  const move = ev => {
    if (!(ev.buttons & 1)) return;
    const r = img.getBoundingClientRect();
    // the pointer marks where on the sphere the light is overhead: N = (x, y, z) → Φ_L = acos z
    const x = ((ev.clientX - r.left) / r.width) * 2 - 1, y = 1 - ((ev.clientY - r.top) / r.height) * 2;
    const z = Math.sqrt(Math.max(0, 1 - x * x - y * y));
    state.phi_l = Math.round(Math.min(175, Math.acos(z) * 180 / Math.PI));
    document.getElementById("phi_l").value = state.phi_l;
    document.getElementById("phi_l-out").textContent = state.phi_l;
    update();
  };
  img.addEventListener("mousemove", move);
  img.addEventListener("mousedown", move);
  img.draggable = false;
}

function drawAll() {
  if (!lastViews) return;
  const ok = [];
  lastViews.models.forEach((v, k) => {
    const i = lastViews.index[k];
    const err = document.getElementById("model-error-" + i);
    if (v.error) { if (err) err.textContent = v.error; return; }
    // a file whose newest version fails: its error here, its last good version drawn
    if (err) err.textContent = v.reload_error ? "not reloaded (drawing the last good version): " +
      v.reload_error : "";
    ok.push([v, i]);
  });
  const t0 = performance.now();
  const byId = id => document.getElementById(id);
  drawPolar(byId("polar"), state, ok); scheduleLobe(byId("lobe"), state, ok);
  drawCurves(byId("curves"), state, ok); drawAlbedo(byId("albedo"), state, ok);
  drawImages("spheres", ok, "sphere"); drawHalfdiffs(byId("halfdiffs"), state, ok);
  drawMs = performance.now() - t0;
  const errors = lastViews.models.filter(v => v.error || v.reload_error)
    .map(v => { const e = v.error || v.reload_error;  // a file's error already names it
                return e.startsWith(v.file || v.spec) ? e : v.spec + ": " + e; });
  showMessage(errors.concat(lastViews.notes || []).join(" · "));
}

// What the server said of each file model: its declarations (new controls when they
// change), the parameters its new version no longer declares (forgotten, with a note).
function takeFileInfo(models, index) {
  let relist = false;
  const notes = [];
  models.forEach((v, k) => {
    if (!v.file) return;
    const entry = state.models[index[k]];
    const old = fileInfo[v.spec] || {};
    const info = { file: v.file, digest: v.digest, decl: v.decl || old.decl,
                   reload_error: v.reload_error, reloaded: old.reloaded, compiled: v.compiled };
    if (old.digest && v.digest && old.digest !== v.digest) info.reloaded = new Date().toLocaleTimeString();
    if (JSON.stringify(info.decl) !== JSON.stringify(old.decl) || info.digest !== old.digest ||
        info.compiled !== old.compiled) relist = true;
    fileInfo[v.spec] = info;
    for (const name of v.dropped || []) {
      if (entry && name in entry.params) {
        delete entry.params[name];
        notes.push(v.spec + ": parameter " + name + " is not in the file any more (dropped)");
      }
    }
  });
  if (notes.length) writeHash();
  if (relist) renderModelList();
  return notes;
}

function shownFiles() {
  return new Set((lastViews ? lastViews.models : []).map(v => v.file).filter(Boolean));
}

async function pollChanges() {
  try {
    if (since !== null) {
      const r = await api("/api/changes?since=" + since);
      const files = shownFiles();
      if (r.version > since) {
        since = r.version;
        if (r.changed.some(f => files.has(f))) update();
      }
    }
  } catch (e) {
    // the server is gone or restarting: keep polling quietly
  }
  setTimeout(pollChanges, POLL_MS);
}

// ------------------------------------------------------------------ updates
function request() {
  const vis = visibleEntries();
  return { body: Object.assign({}, state, { models: vis.map(([m]) => m) }), index: vis.map(([, i]) => i) };
}

// Each state is asked with draft: true (the server may answer a slow model's slow views
// as drafts, marked draft: true, compute.py "Drafts"), then, when some were drafts and no
// newer state waits, once more with draft: false: the exact views. "ready" once exact.
async function update() {
  writeHash();
  pending = request();
  pending.body.draft = true;
  if (inflight) return;  // the newest state is sent when the running request returns
  while (pending) {
    const req = pending; pending = null; inflight = true;
    document.getElementById("status").textContent = "updating…";
    try {
      const t0 = performance.now();
      const data = await api("/api/views", req.body);
      since = data.version;
      const notes = takeFileInfo(data.models, req.index);
      lastViews = { models: data.models, index: req.index, notes };
      drawAll();
      document.getElementById("timing").textContent =
        "views " + data.ms + " ms on the server, " + Math.round(performance.now() - t0) +
        " ms round trip, drawn in " + Math.round(drawMs) + " ms" +
        (lobeMs === null ? "" : " (+ 3-D lobe " + Math.round(lobeMs) + " ms)");
      if (data.models.some(v => v.draft)) {  // drafts drawn: the exact views next
        if (!pending) pending = { body: Object.assign({}, req.body, { draft: false }), index: req.index };
        continue;
      }
      document.getElementById("status").textContent = "ready";
      fetchVerdicts(req);
    } catch (e) {
      showMessage(e.message);
      document.getElementById("status").textContent = "error";
    } finally {
      inflight = false;
    }
  }
}

let verdictSeq = 0;
async function fetchVerdicts(req) {
  const seq = ++verdictSeq;
  const box = document.getElementById("verdicts");
  box.textContent = "verdict: computing…";
  try {
    const data = await api("/api/verdict", req.body);
    if (seq !== verdictSeq) return;
    box.innerHTML = "";
    data.verdicts.forEach((v, k) => {
      const line = document.createElement("div");
      const i = req.index[k];
      line.style.color = COLOURS[i % COLOURS.length];
      if (v.error) { line.textContent = v.spec + ": " + v.error; box.appendChild(line); return; }
      let energy = v.energy;
      if (v.energy === "diverges") energy += " at grazing, a ~ cos^-" + v.divergence_exponent;
      if (v.energy === "exceeds") energy += " 1 (×" + Number(v.max_scale).toPrecision(3) + " fixes it)";
      line.innerHTML = "<b>" + v.model + "</b>: reciprocal " + ({ "reciprocal": "yes", "not reciprocal": "no" }[v.reciprocity] || v.reciprocity) +
        "; energy <span class='" + (v.energy === "conserves" ? "verdict-ok" : "verdict-bad") + "'>" +
        energy + "</span>; max albedo " + Number(v.max_albedo).toPrecision(4) + " at " + v.theta_max_deg +
        "° (albedo to " + v.tol + ")";
      line.className = "verdict";
      box.appendChild(line);
    });
  } catch (e) {
    if (seq === verdictSeq) box.textContent = "verdict: " + e.message;
  }
}

function refreshFitTargets() {
  const sel = document.getElementById("fit-target");
  const keep = sel.value;
  sel.innerHTML = "";
  const specs = state.models.map(m => m.spec).filter(isMaterial);
  for (const s of specs) { const o = document.createElement("option"); o.value = s; o.textContent = s; sel.appendChild(o); }
  if (specs.includes(keep)) sel.value = keep;
}

async function startFit() {
  const box = document.getElementById("fit-status");
  const target = document.getElementById("fit-target").value;
  const model = state.models.find(m => !isMaterial(m.spec));
  if (!target || !model) { box.textContent = "add a material (e.g. merl:nickel) and a model to fit"; return; }
  box.textContent = "fitting " + model.spec + " to " + target + " …";
  try {
    const { id } = await api("/api/fit", { model, target, loss: document.getElementById("fit-loss").value });
    for (;;) {
      await new Promise(r => setTimeout(r, 300));
      const j = await api("/api/fit/" + id);
      if (j.state === "running") {
        box.textContent = "fitting " + j.model + " to " + j.target + ": " + j.stage + ", " +
          j.evaluations + " evaluations, " + j.seconds + " s";
        continue;
      }
      if (j.state === "error") { box.textContent = "fit failed: " + j.error; return; }
      box.textContent = "fitted in " + j.seconds + " s: " + j.message;
      state.models.push({ spec: model.spec, params: j.params, pump: model.pump || null,
                          times: model.times || 1, visible: true, fitted_to: target });
      renderModelList(); update();
      return;
    }
  } catch (e) { box.textContent = "fit failed: " + e.message; }
}

function download(name, blob) {
  const a = document.createElement("a");
  a.href = URL.createObjectURL(blob); a.download = name; a.click();
  setTimeout(() => URL.revokeObjectURL(a.href), 1000);
}

async function init() {
  state = readHash();
  try {
    catalog = await api("/api/catalog");
  } catch (e) {
    showMessage("cannot load the model catalog: " + e.message);
    return;
  }
  const dl = document.getElementById("spec-list");
  for (const m of catalog.models) { const o = document.createElement("option"); o.value = m.name; dl.appendChild(o); }
  for (const s of catalog.materials) { const o = document.createElement("option"); o.value = s; dl.appendChild(o); }
  renderModelList();
  document.getElementById("fit-button").addEventListener("click", startFit);
  bindGlobal("theta_i", Number); bindGlobal("phi_i", Number); bindGlobal("phi_l", Number);
  bindGlobal("ambient", Number); bindGlobal("mode", String); bindGlobal("log", Boolean);
  bindGlobal("cosine", Boolean);
  document.getElementById("log").addEventListener("change", drawAll);
  document.getElementById("add-form").addEventListener("submit", ev => {
    ev.preventDefault();
    const spec = document.getElementById("add-spec").value.trim();
    if (!spec) return;
    const problem = unknownSpec(spec);
    if (problem) { showMessage(problem); return; }  // an unknown spec never enters the list
    state.models.push({ spec, params: {}, pump: null, times: 1, visible: true });
    document.getElementById("add-spec").value = "";
    renderModelList(); update();
  });
  document.getElementById("open-form").addEventListener("submit", async ev => {
    ev.preventDefault();
    const input = document.getElementById("open-path"), box = document.getElementById("open-error");
    const path = input.value.trim();
    try {
      const r = await api("/api/open", { path });
      box.textContent = "";
      state.models.push({ spec: r.spec, params: {}, pump: null, times: 1, visible: true });
      input.value = "";
      renderModelList(); update();
    } catch (e) {
      box.textContent = e.message;
    }
  });
  document.getElementById("share").addEventListener("click", () => {
    writeHash();
    if (navigator.clipboard) navigator.clipboard.writeText(location.href).catch(() => {});
    showMessage("link: " + location.href);
  });
  document.getElementById("export-json").addEventListener("click", () => {
    const models = (lastViews ? lastViews.models : []).filter(v => !v.error)
      .map(v => ({ model: v.name, params: v.params }));
    download("brdfkit-models.json", new Blob([JSON.stringify(models, null, 2)], { type: "application/json" }));
  });
  document.getElementById("export-binary").addEventListener("click", async () => {
    const vis = visibleEntries();
    if (!vis.length) { showMessage("no model to export"); return; }
    const res = await fetch("/api/export/binary", { method: "POST", headers: { "Content-Type": "application/json" },
                                                   body: JSON.stringify(vis[0][0]) });
    if (!res.ok) { showMessage((await res.json()).error); return; }
    download(vis[0][0].spec.replace(/[^A-Za-z0-9._-]/g, "_") + ".binary", await res.blob());
  });
  for (const b of document.querySelectorAll("button.png")) {
    b.addEventListener("click", () => downloadPlot(b.dataset.for));
  }
  for (const b of document.querySelectorAll("button.png-img")) {  // every image of the view
    b.addEventListener("click", () => {
      document.querySelectorAll("#" + b.dataset.for + " img").forEach((img, k) => {
        const a = document.createElement("a");
        a.href = img.src; a.download = "brdfkit-" + b.dataset.for + "-" + k + ".png"; a.click();
      });
    });
  }
  liveWhileHovered(document.getElementById("lobe"));
  update();
  pollChanges();
}

window.addEventListener("DOMContentLoaded", init);
