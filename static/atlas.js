// The atlas panel: the repeatability atlas of the session's current state (app/dashboard/atlas.py).
// It is a job of the REST API's atlas jobs (their limits apply): started through the session
// (POST /api/sessions/{id}/atlas), followed until done (GET .../atlas/{job}: progress, then the
// heatmap), cancelled by DELETE /atlas/{job}. A cell of the heatmap is a start: a click sets the
// session's x0 there (and the path's scale), so the main view recomputes from that start. Its
// CSV button downloads the table of the atlas shown (GET .../atlas/{job}/table.csv: the engine's
// AtlasResult.columns(), a row per start, algorithm and cycle).
import { api } from "./api.js";
import { parseNumber } from "./controls.js";
import { $, el, fieldNote, fmt, markInvalid } from "./dom.js";
import { drawFigure, followWidth, panelHead } from "./panels.js";

const POLL_MS = 250;
// token: bumped to stop following a job; job: the one followed; shown: the atlas on screen;
// covers: the atlasKey of each state it is the atlas of (the state it was computed for, and a
// scaled path's state that a click on a cell of that band set).
const atlas = { token: 0, job: null, shown: null, covers: new Set(), state: null, send: null, polling: null };

const detail = (body) => (Array.isArray(body.detail) ? body.detail.map((d) => d.msg).join("; ") : body.detail);
// What an atlas depends on in a state (not x0: every start of the curve is in it).
// (posture's rest is left out: an atlas pulls each run toward its own start)
const atlasKey = (s) => {
  const { rest, ...parameters } = s.algorithm_parameters || {};
  return JSON.stringify([s.robot, s.robot_parameters, s.augmentation, s.augmentation_parameters, s.gamma, s.mode, s.tolerance, s.task, s.path, s.algorithms, parameters]);
};

function say(text, error = false) {
  const status = $("#atlas-status");
  status.textContent = text;
  status.classList.toggle("error", error);
}

function showProgress(body) {
  $("#atlas-progress-box").hidden = !body;
  $("#atlas-compute").disabled = Boolean(body);
  if (!body) return;
  const pct = Math.round(100 * body.progress);
  $("#atlas-bar").style.width = `${pct}%`;
  $("#atlas-progress-text").textContent = body.status === "queued"
    ? `waiting: ${body.message || "another atlas is computing (one at a time)"}`
    : `computing ${pct}% (${body.runs_done} of ${body.runs} starts, ${fmt(body.elapsed_s, 1)} s)`;
}

// The request of the panel's boxes, or null when a box does not hold what it should: each such
// box is marked as a refused control is (controls.js), quoting the text, and the status says
// which; nothing is sent with a value the user did not type. An empty starts box is refused (not
// taken as the server's 256); an empty cycles or scales box is the controls' cycles, the path
// as it is.
function request() {
  const body = {};
  const refused = [];
  for (const name of ["starts", "cycles"]) {
    const typed = $(`#atlas-${name}`).value.trim();
    const n = parseNumber(typed);
    if (n !== null) body[name] = n;
    else if (typed) refused.push([name, `“${typed}” is not a number`]);
    else if (name === "starts") refused.push([name, "give the number of starts"]);
  }
  const scales = $("#atlas-scales").value.split(/[,;\s]+/).filter(Boolean);
  const bad = scales.find((s) => parseNumber(s) === null);
  if (bad !== undefined) refused.push(["scales", `“${bad}” is not a number`]);
  else if (scales.length) body.scales = scales.map(Number);
  for (const [name, why] of refused) refuse(name, `${why}; nothing was sent`);
  if (!refused.length) return body;
  say(`not sent: ${refused.map(([name, why]) => `${name}: ${why}`).join("; ")}`, true);
  return null;
}

// A box of the panel (``name``: starts, cycles, scales) refused, here or by the server.
function refuse(name, text) {
  const row = $(`#atlas-${name}`).closest("label");
  fieldNote(row, text);
  markInvalid(row, true);
}

function clearRefusals() {
  for (const note of document.querySelectorAll(".atlas-bar .field-error")) {
    markInvalid(note.parentElement, false);
    note.remove();
  }
}

// The server's refusal of the request: beside the boxes it is about (its fields, by their
// location in the body), with what was typed there.
const BOXES = ["starts", "cycles", "scales"];
function refusedBoxes(body) {
  for (const d of Array.isArray(body.detail) ? body.detail : []) {
    const name = d.loc?.[0] === "body" ? d.loc[1] : null;
    const box = BOXES.includes(name) && $(`#atlas-${name}`);
    if (box) refuse(name, `“${box.value.trim()}” was refused: ${d.msg}`);
  }
}

async function start(state) {
  clearRefusals();
  const body = request();
  if (!body) return;
  const token = ++atlas.token;
  say("starting the atlas…");
  showProgress({ status: "running", progress: 0, runs_done: 0, runs: body.starts || 0, elapsed_s: 0 });
  try {
    const res = await fetch(api("/atlas"), {
      method: "POST", headers: { "Content-Type": "application/json" }, body: JSON.stringify(body),
    });
    const job = await res.json();
    if (token !== atlas.token) return;
    if (!res.ok) {
      refusedBoxes(job);
      throw new Error(`the atlas was refused: ${detail(job)}`);
    }
    atlas.job = job.id;
    await follow(job.id, token, atlasKey(state()));
  } catch (err) {
    if (token !== atlas.token) return;
    showProgress(null);
    say(err.message, true);
  }
}

async function follow(id, token, key) {
  for (;;) {
    atlas.polling = fetch(api(`/atlas/${id}`));
    const res = await atlas.polling;
    const body = await res.json();
    if (token !== atlas.token) return;
    if (!res.ok) throw new Error(`the atlas was lost: ${detail(body)}`);
    if (body.status === "done") return draw(body, key);
    if (body.status === "failed") throw new Error(`the atlas failed: ${body.error}`);
    if (body.status === "cancelled") throw new Error("the atlas was cancelled on the server");
    showProgress(body);
    await new Promise((resolve) => { setTimeout(resolve, POLL_MS); });
    if (token !== atlas.token) return;
  }
}

function cancel() {
  const id = atlas.job;
  atlas.token += 1; // (stop following it)
  atlas.job = null;
  showProgress(null);
  say(atlas.shown ? "Atlas cancelled; the heatmap below is the previous atlas." : "Atlas cancelled.");
  // (after a poll in flight: the job is still there for it, and no 404 is logged)
  const polled = atlas.polling || Promise.resolve();
  if (id) polled.catch(() => {}).then(() => fetch(`/atlas/${id}`, { method: "DELETE" })).catch(() => {});
}

async function draw(body, key) {
  atlas.job = null;
  atlas.shown = body;
  atlas.covers = new Set([key]);
  atlasState(atlas.state());
  const div = $("#plot-atlas");
  div.classList.add("drawn");
  // Its height is the figure's (rows of cycles and scales); the width follows the window.
  // (plotly's responsive mode would take the height from the box too.)
  const layout = { ...body.figure.layout, width: div.clientWidth };
  await drawFigure(div, body.figure.data, layout);
  // (plotly puts its plot first: the head and its help go back above it)
  div.prepend(...div.querySelectorAll(":scope > .panel-head, :scope > .panel-help"));
  if (!div.dataset.clicks) {
    div.dataset.clicks = "on";
    div.on("plotly_click", (ev) => moveTo(ev.points[0]));
    followWidth(div, (d) => d.clientWidth);
  }
  showProgress(null);
  for (const button of div.querySelectorAll(".panel-tools .tool")) button.disabled = false;
  // body.runs counts the starts times the paths (a path per scale); every chosen algorithm runs
  // each of them.
  const k = body.request.algorithms.length;
  const paths = (body.request.scales || [1]).length;
  const count = (n, noun) => `${n} ${noun}${n === 1 ? "" : "s"}`;
  const per = [count(body.runs / paths, "start"), ...(paths > 1 ? [count(paths, "path scale")] : []), count(k, "algorithm")].join(" x ");
  say(`Atlas done: ${body.runs * k} runs (${per}) of ${count(body.request.cycles, "cycle")} in ${fmt(body.elapsed_s, 1)} s. Click a cell to move the main view to that start.`);
  div.dataset.runs = body.runs;
}

// The table of the atlas on screen, as the server writes it (its name from the server): asked
// for first, so that a job the server no longer keeps is said in the panel, then saved by a link
// (the browser streams it to disk).
async function saveTable() {
  if (!atlas.shown) return;
  const url = api(`/atlas/${atlas.shown.id}/table.csv`);
  const res = await fetch(url);
  if (!res.ok) {
    const body = await res.json().catch(() => ({}));
    say(`The table of this atlas is gone: ${detail(body) || res.status}. Compute the atlas again.`, true);
    return;
  }
  await res.body.cancel();
  const link = el("a", { href: url, download: "" });
  document.body.append(link);
  link.click();
  link.remove();
}

// A cell's start (and its path's scale) as the session's state.
function moveTo(point) {
  const body = atlas.shown;
  if (!body || !point) return;
  const n = body.starts[0].length;
  const [row, col] = Array.isArray(point.pointNumber) ? point.pointNumber : [null, null];
  const run = Number.isFinite(point.customdata) ? point.customdata : (Math.floor(row / body.request.cycles) * n + col);
  const j = Math.floor(run / n);
  const i = run % n;
  const x0 = body.starts[j][i];
  const patch = { x0 };
  const scale = (body.request.scales || [1])[j];
  if (scale !== 1) {
    const path = body.paths[j];
    const given = body.request.path.slice(1); // (the state's path when computed)
    const home = path[0];
    patch.path = given.map((p) => p.map((v, d) => home[d] + scale * (v - home[d])));
  }
  atlas.covers.add(atlasKey({ ...atlas.state(), ...patch })); // (still this atlas: its band)
  // (plotly's click keeps the focus where it was: a control left with it, an x0 box typed in,
  // would keep its text and not show the start clicked)
  if ($("#controls").contains(document.activeElement)) document.activeElement.blur();
  atlas.send(patch);
  const s = body.request.scales ? `, path ×${scale}` : "";
  say(`Moved the main view to start ${i + 1} of ${n} (s = ${fmt(Number(point.x))}${s}): x0 = (${x0.map((v) => fmt(v)).join(", ")}).`);
}

// The current state changed: say when the atlas on screen is of another state.
export function atlasState(state) {
  const note = $("#atlas-outdated");
  if (note) note.hidden = !atlas.shown || atlas.covers.has(atlasKey(state));
}

// Build the panel (index.html's #atlas); ``state()`` is the session's current state, ``send``
// changes it (as the controls do).
export function atlasPanel(state, send) {
  atlas.send = send;
  atlas.state = state;
  const field = (label, input, help) => el("label", { title: help }, el("span", {}, label), input);
  // (text boxes, as the controls' exact values: a refusal quotes what was typed, which a number
  // box does not keep when it is not a number)
  const starts = el("input", { type: "text", inputMode: "numeric", id: "atlas-starts", value: "256" });
  const cycles = el("input", { type: "text", inputMode: "numeric", id: "atlas-cycles", placeholder: "as above" });
  const scales = el("input", { type: "text", id: "atlas-scales", placeholder: "1 (e.g. 0.5, 1, 1.5)" });
  const compute = el("button", { type: "button", id: "atlas-compute", onclick: () => start(state) }, "Compute atlas");
  const stop = el("button", { type: "button", id: "atlas-cancel", onclick: cancel, title: "stop this atlas" }, "Cancel");
  const progress = el("span", { id: "atlas-progress-box", className: "progress-box" },
    el("span", { className: "progress" }, el("span", { id: "atlas-bar", className: "bar" }), el("span", { id: "atlas-progress-text" })), stop);
  progress.hidden = true;
  const outdated = el("p", { id: "atlas-outdated", className: "note" }, "This atlas is of an earlier state (robot, map, path, algorithms, γ or mode): compute again for the current one.");
  outdated.hidden = true;
  const plot = el("div", { id: "plot-atlas", className: "panel full atlas-plot" });
  const key = el("span", { className: "key-list" },
    el("span", { className: "key" }, "colour: log10 of the drift ‖x − x0‖ after each cycle (its scale on the right)"),
    el("span", { className: "key" }, "one heatmap per chosen algorithm, named above it in its colour"));
  panelHead(plot, "atlas", true, key);
  plot.querySelector(".panel-tools").append(el("button", {
    type: "button", className: "tool", id: "atlas-csv", disabled: true, onclick: saveTable,
    title: "save the table of this atlas as CSV: a row per start, algorithm and cycle, with its drift",
  }, "CSV"));
  // (no atlas to save before the first is drawn: PNG and SVG are off until then, as CSV is)
  for (const button of plot.querySelectorAll(".panel-tools .tool:not(.info)")) button.disabled = true;
  $("#atlas").replaceChildren(
    el("h2", {}, "Repeatability atlas"),
    el("div", { className: "atlas-bar" },
      field("starts", starts, "starts on the self-motion curve of k(x0), 2 to 4096"),
      field("cycles", cycles, "cycles of the path per start (empty: the controls' cycles)"),
      field("path scales", scales, "scales of the path about k(x0), each a band of rows (empty: the path as it is)"),
      compute, progress),
    el("p", { id: "atlas-status", className: "atlas-status", role: "status" }, "Compute the atlas of the current robot, path and map: the drift of each chosen algorithm from every start of the self-motion curve of k(x0)."),
    outdated, plot);
}
