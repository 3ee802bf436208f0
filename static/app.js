// jik dashboard: one session per tab. The page creates its session from the state in its URL
// (POST /api/sessions), follows it over server-sent events and draws its figures; controls are
// built from GET /robots (ranges, defaults) and change the session's state
// (POST /api/sessions/{id}/state). The viser scene (iframe) shows and changes the same session.
"use strict";

const PANELS = ["task", "drift", "joints", "augmenting", "sensitivity", "table"];
const PLOT_CONFIG = { responsive: true, displaylogo: false };
const jik = {
  session: null, catalogue: null, config: null, state: null, generation: 0, shownGeneration: 0,
  pending: new Map(), lastLatency: null,
};
const api = (path) => `/api/sessions/${jik.session}${path}`;

const $ = (sel) => document.querySelector(sel);
const el = (tag, attrs = {}, ...children) => {
  const e = document.createElement(tag);
  for (const [k, v] of Object.entries(attrs)) {
    if (k === "dataset") Object.assign(e.dataset, v);
    else if (k in e && k !== "list") e[k] = v;
    else e.setAttribute(k, v);
  }
  for (const c of children) e.append(c);
  return e;
};
const fmt = (v, d = 3) => (Math.abs(v) >= 1e4 || (Math.abs(v) < 1e-3 && v !== 0) ? v.toExponential(2) : (+v).toFixed(d));

function robotSpec(name) {
  return jik.catalogue.robots.find((r) => r.name === name);
}

// ---------------------------------------------------------------- sending changes
// A change is posted at once; while a POST is in flight, newer changes are merged and sent
// when it returns (a slider drag sends one request at a time, never a stale backlog).
let queued = {};
let queuedSince = null;
let inFlight = false;
function change(patch) {
  for (const [k, v] of Object.entries(patch)) {
    if (v && typeof v === "object" && !Array.isArray(v) && queued[k]) queued[k] = { ...queued[k], ...v };
    else queued[k] = v;
  }
  if (queuedSince === null) queuedSince = performance.now();
  if (!inFlight) flush();
}

async function flush() {
  const patch = queued;
  const since = queuedSince;
  queued = {};
  queuedSince = null;
  if (!Object.keys(patch).length) return;
  inFlight = true;
  // Any result newer than the last generation known now answers this change (the result can
  // arrive before the POST's response).
  if (!jik.pending.has(jik.generation)) jik.pending.set(jik.generation, since);
  try {
    const res = await fetch(api("/state"), {
      method: "POST", headers: { "Content-Type": "application/json" }, body: JSON.stringify(patch),
    });
    const body = await res.json();
    if (!res.ok) {
      // (the session's "refused" event shows it and puts the controls back; this covers a
      // refusal of the request itself)
      setStatus(Array.isArray(body.detail) ? body.detail.map((d) => d.msg).join("; ") : body.detail, true);
      jik.pending.delete(jik.generation);
      return;
    }
    jik.generation = Math.max(jik.generation, body.generation);
  } finally {
    inFlight = false;
    if (Object.keys(queued).length) flush();
  }
}

// ---------------------------------------------------------------- controls
function slider(label, { min, max, step, value, log = false, onInput, id }) {
  const toPos = (v) => (log ? Math.log10(v) : v);
  const fromPos = (p) => (log ? 10 ** p : p);
  const input = el("input", {
    type: "range", min: toPos(min), max: toPos(max), step: log ? (toPos(max) - toPos(min)) / 200 : step,
    value: toPos(value), id,
  });
  const show = (v) => (Number.isInteger(step) && !log ? String(Math.round(v)) : fmt(v));
  const out = el("output", {}, show(value));
  input.addEventListener("input", () => {
    const v = +fromPos(+input.value).toPrecision(4);
    out.textContent = show(v);
    onInput(v);
  });
  input.setValue = (v) => { input.value = toPos(v); out.textContent = show(v); };
  return el("label", {}, el("span", {}, label, " ", out), input);
}

function numberBox(label, { min, max, step, value, onChange, id }) {
  const input = el("input", { type: "number", min, max, step, value: +(+value).toFixed(4), id });
  input.addEventListener("change", () => onChange(+input.value));
  input.setValue = (v) => { input.value = +(+v).toFixed(4); };
  return el("label", {}, label, input);
}

function select(label, options, value, onChange, id) {
  const s = el("select", { id });
  for (const [v, text] of options) s.append(el("option", { value: v, selected: v === value }, text));
  s.addEventListener("change", () => onChange(s.value));
  s.setValue = (v) => { s.value = v; };
  return el("label", {}, label, s);
}

const bound = new Map(); // state path -> input with setValue

function buildControls(state) {
  const form = $("#controls");
  form.replaceChildren();
  bound.clear();
  const spec = robotSpec(state.robot);
  const bind = (key, label) => { bound.set(key, label.querySelector("input,select")); return label; };

  const main = el("fieldset");
  main.append(bind("robot", select("robot", jik.catalogue.robots.map((r) => [r.name, r.title]), state.robot,
    (v) => change({ robot: v }), "ctl-robot")));
  main.append(bind("mode", select("mode", (spec.modes || ["continuous", "discrete"]).map((m) => [m, m]), state.mode,
    (v) => change({ mode: v, gamma: v === "discrete" ? Math.min(state.gamma, 1) : state.gamma }), "ctl-mode")));
  const gmax = state.mode === "discrete" ? 1.99 : 10;
  main.append(bind("gamma", slider("γ (decay rate)", {
    min: 0.01, max: gmax, value: Math.min(state.gamma, gmax), log: true, id: "ctl-gamma",
    onInput: (v) => change({ gamma: v }),
  })));
  form.append(main);

  const params = el("fieldset");
  for (const p of spec.parameters) {
    if (Array.isArray(p.default)) {
      const value = state.robot_parameters[p.name];
      p.default.forEach((_, i) => params.append(bind(`robot_parameters.${p.name}.${i}`, numberBox(`${p.name}[${i + 1}]`, {
        min: p.minimum[i], max: p.maximum[i], step: 0.1, value: value[i], id: `ctl-${p.name}-${i}`,
        onChange: (v) => { const q = [...jik.state.robot_parameters[p.name]]; q[i] = v; change({ robot_parameters: { [p.name]: q } }); },
      }))));
      for (const [name, preset] of Object.entries(p.presets || {})) {
        params.append(el("button", { type: "button", id: `ctl-preset-${name}`, title: `${p.name} = (${preset.map((v) => fmt(v)).join(", ")})`,
          onclick: () => change({ robot_parameters: { [p.name]: preset } }) }, `${p.name} = ${name}`));
      }
    } else {
      params.append(bind(`robot_parameters.${p.name}`, slider(p.name, {
        min: p.minimum, max: p.maximum, step: (p.maximum - p.minimum) / 200, value: state.robot_parameters[p.name],
        id: `ctl-${p.name}`, onInput: (v) => change({ robot_parameters: { [p.name]: v } }),
      })));
    }
  }
  params.append(bind("augmentation", select("augmenting map h", spec.augmentations.map((a) => [a.name, `${a.name} ${a.equation}`]),
    state.augmentation, (v) => change({ augmentation: v }), "ctl-augmentation")));
  const aug = spec.augmentations.find((a) => a.name === state.augmentation);
  for (const p of aug.parameters) {
    params.append(bind(`augmentation_parameters.${p.name}`, slider(p.name, {
      min: p.minimum, max: p.maximum, step: (p.maximum - p.minimum) / 200, value: state.augmentation_parameters[p.name],
      id: `ctl-aug-${p.name}`, onInput: (v) => change({ augmentation_parameters: { [p.name]: v } }),
    })));
  }
  form.append(params);

  const start = el("fieldset");
  spec.variable_names.forEach((name, i) => {
    const [lo, hi] = spec.x_range[i] || [-10, 10];
    start.append(bind(`x0.${i}`, slider(`x0: ${name}`, {
      min: lo, max: hi, step: (hi - lo) / 400, value: state.x0[i], id: `ctl-x0-${i}`,
      onInput: (v) => { const x = [...jik.state.x0]; x[i] = v; jik.state.x0 = x; change({ x0: x }); },
    })));
  });
  form.append(start);

  const task = el("fieldset");
  if (spec.default_path.length) {
    task.append(bind("task", select("task", [["path", "closed path"], ["target", "single target"]], state.task,
      (v) => change({ task: v }), "ctl-task")));
  }
  if (state.task === "path") {
    const text = el("input", { type: "text", id: "ctl-path", value: state.path.map((p) => p.join(", ")).join("; ") });
    text.addEventListener("change", () => change({ path: text.value.split(";").map((p) => p.split(",").map(Number)) }));
    text.setValue = (v) => { text.value = v.map((p) => p.join(", ")).join("; "); };
    bound.set("path", text);
    task.append(el("label", {}, "path (task points; closed back to k(x0))", text));
    task.append(bind("cycles", slider("cycles", {
      min: 1, max: jik.config.max_cycles || 20, step: 1, value: state.cycles, id: "ctl-cycles",
      onInput: (v) => change({ cycles: Math.round(v) }),
    })));
  } else {
    spec.task_names.forEach((name, i) => task.append(bind(`target.${i}`, numberBox(`target ${name}`, {
      step: 0.1, value: state.target[i], id: `ctl-target-${i}`,
      onChange: (v) => { const t = [...jik.state.target]; t[i] = v; change({ target: t }); },
    }))));
  }
  form.append(task);
}

function syncControls(state) {
  for (const [key, input] of bound) {
    if (document.activeElement === input) continue;
    const value = key.split(".").reduce((o, k) => (o == null ? o : o[k]), state);
    if (value !== undefined && input.setValue) input.setValue(value);
  }
}

// ---------------------------------------------------------------- events
function setStatus(text, error = false) {
  const s = $("#status-text");
  s.textContent = text;
  s.classList.toggle("error", error);
}

function showProgress(fraction, elapsed) {
  const box = $("#progress");
  // Only computations longer than half a second get a progress bar.
  box.hidden = !(elapsed > 0.5 && fraction < 1);
  $("#progress-bar").style.width = `${Math.round(100 * fraction)}%`;
  $("#progress-text").textContent = `computing ${Math.round(100 * fraction)}%`;
}

function onState(msg) {
  const rebuild = !jik.state || jik.state.robot !== msg.state.robot || jik.state.augmentation !== msg.state.augmentation
    || jik.state.task !== msg.state.task || jik.state.mode !== msg.state.mode;
  jik.state = msg.state;
  jik.generation = Math.max(jik.generation, msg.generation);
  if (rebuild) buildControls(msg.state);
  else syncControls(msg.state);
  rememberInUrl(msg.state);
  if (msg.generation > jik.shownGeneration) setStatus(`computing generation ${msg.generation}…`);
}

// A figure that is one plotly table is drawn as an HTML table: the same cells, drawn far faster
// than plotly's SVG table (docs/benchmarks.md).
function isTable(fig) {
  return fig.data.length === 1 && fig.data[0].type === "table";
}

function drawTable(div, fig) {
  const t = fig.data[0];
  const fills = (f, col, row) => (Array.isArray(f) ? (Array.isArray(f[col]) ? f[col][row % f[col].length] : f[col]) : f);
  const head = el("tr", {}, ...t.header.values.map((v, c) => {
    const th = el("th", {}, String(v));
    th.style.background = fills((t.header.fill || {}).color, c, 0) || "";
    return th;
  }));
  const cols = t.cells.values;
  const rows = Math.max(...cols.map((c) => c.length));
  const body = [];
  for (let r = 0; r < rows; r++) {
    body.push(el("tr", {}, ...cols.map((col, c) => {
      const td = el("td", {}, String(col[r] ?? ""));
      const fc = (t.cells.fill || {}).color;
      const f = fills(fc, Array.isArray(fc) && fc.length === 1 ? 0 : c, r);
      if (f) td.style.background = f;
      return td;
    })));
  }
  const title = (fig.layout.title && fig.layout.title.text) || "";
  div.classList.add("html-table");
  div.replaceChildren(
    el("h3", { className: "table-title" }, title),
    el("div", { className: "table-scroll" }, el("table", {}, el("thead", {}, head), el("tbody", {}, ...body))),
  );
}

// A figure that differs from the one on screen only in its lines' data, its axis ranges, its
// title text and its shapes (same styles, same contours) takes the new ranges, title and shapes
// by Plotly.relayout, then moves its lines with Plotly.animate: no redraw of the rest, a third
// of Plotly.react's cost. Both run in the same task, so that the browser paints the panel once:
// with the move first, plotly ran the relayout in a task after the next frame, which showed the
// new lines on the old axes. The server rounds the ranges (app/figures.py nice_range) and keeps
// them while the data fill them (keep_ranges), so that most changes do not even touch the axes.
const DATA_KEYS = ["x", "y", "customdata", "text"];
const MOVE = { transition: { duration: 0 }, frame: { duration: 0, redraw: false }, mode: "immediate" };
const isAxis = (k) => /^[xy]axis[0-9]*$/.test(k);
const axisRanges = (layout) => Object.fromEntries(Object.keys(layout || {}).filter(isAxis).sort()
  .map((k) => [k, layout[k].range || null]));
// The figure without its lines' data, axis ranges, title text and shapes (JSON): what must stay
// for a move. (A new title text, as the h panel's E1/E2 that a second phase fills in, is set
// with the move: a relayout of the title.) Plotly.animate drops the layer of any trace it
// cannot animate: scatter traces move only in figures of scatter traces. The h panel's runs are
// shapes over its map (a contour, app/figures.py), moved by the relayout alone.
const moves = (t) => t.type === "scatter";
// The indices of a figure's lines (the traces Plotly.animate moves), and the animation frame
// that gives the lines `traces` of `data` their data.
const lineIndices = (fig) => fig.data.flatMap((t, i) => (moves(t) ? [i] : []));
const moveFrame = (data, traces) => ({
  traces, data: traces.map((i) => Object.fromEntries(DATA_KEYS.filter((k) => k in data[i]).map((k) => [k, data[i][k]]))),
});
function shape(fig) {
  const strip = (t) => (moves(t) ? Object.fromEntries(Object.entries(t).map(([k, v]) => [k, DATA_KEYS.includes(k) || v])) : t);
  const layout = Object.fromEntries(Object.entries(fig.layout).map(
    ([k, v]) => [k, (isAxis(k) && v.range ? { ...v, range: true } : k === "title" ? { ...v, text: true } : k === "shapes" || v)]));
  return JSON.stringify([layout, fig.data.map(strip)]);
}
const onScreen = {}; // panel -> what plan() compares a new figure with (screenEntry)
// The figure on screen as plan() compares a new one with it: its shape, axis ranges (held: those
// asked for; shown: JSON of those plotly drew, null until drawn), shapes and lines' data (JSON;
// typed arrays come as base64 text).
function screenEntry(fig, figShape, held, shown) {
  return {
    shape: figShape, ranges: JSON.stringify(held), held, shown,
    shapes: JSON.stringify(fig.layout.shapes || []),
    data: fig.data.map((t) => (moves(t) ? JSON.stringify(DATA_KEYS.map((k) => t[k])) : null)),
  };
}

// How a panel takes its new figure: {frame, relayout} to move it (Plotly.relayout when that has
// anything, then Plotly.animate when the lines changed), or null to draw it (Plotly.react).
function plan(div, key, fig) {
  const last = onScreen[key];
  const figShape = shape(fig); // (JSON of the whole figure but its lines: once per panel)
  const same = Boolean(last && div.data && last.shape === figShape);
  // The user zoomed (the ranges on screen are not those plotly drew): the figure keeps the
  // ranges it had, so that plotly keeps the user's view (uirevision keeps a user's edit only
  // while the figure's own value stays); a double-click goes back to them.
  const zoomed = same && last.shown && JSON.stringify(axisRanges(div.layout)) !== last.shown;
  if (zoomed) {
    for (const [k, r] of Object.entries(last.held)) if (fig.layout[k] && r) fig.layout[k] = { ...fig.layout[k], range: r };
  }
  const held = axisRanges(fig.layout);
  // (shown: while the user's zoom stays, that of the same ranges before.)
  const entry = (onScreen[key] = screenEntry(fig, figShape, held, zoomed ? last.shown : null));
  const newRanges = same && entry.ranges !== last.ranges;
  const traces = lineIndices(fig);
  if (!same || (traces.length && traces.length < fig.data.length)) return null;
  // New ranges where an axis is scaled to another (the task plane): drawn anew. plotly's relayout
  // redoes the constraints there, which costs more than Plotly.react (33-40 ms against 23 in the
  // page alone).
  if (newRanges && Object.keys(fig.layout).some((k) => isAxis(k) && fig.layout[k].scaleanchor)) return null;
  // Only the lines that changed move (a new map leaves the pseudoinverse's as they are).
  const changed = traces.filter((i) => entry.data[i] !== last.data[i]);
  const frame = changed.length ? moveFrame(fig.data, changed) : null;
  // Before the move, a relayout: a new title text (the h panel's E1/E2), and the new axis
  // ranges, as a zoom sets them (the ranges of an animation frame miss stacked axes): only the
  // axes whose range changed, each of which plotly redraws.
  const relayout = {};
  const title = (fig.layout.title || {}).text;
  if (title !== ((div.layout || {}).title || {}).text) relayout["title.text"] = title;
  if (newRanges) {
    for (const [k, r] of Object.entries(held)) {
      if (r && JSON.stringify(r) !== JSON.stringify(last.held[k])) relayout[`${k}.range`] = r;
    }
  }
  if (entry.shapes !== last.shapes) relayout.shapes = fig.layout.shapes || [];
  return { frame, relayout };
}

// The panel's own buttons (once): save it as PNG or SVG, as plotly draws it.
function panelTools(div, key) {
  if (div.querySelector(":scope > .panel-tools")) return;
  const save = (format) => el("button", {
    type: "button", className: "tool", title: `save this panel as ${format.toUpperCase()}`,
    onclick: () => Plotly.downloadImage(div, { format, filename: `jik-${key}`, scale: format === "png" ? 2 : 1 }),
  }, format.toUpperCase());
  div.append(el("div", { className: "panel-tools", title: "drag to zoom, double-click to reset" }, save("png"), save("svg")));
}

const drawn = {}; // panel -> digest of the figure on screen
async function drawFigures(figures, digests = {}, robot = null) {
  const pre = (robot && ahead.robots[robot]) || {};
  if (robot) delete ahead.robots[robot];
  try {
    await Promise.all(Object.entries(figures).map(([key, fig]) => {
      const div = document.getElementById(`plot-${key}`);
      if (!div || (digests[key] && drawn[key] === digests[key])) return null; // unchanged panel
      drawn[key] = digests[key];
      if (pre[key] && pre[key].digest === digests[key] && pre[key].width === div.getBoundingClientRect().width) {
        showAhead(div, pre[key].div, key, fig);
        return null;
      }
      if (isTable(fig)) {
        onScreen[key] = null;
        drawTable(div, fig);
        return null;
      }
      div.classList.remove("html-table");
      const move = plan(div, key, fig); // (before plotly fills the layout in)
      const p = move
        ? (Object.keys(move.relayout).length ? Plotly.relayout(div, move.relayout) : Promise.resolve())
          .then(() => !move.frame || Plotly.animate(div, move.frame, MOVE))
        : Plotly.react(div, fig.data, fig.layout, PLOT_CONFIG);
      panelTools(div, key);
      return p.then(() => {
        if (onScreen[key] && onScreen[key].shown === null) onScreen[key].shown = JSON.stringify(axisRanges(div.layout));
      });
    }));
  } finally {
    discard(Object.values(pre).filter((p) => p.div.closest(".ahead"))); // (those not shown)
  }
}

// Another robot's panels, drawn off screen from an "ahead" event (its default state, solved
// while the page was idle): a switch to that robot shows them at once instead of drawing four
// plotly figures, when the result's figure is the same.
const ahead = { robots: {}, tokens: {} }; // robots: robot -> panel -> {div, digest, width}
function discard(panels) {
  for (const p of panels) { Plotly.purge(p.div); p.div.remove(); }
}
async function onAhead(msg) {
  if (!jik.state || msg.robot === jik.state.robot) return;
  const have = ahead.robots[msg.robot];
  const keys = Object.keys(msg.figures).filter((k) => have && have[k]);
  if (keys.length && keys.length === Object.keys(have).length && keys.every((k) => have[k].digest === msg.digests[k]
    && have[k].width === document.getElementById(`plot-${k}`).getBoundingClientRect().width)) return; // (drawn already)
  const token = (ahead.tokens[msg.robot] = (ahead.tokens[msg.robot] || 0) + 1); // (a newer one stops this)
  discard(Object.values(ahead.robots[msg.robot] || {}));
  delete ahead.robots[msg.robot];
  let box = document.querySelector(".ahead");
  if (!box) {
    box = el("div", { className: "ahead", style: "position:absolute;left:-10000px;top:0" });
    box.setAttribute("aria-hidden", "true");
    document.body.append(box);
  }
  const panels = {};
  for (const [key, fig] of Object.entries(msg.figures)) {
    const visible = document.getElementById(`plot-${key}`);
    if (!visible || isTable(fig) || !fig.data.length) continue;
    // Between panels: a result that came meanwhile is drawn first.
    await new Promise((r) => setTimeout(r, 0));
    if (token !== ahead.tokens[msg.robot] || msg.robot === jik.state.robot) break;
    const div = el("div", { className: visible.className.replace(/\bstale\b/, "") });
    const width = visible.getBoundingClientRect().width; // (fractional, as plotly takes it; shown only at this width)
    div.style.width = `${width}px`;
    box.append(div);
    await Plotly.react(div, fig.data, fig.layout, PLOT_CONFIG);
    panels[key] = { div, digest: msg.digests[key], width };
  }
  if (token === ahead.tokens[msg.robot] && msg.robot !== jik.state.robot) ahead.robots[msg.robot] = panels;
  else discard(Object.values(panels));
}
function showAhead(div, pre, key, fig) {
  pre.id = div.id;
  pre.className = div.className;
  pre.classList.remove("html-table");
  pre.style.width = "";
  Plotly.purge(div);
  div.replaceWith(pre);
  panelTools(pre, key);
  onScreen[key] = screenEntry(fig, shape(fig), axisRanges(fig.layout), JSON.stringify(axisRanges(pre.layout)));
}

async function onResult(msg) {
  if (msg.generation < jik.shownGeneration) return;
  if (!jik.state) onState({ state: msg.state, generation: msg.generation });
  await drawFigures(msg.figures, msg.digests, msg.state.robot);
  // Panels the second phase redraws (E1/E2) are dimmed until then, not redrawn empty.
  for (const key of msg.stale || []) {
    const div = document.getElementById(`plot-${key}`);
    if (div) div.classList.add("stale");
    drawn[key] = undefined;
  }
  const now = performance.now();
  jik.shownGeneration = msg.generation;
  document.body.dataset.generation = msg.generation;
  document.body.dataset.robot = msg.state.robot;
  for (const [before, since] of [...jik.pending]) {
    if (msg.generation > before) {
      const g = before;
      jik.lastLatency = { generation: msg.generation, ms: now - since };
      jik.pending.delete(g);
    }
  }
  showProgress(1, 0);
  renderVerdict(msg);
  const t = msg.timing;
  const lat = jik.lastLatency && jik.lastLatency.generation === msg.generation ? ` · control → plots ${Math.round(jik.lastLatency.ms)} ms` : "";
  $("#timing").textContent = `generation ${msg.generation}: compute ${Math.round(1000 * t.compute)} ms, figures ${Math.round(1000 * t.figures)} ms${lat}`;
  setStatus(msg.generation < jik.generation ? `computing generation ${jik.generation}…` : `up to date (generation ${msg.generation})`);
}

function renderVerdict(msg) {
  const p = msg.summary.pseudoinverse;
  const e = msg.summary.extended;
  const box = $("#verdict");
  const fail = [p, e].filter((s) => !s.success).map((s) => s.message);
  if (msg.state.task === "path" && p.drift.length && e.drift.length) {
    const n = Math.min(p.drift.length, e.drift.length);
    box.innerHTML = `After <b>${n}</b> cycle${n > 1 ? "s" : ""} of the closed path, the joints of the
      <b class="p">pseudoinverse</b> end <b class="p">${fmt(p.drift[n - 1])}</b> away from x0 and the drift grows each cycle;
      the <b class="e">extended Jacobian</b> returns to within <b class="e">${fmt(e.drift[n - 1])}</b>.
      <span class="why">Why: J<sup>P#</sup> picks the minimum-norm joint velocity, which has no memory of the start, so a
      closed task path need not close in the joints. J<sup>E#</sup> adds the equation h(x) = h(x0) (h changed by
      ${e.h_change === null ? "—" : fmt(e.h_change)} along its run): each task point then has one configuration on that level set,
      so closed task paths give closed joint paths.</span>`;
  } else if (!fail.length) {
    box.innerHTML = `Both algorithms drive the task error to the target: <b class="p">pseudoinverse</b> ${p.message};
      <b class="e">extended Jacobian</b> ${e.message}.
      <span class="why">The extended Jacobian keeps h constant (eq. (12)); compare the paths and the controls.</span>`;
  } else {
    box.innerHTML = `<b class="p">pseudoinverse</b>: ${p.message}. <b class="e">extended Jacobian</b>: ${e.message}.`;
  }
  if (fail.length) box.innerHTML += ` <span class="error">Stopped: ${fail.join(" · ")}</span>`;
}

async function onFunctionals(msg) {
  if (msg.generation !== jik.shownGeneration) return;
  if (msg.figures) await drawFigures(msg.figures, msg.digests);
  for (const key of Object.keys(msg.figures || {})) {
    const div = document.getElementById(`plot-${key}`);
    if (div) div.classList.remove("stale");
  }
  // Only a title changed: relayout it instead of redrawing the panel (when it differs).
  await Promise.all(Object.entries(msg.titles || {}).map(([key, text]) => {
    const div = document.getElementById(`plot-${key}`);
    if (!div || !div.layout || (div.layout.title || {}).text === text) return null;
    return Plotly.relayout(div, { "title.text": text }); // (the panel can still move: see shape)
  }));
}

function connect() {
  const source = new EventSource(api("/events"));
  const on = (kind, fn) => source.addEventListener(kind, (ev) => fn(JSON.parse(ev.data)));
  let chain = Promise.resolve();
  const serial = (fn) => (msg) => { chain = chain.then(() => fn(msg)).catch((err) => setStatus(String(err), true)); };
  on("state", onState);
  on("progress", (msg) => { if (msg.generation === jik.generation) showProgress(msg.fraction, msg.elapsed); });
  on("result", serial(onResult));
  on("refused", onRefused);
  on("functionals", serial(onFunctionals));
  on("ahead", (msg) => { onAhead(msg).catch((err) => console.warn("drawing ahead:", err)); });
  // The server's "error" events carry data; the connection's own error events do not (both
  // reach the "error" listeners).
  source.addEventListener("error", (ev) => {
    if (ev.data === undefined) {
      setStatus("connection lost; reconnecting…", true);
      return;
    }
    const msg = JSON.parse(ev.data);
    if (msg.generation === jik.generation) { showProgress(1, 0); setStatus(msg.message, true); }
  });
}

// A change the session refused (from this page or from the scene): the controls show the
// values in force again, and the refusal stays in the header until the next change.
function onRefused(msg) {
  jik.pending.delete(jik.generation);
  onState({ state: msg.state, generation: msg.generation });
  setStatus(`refused (${msg.source === "scene" ? "in the 3D scene" : "here"}): ${msg.message}`, true);
}

// ---------------------------------------------------------------- the session and its link
// The page's URL holds the state (?state=<JSON of the dashboard's fields>): a copied link, or a
// reload, starts a new session with the same state.
function rememberInUrl(state) {
  const url = new URL(location.href);
  url.searchParams.set("state", JSON.stringify(state));
  history.replaceState(null, "", url);
}
function stateFromUrl() {
  const text = new URL(location.href).searchParams.get("state");
  if (!text) return {};
  try {
    const state = JSON.parse(text);
    return state && typeof state === "object" && !Array.isArray(state) ? state : {};
  } catch (err) {
    setStatus(`the link's state is not valid JSON (${err.message}); starting from the defaults`, true);
    return {};
  }
}
// A software WebGL renderer (no GPU) draws the scene without shadows and environment map.
function softwareRenderer() {
  try {
    const gl = document.createElement("canvas").getContext("webgl");
    const info = gl && gl.getExtension("WEBGL_debug_renderer_info");
    const name = info ? gl.getParameter(info.UNMASKED_RENDERER_WEBGL) : "";
    return /swiftshader|llvmpipe|software|softpipe/i.test(name);
  } catch (err) {
    return false;
  }
}
async function openSession(state) {
  const res = await fetch("/api/sessions", {
    method: "POST", headers: { "Content-Type": "application/json" },
    body: JSON.stringify({ state, low_end: softwareRenderer() }),
  });
  const body = await res.json();
  if (res.status === 422 && Object.keys(state).length) {
    setStatus(`the link's state was refused (${body.detail.map((d) => d.msg).join("; ")}); starting from the defaults`, true);
    return openSession({});
  }
  if (!res.ok) throw new Error(typeof body.detail === "string" ? body.detail : JSON.stringify(body.detail));
  return body;
}
function copyLink() {
  const button = $("#copy-link");
  navigator.clipboard.writeText(location.href).then(
    () => { button.textContent = "link copied"; },
    () => { button.textContent = "copy the address bar"; },
  );
}

async function main() {
  for (const a of ["pseudoinverse", "extended"]) document.documentElement.style.setProperty(`--${a}`, "");
  const [config, catalogue] = await Promise.all([
    fetch("/api/dashboard/config").then((r) => r.json()),
    fetch("/robots").then((r) => r.json()),
  ]);
  jik.config = config;
  jik.catalogue = catalogue;
  for (const [a, c] of Object.entries(config.colors)) document.documentElement.style.setProperty(`--${a}`, c);
  const session = await openSession(stateFromUrl());
  jik.session = session.id;
  $("#export-json").href = api("/export.json");
  $("#export-csv").href = api("/export.csv");
  $("#copy-link").addEventListener("click", copyLink);
  onState({ state: session.state, generation: session.generation });
  const frame = $("#scene");
  if (session.scene) {
    const ws = `${location.protocol === "https:" ? "wss" : "ws"}://${location.host}${api("/scene")}`;
    frame.src = `/scene/?websocket=${encodeURIComponent(ws)}`;
  } else {
    frame.hidden = true;
    const note = $("#scene-note");
    note.hidden = false;
    note.textContent = "The 3D scene runs with `jik serve`.";
  }
  connect();
  // A closing tab ends its session at once (otherwise it expires when idle); a tab restored from
  // the browser's page cache then starts a new one from its URL.
  addEventListener("pagehide", () => { fetch(api(""), { method: "DELETE", keepalive: true }); });
  addEventListener("pageshow", (ev) => { if (ev.persisted) location.reload(); });
}

main().catch((err) => setStatus(String(err), true));
