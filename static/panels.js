// The plotly panels: drawn from the figures of a session's results, moved in place when only
// their data, ranges, title or shapes changed, and drawn ahead (off screen) for a robot switch.
import { el, withErrataLinks } from "./dom.js";
import { saveImage, saveTable } from "./panel_exports.js";

// (not plotly's `responsive`: its resize sizes a figure to its panel, height too, and a panel's
// height follows its figure, so every figure fell to the panel's least height: followWidth)
const PLOT_CONFIG = {
  responsive: false,
  displaylogo: false,
  modeBarButtonsToRemove: ["toImage", "select2d", "lasso2d"],
};

// Plotly's toolbar stands upright in the right margin, from the top of the plots down (style.css
// places it by this variable), so that it covers neither the title above nor the plots.
function toolbarBesidePlots(div) {
  if (div._fullLayout) div.style.setProperty("--toolbar-top", `${div._fullLayout.margin.t}px`);
}

// A figure drawn anew (Plotly.react), its toolbar beside its plots.
export async function drawFigure(div, data, layout) {
  await Plotly.react(div, data, layout, PLOT_CONFIG);
  toolbarBesidePlots(div);
}

// A drawn figure follows its panel's width (``measure(div)``), its own height kept.
export function followWidth(div, measure) {
  new ResizeObserver(() => {
    const width = measure(div);
    if (div.layout && div._fullLayout && width && Math.abs(div._fullLayout.width - width) > 1) {
      Plotly.relayout(div, { width, height: div.layout.height });
    }
  }).observe(div);
}

// The page's configuration (/api/dashboard/config): colours, labels, line styles, panels' help.
let CONFIG = { colors: {}, labels: {}, styles: {}, panels: [] };

// The key of the algorithms: colour and line style (the same in every panel and in the
// header), and their robots in the 3D scene.
export function algorithmKey(withRobot = false) {
  return el("span", { className: "key-list" }, ...Object.keys(CONFIG.labels).map((a) => {
    const style = CONFIG.styles[a] || {};
    const sample = el("i", { className: "line-sample" });
    sample.style.borderTop = `3px ${{ solid: "solid", dot: "dotted" }[style.dash] || "dashed"} ${CONFIG.colors[a]}`;
    const words = withRobot ? `${CONFIG.labels[a]}: ${style.line}; ${style.robot} in the 3D scene` : CONFIG.labels[a];
    const key = el("span", { className: "key", dataset: { algorithm: a } }, sample, words);
    key.hidden = !chosen.includes(a);
    return key;
  }));
}

// The algorithms of the state on screen (the keys show those only).
let chosen = ["pseudoinverse", "extended"];
export function showChosen(algorithms) {
  chosen = algorithms;
  for (const key of document.querySelectorAll(".key[data-algorithm]")) key.hidden = !chosen.includes(key.dataset.algorithm);
}

// The panels' boxes, in the order and sizes the server gives (/api/dashboard/config).
export function layoutPanels(panels, config) {
  CONFIG = config;
  document.getElementById("panels").replaceChildren(
    ...panels.map((p) => el("div", { className: `panel ${p.size}`.trim(), id: `plot-${p.id}` })));
}

// A figure that is one plotly table is drawn as an HTML table: the same cells, drawn far faster
// than plotly's SVG table (docs/benchmarks.md).
function isTable(fig) {
  return fig.data.length === 1 && fig.data[0].type === "table";
}

function drawTable(div, fig, key) {
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
  const meta = fig.layout.meta || {};
  // Cells that differ from the paper's printed value: marked, the printed value on hover.
  for (const [col, row, printed] of meta.differs || []) {
    const td = body[row] && body[row].children[col];
    if (td) { td.classList.add("differs"); td.title = `printed: ${printed}`; }
  }
  div.classList.add("html-table");
  div.replaceChildren(
    el("h3", { className: "table-title" }, title),
    // (a region with the focus: a table wider than its panel scrolls by the arrow keys too)
    el("div", { className: "table-scroll", role: "region", tabIndex: 0, ariaLabel: title }, el("table", {}, el("thead", {}, head), el("tbody", {}, ...body))),
    ...(meta.notes || []).map((n) => el("p", { className: "table-note" }, ...withErrataLinks(n))),
  );
  panelHead(div, key, false);
}

// A figure that differs from the one on screen only in its lines' data, its axis ranges, its
// title text and its shapes (same styles, same contours) takes the new ranges, title and shapes
// by Plotly.relayout, then moves its lines with Plotly.animate: no redraw of the rest, a third
// of Plotly.react's cost. Both run in the same task, so that the browser paints the panel once:
// with the move first, plotly ran the relayout in a task after the next frame, which showed the
// new lines on the old axes. The server rounds the ranges (app/dashboard/plotting.py nice_range) and keeps
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
// shapes over its map (a contour, app/dashboard/map_figures.py), moved by the relayout alone.
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
    // (lines without points: an algorithm's run that stopped before a cycle ended)
    empty: fig.data.map((t) => moves(t) && Array.isArray(t.x) && t.x.length === 0),
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
  // A line that loses or gains all its points is drawn anew: Plotly.animate then drops the
  // figure's scatter layer, every line of it.
  if (changed.some((i) => entry.empty[i] || last.empty[i])) return null;
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

// A panel's head (once): the key of the algorithms, a "?" that shows what the panel is, and
// (plots) buttons that save it as PNG or SVG, with its legend and the state it shows.
// (legend: a key of the panel's own, instead of the algorithms'.)
export function panelHead(div, key, plot = true, legend = null) {
  if (div.querySelector(":scope > .panel-head")) return;
  const text = ([...CONFIG.panels, ...(CONFIG.tools || [])].find((p) => p.id === key) || {}).help || "";
  const help = el("p", { className: "panel-help", id: `help-${key}` }, text);
  help.hidden = true;
  // (named for a screen reader by what the help says first: "Repeatability", "Table 1 ...")
  const info = el("button", {
    type: "button", className: "tool info", title: "what this panel shows",
    "aria-label": `what this panel shows: ${text.split(/[:.(]/)[0].trim() || key}`,
    onclick: () => { help.hidden = !help.hidden; info.setAttribute("aria-expanded", String(!help.hidden)); },
  }, "?");
  info.setAttribute("aria-controls", help.id);
  info.setAttribute("aria-expanded", "false");
  // (the chosen algorithms' labels and colours: the caption names those drawn without a legend)
  const keys = () => chosen.map((a) => [CONFIG.labels[a], CONFIG.colors[a]]);
  const save = (format) => el("button", {
    type: "button", className: "tool", title: `save this panel as ${format.toUpperCase()}, with its legend and state`,
    onclick: () => saveImage(div, key, format, keys()),
  }, format.toUpperCase());
  const csv = el("button", {
    type: "button", className: "tool", title: "save this table as CSV, with its notes and the state it shows",
    onclick: () => saveTable(div, key),
  }, "CSV");
  const tools = el("div", { className: "panel-tools", title: plot ? "drag to zoom, double-click to reset" : "" },
    info, ...(plot ? [save("png"), save("svg")] : [csv]));
  div.prepend(el("div", { className: "panel-head" }, legend || algorithmKey(), tools), help);
}
// A plot's head, and its width following the panel's (as plotly measures a panel when it draws).
function panelTools(div, key) {
  panelHead(div, key, true);
  if (div.dataset.follows) return;
  div.dataset.follows = "on";
  followWidth(div, (d) => parseFloat(getComputedStyle(d).width));
}

export const drawn = {}; // panel -> digest of the figure on screen
export async function drawFigures(figures, digests = {}, robot = null) {
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
        drawTable(div, fig, key);
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
        toolbarBesidePlots(div);
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
export async function onAhead(msg, shownRobot) {
  if (msg.robot === shownRobot()) return;
  const have = ahead.robots[msg.robot];
  const keys = Object.keys(msg.figures).filter((k) => have && have[k]);
  if (keys.length && keys.length === Object.keys(have).length && keys.every((k) => have[k].digest === msg.digests[k]
    && have[k].width === document.getElementById(`plot-${k}`).getBoundingClientRect().width)) return; // (drawn already)
  const token = (ahead.tokens[msg.robot] = (ahead.tokens[msg.robot] || 0) + 1); // (a newer one stops this)
  discard(Object.values(ahead.robots[msg.robot] || {}));
  delete ahead.robots[msg.robot];
  let box = document.querySelector(".ahead");
  if (!box) {
    // (inert: its plots' toolbars are out of the Tab order and of screen readers)
    box = el("div", { className: "ahead", inert: true, style: "position:absolute;left:-10000px;top:0" });
    document.body.append(box);
  }
  const panels = {};
  for (const [key, fig] of Object.entries(msg.figures)) {
    const visible = document.getElementById(`plot-${key}`);
    if (!visible || isTable(fig) || !fig.data.length) continue;
    // Between panels: a result that came meanwhile is drawn first.
    await new Promise((r) => setTimeout(r, 0));
    if (token !== ahead.tokens[msg.robot] || msg.robot === shownRobot()) break;
    const div = el("div", { className: visible.className.replace(/\bstale\b/, "") });
    const width = visible.getBoundingClientRect().width; // (fractional, as plotly takes it; shown only at this width)
    div.style.width = `${width}px`;
    box.append(div);
    await drawFigure(div, fig.data, fig.layout);
    panels[key] = { div, digest: msg.digests[key], width };
  }
  if (token === ahead.tokens[msg.robot] && msg.robot !== shownRobot()) ahead.robots[msg.robot] = panels;
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


// Panels that a result's second phase redraws (E1/E2) are dimmed until then, not drawn empty,
// with what they wait for.
export function markStale(keys, waiting = "computing E1, E2 for the new state…") {
  for (const key of keys) {
    const div = document.getElementById(`plot-${key}`);
    if (div) {
      div.classList.add("stale");
      div.dataset.waiting = waiting;
    }
    drawn[key] = undefined;
  }
}

// A result's second phase: its figures, or only new titles (relayouted, not redrawn).
export async function applyFunctionals(msg) {
  if (msg.figures) await drawFigures(msg.figures, msg.digests);
  for (const key of Object.keys(msg.figures || {})) {
    const div = document.getElementById(`plot-${key}`);
    if (div) div.classList.remove("stale");
  }
  await Promise.all(Object.entries(msg.titles || {}).map(([key, text]) => {
    const div = document.getElementById(`plot-${key}`);
    if (!div || !div.layout || (div.layout.title || {}).text === text) return null;
    return Plotly.relayout(div, { "title.text": text }); // (the panel can still move: see shape)
  }));
}
