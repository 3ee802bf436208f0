// The page's session on the server (app/api/routes/sessions.py): created from a link's state,
// changed by control keys, followed over server-sent events.
export const session = { id: null, generation: 0 };
export const api = (path) => `/api/sessions/${session.id}${path}`;

// A software WebGL renderer (no GPU): the session's scene is then drawn without shadows and
// environment map. Off for every hardware renderer.
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

const detail = (body) => (Array.isArray(body.detail) ? body.detail.map((d) => d.msg).join("; ") : body.detail);

// A new session with ``state`` (a link's); a refused link state falls back to the defaults,
// calling onRefusedLink(message). While every session of the server is in use (503), it asks
// again after the response's Retry-After, calling onFull(message, seconds) each time.
export async function openSession(state, onRefusedLink, onFull) {
  const res = await fetch("/api/sessions", {
    method: "POST", headers: { "Content-Type": "application/json" },
    body: JSON.stringify({ state, low_end: softwareRenderer() }),
  });
  const body = await res.json();
  if (res.status === 422 && Object.keys(state).length) {
    onRefusedLink(detail(body));
    return openSession({}, onRefusedLink, onFull);
  }
  if (res.status === 503) {
    const seconds = Number(res.headers.get("Retry-After")) || 5;
    onFull(detail(body), seconds);
    await new Promise((resolve) => { setTimeout(resolve, 1000 * seconds); });
    return openSession(state, onRefusedLink, onFull);
  }
  if (!res.ok) throw new Error(detail(body));
  session.id = body.id;
  session.generation = body.generation;
  return body;
}

// Changes are posted at once; while a POST is in flight, newer changes are merged and sent when
// it returns (a slider drag sends one request at a time, never a stale backlog). A refusal of
// the request itself goes to onError; onRefused is told which POST the session refused (422, its
// "refused" event says why).
let queued = {};
let inFlight = false;
let posts = 0; // the POSTs of changes started; onAccepted and onRefused are told which one
export const changesPosted = () => posts;
export function change(patch, onError, onAccepted = () => {}, onRefused = () => {}) {
  Object.assign(queued, patch);
  if (!inFlight) flush(onError, onAccepted, onRefused);
}

async function flush(...callbacks) {
  const [onError, onAccepted, onRefused] = callbacks;
  const patch = queued;
  queued = {};
  if (!Object.keys(patch).length) return;
  inFlight = true;
  const post = ++posts;
  try {
    const res = await fetch(api("/state"), {
      method: "POST", headers: { "Content-Type": "application/json" }, body: JSON.stringify(patch),
    });
    const body = await res.json();
    if (res.ok) {
      session.generation = Math.max(session.generation, body.generation);
      onAccepted(body, post);
    } else if (res.status === 422) onRefused(post);
    else onError(detail(body));
  } finally {
    inFlight = false;
    if (Object.keys(queued).length) flush(...callbacks);
  }
}

// Follow the session's events: handlers by kind, each given the parsed data. "lost" is called
// when the connection drops (the browser reconnects by itself). A hidden tab lets go of its
// stream and follows again when shown (the server sends a new listener the latest event of each
// kind): a stream holds one of the six connections a browser keeps to one server, so a seventh
// tab of the dashboard, or any request of the six, would wait for one of them to close.
export function follow(handlers, lost) {
  let source = null;
  const open = () => {
    source = new EventSource(api("/events"));
    for (const [kind, fn] of Object.entries(handlers)) {
      source.addEventListener(kind, (ev) => { if (ev.data !== undefined) fn(JSON.parse(ev.data)); });
    }
    source.addEventListener("error", (ev) => { if (ev.data === undefined) lost(); });
  };
  document.addEventListener("visibilitychange", () => {
    if (document.hidden && source) {
      source.close();
      source = null;
    } else if (!document.hidden && !source) open();
  });
  if (!document.hidden) open();
}

// A closing tab ends its session at once (otherwise it expires when idle).
export function endOnClose() {
  addEventListener("pagehide", () => { fetch(api(""), { method: "DELETE", keepalive: true }); });
  addEventListener("pageshow", (ev) => { if (ev.persisted) location.reload(); });
}
