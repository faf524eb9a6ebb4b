// brdfkit explorer: the views drawn with Plotly.js (served from the plotly package, no CDN).
// Each draw function takes the page's state and the models' views, [[view, model index], ...],
// and redraws its figure with Plotly.react (the figure is updated in place: zoom and the 3-D
// camera survive a parameter move through layout.uirevision).
// Colours: one per model (COLOURS, the model list's border colour) in luminance mode; in
// R, G, B mode the channels are red, green and blue and the models differ by line dash.
"use strict";

const COLOURS = ["#1f77b4", "#d62728", "#2ca02c", "#9467bd", "#ff7f0e", "#8c564b", "#e377c2", "#17becf"];
const CHANNEL_COLOURS = ["#d62728", "#2ca02c", "#1f77b4"];  // R, G, B
const CHANNEL_NAMES = ["R", "G", "B"];
const MODEL_DASH = ["solid", "dash", "dot", "dashdot", "longdash", "longdashdot"];
const LIGHT_COLOUR = "#e69500";  // the incident direction ω_i
// Decades of f shown on a log axis below the largest value: the θ_h × θ_d image's 4 and one
// more on the curves, whose tails matter less than the peak's shape.
const LOG_DECADES = 5;
const FONT = { family: "system-ui, sans-serif", size: 11 };
const CONFIG = { responsive: true, displaylogo: false,
                 modeBarButtonsToRemove: ["select2d", "lasso2d", "toImage"] };

function modelColour(i) { return COLOURS[i % COLOURS.length]; }

// The line style of channel c of model i's curve (nch channels drawn).
function lineStyle(i, c, nch) {
  return nch === 3 ? { color: CHANNEL_COLOURS[c], dash: MODEL_DASH[i % MODEL_DASH.length], width: 1.6 }
                   : { color: modelColour(i), dash: "solid", width: 1.6 };
}

function traceName(v, c, nch) { return nch === 3 ? v.name + " " + CHANNEL_NAMES[c] : v.name; }

function baseLayout(extra) {
  return Object.assign({ font: FONT, margin: { l: 62, r: 14, t: 10, b: 46 }, autosize: true,
                         paper_bgcolor: "#fff", plot_bgcolor: "#fff", uirevision: "keep",
                         legend: { orientation: "h", y: -0.22, font: { size: 10 } },
                         showlegend: false, hovermode: "closest" }, extra);
}

// A log axis's range: the top LOG_DECADES decades below the largest positive value.
function logRange(values) {
  let hi = -Infinity;
  for (const v of values) if (v > 0 && v > hi) hi = v;
  if (!isFinite(hi)) return undefined;
  const top = Math.log10(hi);
  return [top - LOG_DECADES, top + 0.15];
}

function valueAxis(log, title, values) {
  return Object.assign(log ? { type: "log", title: { text: title }, range: logRange(values),
                               exponentformat: "power", showexponent: "all", dtick: 1, zeroline: false }
                             : { type: "linear", title: { text: title }, rangemode: "tozero", zeroline: false },
                       OUT);
}

// Ticks outside the plot area: the labels stand clear of the axes' corner (0 and 0°).
const OUT = { ticks: "outside", ticklen: 4, tickcolor: "#999" };
const ANGLE_TICKS = Object.assign({ dtick: 15, ticksuffix: "°" }, OUT);

function drawPolar(el, s, items) {
  const traces = [], all = [];
  for (const [v, i] of items) {
    const nch = v.polar.values.length;
    v.polar.values.forEach((ys, c) => {
      all.push(...ys);
      traces.push({ type: "scatterpolar", mode: "lines", theta: v.polar.theta_o_deg, r: ys,
                    name: traceName(v, c, nch), line: lineStyle(i, c, nch),
                    hovertemplate: "θ<sub>o</sub> %{theta:.1f}°<br>f %{r:.4g} /sr<extra>%{fullData.name}</extra>" });
    });
  }
  const radial = s.log ? { type: "log", range: logRange(all), exponentformat: "power", dtick: 1 }
                       : { type: "linear", rangemode: "tozero" };
  const rr = s.log ? radial.range : null, top = Math.max(1e-12, ...all.filter(isFinite));
  traces.push({ type: "scatterpolar", mode: "lines", name: "light ω_i", hoverinfo: "skip",
                theta: [-s.theta_i, -s.theta_i],
                r: s.log ? (rr ? [Math.pow(10, rr[0]), Math.pow(10, rr[1])] : [1e-3, 1]) : [0, top],
                line: { color: LIGHT_COLOUR, width: 2 } });
  const ticks = [-90, -60, -30, 0, 30, 60, 90];
  Plotly.react(el, traces, baseLayout({
    margin: { l: 44, r: 44, t: 16, b: 8 },
    // the radial axis's own title would touch its power-of-ten labels: a note below instead
    annotations: [{ xref: "paper", yref: "paper", x: 1, y: 0, xanchor: "right", yanchor: "bottom",
                    showarrow: false, text: "radius: f (1/sr)" + (s.log ? ", log scale" : "") }],
    polar: { sector: [0, 180], hole: 0, domain: { x: [0, 1], y: [0.1, 1] },
             angularaxis: { rotation: 90, direction: "clockwise", tickmode: "array",
                            tickvals: ticks, ticktext: ticks.map(t => t + "°") },
             radialaxis: Object.assign(radial, { angle: 0, tickangle: 0 }) },
  }), CONFIG);
}

// The 3-D lobe is drawn after the 2-D views, once per burst of updates (the newest):
// WebGL is the costliest figure (~300 ms per redraw with software rendering, a headless
// browser's; milliseconds on a GPU), and the page's next request need not wait for it.
let lobeDue = null;
let lobeMs = null;  // the time the last lobe drawing took (ms)

function scheduleLobe(el, s, items) {
  const idle = lobeDue === null;
  lobeDue = [el, s, items];
  if (!idle) return;
  setTimeout(() => {
    const [e, st, it] = lobeDue;
    lobeDue = null;
    const t0 = performance.now();
    drawLobe(e, st, it);
    renderOnce(e);
    lobeMs = performance.now() - t0;
  }, 0);
}

// Plotly's WebGL scene re-checks itself every animation frame for as long as it exists: ~20%
// of a core measured with software rendering (a headless browser), taken from the server on
// a small machine. The loop runs only while the pointer is over the lobe (to rotate and
// zoom it); otherwise the scene is rendered once per drawing. Plotly's internal scene
// object (_fullLayout.scene._scene.glplot, plotly.js 3); without it the loop just runs.
function glplotOf(el) {
  const sc = el._fullLayout && el._fullLayout.scene && el._fullLayout.scene._scene;
  return sc && sc.glplot && typeof sc.glplot.redraw === "function" ? sc.glplot : null;
}

function renderOnce(el) {
  const gp = glplotOf(el);
  if (!gp || el.dataset.live === "1") return;
  gp._stopped = false; gp.redraw(); gp._stopped = true;
}

function liveWhileHovered(el) {
  el.addEventListener("mouseenter", () => {
    const gp = glplotOf(el);
    if (!gp) return;
    el.dataset.live = "1"; gp._stopped = false;
    const loop = () => { if (el.dataset.live === "1" && !gp._stopped) { gp.redraw(); requestAnimationFrame(loop); } };
    requestAnimationFrame(loop);
  });
  el.addEventListener("mouseleave", () => { el.dataset.live = "0"; renderOnce(el); });
}

function drawLobe(el, s, items) {
  const traces = [];
  for (const [v, i] of items) {
    const L = v.lobe, col = modelColour(i);
    traces.push({ type: "surface", x: L.x, y: L.y, z: L.z, name: v.name, showscale: false,
                  colorscale: [[0, col], [1, col]], surfacecolor: L.z.map(row => row.map(() => 0)),
                  opacity: items.length > 1 ? 0.75 : 1,
                  lighting: { ambient: 0.55, diffuse: 0.7, specular: 0.1 },
                  hovertemplate: v.name + "<br>x %{x:.3f}, y %{y:.3f}, z %{z:.3f}<extra></extra>" });
  }
  if (items.length) {  // the light direction (the same for every model)
    const wi = items[0][0].lobe.wi;
    traces.push({ type: "scatter3d", mode: "lines", x: [0, wi[0]], y: [0, wi[1]], z: [0, wi[2]],
                  name: "light ω_i", hoverinfo: "name", line: { color: LIGHT_COLOUR, width: 6 } });
  }
  // no tick at the scene's corners, where the x, y and z labels would meet
  // another number of models: a new scene (Plotly's WebGL scene updated in place with
  // surfaces added or removed renders a disposed shader: "this._relink is not a function")
  if (el.data && el.data.length !== traces.length) Plotly.purge(el);
  const axis = (t, r, ticks) => ({ title: { text: t }, range: r, tickvals: ticks, zeroline: false });
  const flat = [-0.5, 0, 0.5];
  Plotly.react(el, traces, baseLayout({
    margin: { l: 0, r: 0, t: 0, b: 0 },
    scene: { xaxis: axis("x", [-1, 1], flat), yaxis: axis("y", [-1, 1], flat),
             zaxis: axis("z (normal)", [0, 1], [0.5, 1]),
             aspectmode: "manual", aspectratio: { x: 1, y: 1, z: 0.5 },
             camera: { eye: { x: 0.95, y: -1.2, z: 0.7 } } },
  }), CONFIG);
}

// Three panels sharing the f axis: against θ_h (θ_d = θ_i, φ_d = 90°), θ_d (θ_h = 0) and
// θ_o (the in-plane slice, negative on the light's side).
function drawCurves(el, s, items) {
  const traces = [], all = [];
  const panels = [["theta_h", "x", "θ<sub>h</sub>"], ["theta_d", "x2", "θ<sub>d</sub>"], ["theta_o", "x3", "θ<sub>o</sub>"]];
  for (const [v, i] of items) {
    for (const [key, xaxis, label] of panels) {
      const xs = key === "theta_o" ? v.curves.theta_o.theta_o_deg : v.curves.angle_deg;
      const rows = key === "theta_o" ? v.curves.theta_o.values : v.curves[key];
      rows.forEach((ys, c) => {
        all.push(...ys);
        traces.push({ type: "scatter", mode: "lines", x: xs, y: ys, xaxis, yaxis: "y",
                      name: traceName(v, c, rows.length), line: lineStyle(i, c, rows.length),
                      hovertemplate: label + " %{x:.1f}°<br>f %{y:.4g} /sr<extra>%{fullData.name}</extra>" });
      });
    }
  }
  const ax = (domain, title, range, dtick) =>
    Object.assign({ domain, title: { text: title + " (°)" }, range, dtick, tickangle: 0, zeroline: false }, OUT);
  Plotly.react(el, traces, baseLayout({
    margin: { l: 62, r: 10, t: 10, b: 46 },
    xaxis: ax([0, 0.25], "θ<sub>h</sub>", [0, 90], 30),
    xaxis2: ax([0.32, 0.57], "θ<sub>d</sub>", [0, 90], 30),
    xaxis3: ax([0.64, 1], "θ<sub>o</sub>", [-90, 90], 45),
    yaxis: valueAxis(s.log, "f (1/sr)", all),
  }), CONFIG);
}

function drawAlbedo(el, s, items) {
  const traces = [];
  let hi = 1;
  for (const [v, i] of items) {
    const nch = v.albedo.values.length;
    v.albedo.values.forEach((ys, c) => {
      for (const y of ys) if (isFinite(y) && y > hi) hi = y;
      traces.push({ type: "scatter", mode: "lines", x: v.albedo.theta_deg, y: ys,
                    name: traceName(v, c, nch), line: lineStyle(i, c, nch),
                    hovertemplate: "θ<sub>i</sub> %{x:.1f}°<br>a %{y:.4f}<extra>%{fullData.name}</extra>" });
    });
  }
  Plotly.react(el, traces, baseLayout({
    xaxis: Object.assign({ title: { text: "θ<sub>i</sub>" }, range: [0, 90], zeroline: false }, ANGLE_TICKS),
    yaxis: Object.assign({ title: { text: "albedo a(θ<sub>i</sub>)" }, range: [0, 1.08 * hi], zeroline: false }, OUT),
    // a = 1: energy conservation's bound
    shapes: [{ type: "line", xref: "paper", x0: 0, x1: 1, y0: 1, y1: 1,
               line: { color: "#888", width: 1, dash: "dash" } }],
  }), CONFIG);
}

// θ_h × θ_d images (the server's PNG, MERL's layout: row k at θ_h = 90°·u², u = (k+½)/N):
// one figure per model, the y axis in u with its ticks labelled in θ_h degrees, and a colour
// bar of log₁₀ f (the image's viridis map over [vmin, vmax]).
const HALFDIFF_TICKS = [0, 1, 5, 10, 20, 30, 45, 60, 90];

function drawHalfdiffs(box, s, items) {
  while (box.children.length > items.length) Plotly.purge(box.lastChild), box.lastChild.remove();
  while (box.children.length < items.length) {
    const d = document.createElement("div");
    d.className = "plot halfdiff";
    box.appendChild(d);
  }
  items.forEach(([v, i], k) => {
    const el = box.children[k], info = v.halfdiff_info;
    // the image depends on the model alone: a light or direction move leaves it as drawn
    if (el.drawnSrc === v.halfdiff && el.dataset.model === String(i) && el.drawnName === v.name) return;
    el.drawnSrc = v.halfdiff; el.drawnName = v.name;
    el.dataset.model = i;
    const u = t => 90 * Math.sqrt(t / 90);  // θ_h (deg) → the image's row coordinate u·90
    // views.halfdiff's 90 × 90 pixels (MERL's 90 θ_h and θ_d bins): pixel (k, j) centred at
    // u·90 = k + ½ and θ_d = j + ½ degrees
    const img = { type: "image", source: v.halfdiff, x0: 0.5, y0: 0.5, dx: 1, dy: 1,
                  hoverinfo: "skip", name: v.name };
    const bar = { type: "scatter", mode: "markers", x: [null], y: [null], hoverinfo: "skip",
                  marker: { color: [info.vmin, info.vmax], cmin: info.vmin, cmax: info.vmax,
                            colorscale: "Viridis", showscale: true,
                            colorbar: { title: { text: "log<sub>10</sub> f", side: "right" },
                                        thickness: 12, len: 1, dtick: 1 } } };
    Plotly.react(el, [img, bar], baseLayout({
      margin: { l: 54, r: 10, t: 26, b: 42 },
      title: { text: v.name, font: { size: 12, color: modelColour(i) }, y: 0.98 },
      xaxis: Object.assign({ title: { text: "θ<sub>d</sub>" }, range: [0, 90], zeroline: false,
                             showgrid: false, dtick: 30, ticksuffix: "°" }, OUT),
      yaxis: Object.assign({ title: { text: "θ<sub>h</sub>" }, range: [90, 0], zeroline: false, showgrid: false,
                             tickmode: "array", tickvals: HALFDIFF_TICKS.map(u),
                             ticktext: HALFDIFF_TICKS.map(t => t + "°") }, OUT),
    }), CONFIG);
  });
}

// The drawn traces of a figure as JSON (x, y, r of each trace): the browser tests read the
// numbers drawn through this.
function drawnData(id) {
  const el = document.getElementById(id);
  return JSON.stringify((el && el.data ? el.data : []).map(t => [t.x, t.y, t.r, t.z]));
}

function downloadPlot(id) {
  const el = document.getElementById(id);
  const figs = el.classList.contains("plot") ? [el] : Array.from(el.querySelectorAll(".plot"));
  figs.forEach((f, k) => Plotly.downloadImage(f, { format: "png", scale: 2,
    filename: "brdfkit-" + id + (figs.length > 1 ? "-" + k : "") }));
}
