// jik dashboard: one session per tab. The page opens its session from the state in its URL,
// builds its controls from the session's control specification, follows the session's events
// and draws its panels; the 3D scene (iframe, viser) shows and changes the same session.
import { change, endOnClose, follow, openSession, session, api } from "./api.js";
import { onNotSent, showControls, showRefusal, showStopped } from "./controls.js";
import { $, el, fmt, withErrataLinks } from "./dom.js";
import { robotEditor } from "./editor.js";
import { acceptedPost, copyLink, followHistory, refusedPost, remember, stateFromUrl, travelledTo } from "./link.js";
import { setExportNote } from "./panel_exports.js";
import { algorithmKey, applyFunctionals, drawFigures, layoutPanels, markStale, onAhead, showChosen } from "./panels.js";
import { atlasPanel, atlasState } from "./atlas.js";
import { afterSecond, cancelSecond, clearCancelled, secondWanted } from "./second.js";

// second: the generation whose second phase runs (its progress came, its functionals not yet);
// stopped: the runs of the result on screen, where they stopped (controls.js's showStopped).
const page = { config: null, state: null, shown: 0, shownState: null, editor: null, second: null, stopped: {} };
const send = (patch) => {
  setNotice("");
  change(patch, (message) => setStatus(message, true), accepted, (post) => refusedPost(post, page.state));
};

// A change accepted without a new generation (the values in force typed back after a refusal):
// the result on screen is the state's, and the header and the controls say so instead of the
// old refusal (the send took every note away: the marks of the result's stopped runs are back).
function accepted(body, post) {
  acceptedPost(body, post);
  // (a definition applied that is the one in force makes no new state event: its note says so)
  page.editor.show(body.state);
  if (body.generation !== page.shown || session.generation !== page.shown) return;
  setStatus(`up to date (generation ${page.shown})`);
  showStopped(page.stopped);
}

function setStatus(text, error = false) {
  const s = $("#status-text");
  s.textContent = text;
  s.classList.toggle("error", error);
}

// A note that stays beside the status until the user's next change (a refused link's state).
function setNotice(text) {
  const n = $("#notice");
  n.textContent = text;
  n.hidden = !text;
}

// Only computations running longer than the server's progress_after get a progress bar, with
// what they compute: the runs of a new state (the plots meanwhile are the previous result's),
// or the second phase of the result on screen (E1/E2 and their sensitivity, h on a grid).
// Cancel stops the one shown (page.phase).
function showProgress(fraction, elapsed, phase = "runs", what = "") {
  // (a second phase's bar, once shown, stays until it ends: its timer can show it before an
  // event sent a little earlier arrives)
  const shown = phase === "second" && page.phase === "second";
  const busy = (elapsed > page.config.progress_after || shown) && fraction < 1;
  const runs = phase === "runs";
  $("#progress-box").hidden = !busy;
  if (runs) {
    $("#panels").classList.toggle("pending", busy);
    $("#verdict").classList.toggle("pending", busy);
  }
  page.phase = busy ? phase : null;
  const button = $("#cancel");
  button.disabled = runs && !page.shownState;
  button.title = runs ? "stop this computation and go back to the values of the result on screen"
    : `stop computing ${what}: the result on screen stays, without E1, E2 and their sensitivity`;
  // (a fraction null is work whose progress is not known: a synthesis in a compute worker)
  const percent = fraction === null ? null : Math.round(100 * fraction);
  $("#progress-bar").style.width = `${percent ?? 0}%`;
  // (the runs of a new state may first wait for their map's synthesis, which says so)
  const doing = runs && (!what || what === "the runs") ? "computing" : `computing ${what}`;
  $("#progress-text").textContent = percent === null ? `${doing}…` : `${doing} ${percent}%`;
}

function onState(msg, force = false) {
  page.state = msg.state;
  session.generation = Math.max(session.generation, msg.generation);
  showControls(msg, send, force || travelledTo(msg));
  page.editor.show(msg.state, msg.type === "refused");
  remember(msg);
  atlasState(msg.state);
  if (msg.generation > page.shown) setStatus(`computing generation ${msg.generation}…`);
}

// A change the session refused (made here or in the scene): the controls show the values in
// force, and the refusal stays in the header until the next result.
function onRefused(msg) {
  onState(msg, true);
  const where = msg.source === "scene" ? "in the 3D scene" : "here";
  setStatus(`refused (${where}): ${msg.message}`, true);
  if (msg.field && !page.editor.refused(msg.field, msg.message)) showRefusal(msg.about, msg.message);
}

async function onResult(msg) {
  if (msg.generation < page.shown) return;
  showChosen(msg.state.algorithms || ["pseudoinverse", "extended"]);
  await drawFigures(msg.figures, msg.digests, msg.state.robot);
  clearCancelled();
  markStale(msg.stale || []);
  page.shown = msg.generation;
  page.shownState = msg.state;
  setExportNote(`jik · generation ${msg.generation} · ${describe(msg.state)}`,
    `${msg.state.augmentation}-${msg.state.mode}-g${msg.generation}`);
  document.body.dataset.generation = msg.generation;
  document.body.dataset.robot = msg.state.robot;
  showProgress(1, 0);
  renderVerdict(msg);
  page.stopped = msg.generation === session.generation ? msg.summary : {}; // (not the controls' state: none)
  showStopped(page.stopped);
  $("#panels").classList.remove("outdated");
  delete document.body.dataset.failed;
  exportLinks(msg.generation);
  const t = msg.timing;
  $("#timing").textContent = `generation ${msg.generation}: compute ${Math.round(1000 * t.compute)} ms, figures ${Math.round(1000 * t.figures)} ms`;
  // (the note goes with the result that follows the cancel: the cancelled generation's own
  // result can still come first, when its last leg was running)
  const after = page.cancelled && msg.generation > page.cancelled.running;
  const note = after ? `; generation ${page.cancelled.running} was cancelled` : "";
  if (after) page.cancelled = null;
  setStatus(msg.generation < session.generation ? `computing generation ${session.generation}…` : `up to date (generation ${msg.generation})${note}`);
}

// The verdict: the server's sentences about this result (app/dashboard/verdict.py), each
// coloured by the algorithm it is about.
function renderVerdict(msg) {
  const box = $("#verdict");
  box.classList.remove("failed");
  box.replaceChildren(...msg.verdict.map((s) => {
    const p = el("p", {
      className: [s.role, s.algorithm ? ALGORITHM_CLASS[s.algorithm] || "" : ""].join(" ").trim(),
      dataset: s.algorithm ? { algorithm: s.algorithm } : {},
    }, ...withErrataLinks(s.text));
    if (s.algorithm) p.style.setProperty("--alg", `var(--${s.algorithm})`);
    return p;
  }));
}
const ALGORITHM_CLASS = { pseudoinverse: "p", extended: "e" };

// A state in a few words: which result a failure leaves on screen.
function describe(state) {
  const params = Object.entries(state.robot_parameters)
    .map(([k, v]) => `${k} = ${Array.isArray(v) ? `(${v.map((x) => fmt(x, 2)).join(", ")})` : fmt(v, 2)}`);
  return [state.robot, `${state.mode} mode`, `γ = ${fmt(state.gamma)}`, ...params, state.task === "path" ? `closed path, ${state.cycles} cycles` : "single target"].join(", ");
}

// A generation that failed: its message where the result would be, and which result (if any)
// the plots still show, dimmed.
function onError(msg) {
  if (msg.generation !== session.generation) return;
  showProgress(1, 0);
  setStatus(`generation ${msg.generation} failed`, true);
  document.body.dataset.failed = msg.generation;
  const box = $("#verdict");
  box.classList.add("failed");
  const shown = msg.shown && page.shown ? `The plots below still show generation ${msg.shown.generation} (${describe(msg.shown.state)}), not the controls' values.` : "No result is on screen.";
  box.replaceChildren(
    el("p", { className: "failure", id: "failure" }, `Generation ${msg.generation} failed: ${msg.message}`),
    el("p", { className: "still", id: "still-shown" }, shown),
  );
  $("#panels").classList.add("outdated");
  exportLinks(null, `generation ${msg.generation} failed: nothing current to export`);
}

// The footer's export links: of the generation on screen (named), or off after a failure.
function exportLinks(generation, why = "") {
  for (const [id, path, kind] of [["#export-json", "/export.json", "JSON"], ["#export-csv", "/export.csv", "CSV"]]) {
    const a = $(id);
    if (generation === null) {
      a.removeAttribute("href");
      a.setAttribute("aria-disabled", "true");
      a.title = why;
      a.textContent = `export ${kind} (off: ${why})`;
    } else {
      a.href = api(`${path}?generation=${generation}`); // (the file is the one named)
      a.removeAttribute("aria-disabled");
      a.title = `generation ${generation}: the plots on screen, with its state, verdict, drift and leg ends`;
      a.textContent = `export ${kind} (generation ${generation})`;
    }
  }
}

// Cancel the computation in progress. The runs of a new state: the session goes back to the
// values of the result on screen (a newer generation stops the running one between legs; that
// result is cached). The second phase of the result on screen: it stops, the result stays.
function cancel() {
  if (page.phase === "second") {
    $("#progress-box").hidden = true;
    page.phase = null;
    cancelSecond(page.shown, setStatus);
    return;
  }
  const running = session.generation;
  const back = page.shown;
  $("#progress-box").hidden = true;
  setNotice("");
  change(page.shownState, (message) => setStatus(message, true));
  setStatus(`cancelled generation ${running}; back to the values of generation ${back}`, true);
  page.cancelled = { running, back };
}

// Progress of the current generation's runs, or of the second phase of the result on screen
// while no newer generation is asked for. One step of a second phase can outlast the wait for
// the bar (a map synthesized for a new arm length, half a second): its bar shows once the phase
// has run progress_after, whether or not another step reported by then.
function onProgress(msg) {
  if (msg.generation !== session.generation) return;
  if (msg.phase !== "second") {
    showProgress(msg.fraction, msg.elapsed, "runs", msg.what);
    return;
  }
  const wanted = () => page.second === msg.generation && page.shown === msg.generation
    && session.generation === msg.generation && secondWanted(msg.generation);
  page.second = msg.generation;
  if (!wanted()) return;
  showProgress(msg.fraction, msg.elapsed, "second", msg.what);
  clearTimeout(page.secondTimer);
  const wait = page.config.progress_after - msg.elapsed;
  if (wait > 0 && msg.fraction < 1) {
    page.secondTimer = setTimeout(() => {
      if (wanted()) showProgress(msg.fraction, page.config.progress_after + 1e-3, "second", msg.what);
    }, 1000 * wait + 1);
  }
}

// The second phase of the result on screen, done or cancelled: its panels, then the header
// (unless a newer generation is computing: its status stays).
async function onFunctionals(msg) {
  if (msg.generation === page.second) page.second = null;
  clearTimeout(page.secondTimer);
  if (msg.generation !== page.shown) return;
  await applyFunctionals(msg);
  if (page.phase === "second") showProgress(1, 0, "second");
  afterSecond(msg, msg.generation === session.generation ? setStatus : null);
}

function showScene(hasScene) {
  const frame = $("#scene");
  if (hasScene) {
    const ws = `${location.protocol === "https:" ? "wss" : "ws"}://${location.host}${api("/scene")}`;
    frame.src = `/scene/?websocket=${encodeURIComponent(ws)}`;
    return;
  }
  frame.hidden = true;
  const note = $("#scene-note");
  note.hidden = false;
  note.textContent = "The 3D scene runs with `jik serve`.";
}

// The event stream broke: the server restarted, or the session ended (expired, closed). The
// browser reconnects by itself; a session the server no longer has is opened anew from the
// state in the URL (a reload does it).
function lost() {
  setStatus("connection lost; reconnecting…", true);
  fetch(api("")).then((r) => { if (r.status === 404) location.reload(); }).catch(() => {});
}

async function main() {
  page.config = await fetch("/api/dashboard/config").then((r) => r.json());
  for (const [a, c] of Object.entries(page.config.colors)) document.documentElement.style.setProperty(`--${a}`, c);
  layoutPanels(page.config.panels, page.config);
  page.editor = robotEditor(page.config.robot_kinds, send);
  onNotSent((text) => setStatus(text, true));
  // The sticky header's height, for the scene below it (style.css --header-h).
  new ResizeObserver(([entry]) => document.documentElement.style.setProperty("--header-h", `${Math.ceil(entry.target.getBoundingClientRect().height)}px`)).observe($("header"));
  $("#legend").replaceChildren(algorithmKey(true));
  $("#controls").addEventListener("submit", (ev) => ev.preventDefault()); // (Enter in a box)
  const opened = await openSession(await stateFromUrl(setNotice),
    (message) => setNotice(`the link's state was refused (${message}); showing the defaults`),
    (message, seconds) => setStatus(`${message}; trying again every ${seconds} s…`, true));
  $("#copy-link").addEventListener("click", copyLink);
  followHistory(send);
  $("#cancel").addEventListener("click", cancel);
  atlasPanel(() => page.state, send);
  onState(opened);
  showScene(opened.scene);
  let chain = Promise.resolve(); // results and their second phases are drawn in order
  const serial = (fn) => (msg) => { chain = chain.then(() => fn(msg)).catch((err) => setStatus(String(err), true)); };
  follow({
    state: (msg) => onState(msg),
    refused: onRefused,
    progress: onProgress,
    result: serial(onResult),
    functionals: serial(onFunctionals),
    ahead: (msg) => { onAhead(msg, () => page.state && page.state.robot).catch((err) => console.warn("drawing ahead:", err)); },
    error: serial(onError),
  }, lost);
  endOnClose();
}

main().catch((err) => setStatus(String(err), true));
