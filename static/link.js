// The session's state in the page's address and the tab's history (main.js calls these).
import { changesPosted } from "./api.js";
import { $ } from "./dom.js";

// The page's URL holds the state (?state=<JSON of the dashboard's fields>): a copied link, or a
// reload, starts a new session with the same state. A state whose JSON is longer than
// PLAIN_STATE (a pasted URDF of tens of kB, which the server's cap on a request's headers, 64 kB,
// refused with 431 on a reload) is held deflated: ?z=<base64url of its JSON, deflate-raw>. One
// still longer than LINK_STATE (a URDF of some hundreds of kB) stays in this tab
// (sessionStorage, ?tab): a reload opens it, and "copy link" says the state is too large for one.
// Each change is an entry of the tab's history (the state with it): back and forward bring the
// session to that entry's state. Changes of the same single field in a row (a slider's drag)
// make one entry; the first state, and the one that back or forward brought, make none.
const PLAIN_STATE = 16 * 1024;
const LINK_STATE = 48 * 1024;
const TAB_STATE = "jik-state";
let remembering = 0; // the newest state written (a deflation finishes later than it starts)
const written = { state: null, field: null }; // the history's newest state, its one changed field

async function rememberInUrl(state) {
  const turn = ++remembering;
  const text = JSON.stringify(state);
  const url = new URL(location.href);
  for (const key of ["state", "z", "tab"]) url.searchParams.delete(key);
  const z = encodeURIComponent(text).length <= PLAIN_STATE ? null : await deflated(text);
  if (turn !== remembering) return;
  if (z === null) url.searchParams.set("state", text);
  else if (z.length <= LINK_STATE) url.searchParams.set("z", z);
  else {
    sessionStorage.setItem(TAB_STATE, text);
    url.searchParams.set("tab", "");
  }
  const before = written.state || state;
  const fields = Object.keys(state).filter((k) => JSON.stringify(state[k]) !== JSON.stringify(before[k]));
  const field = fields.length === 1 ? fields[0] : null;
  const push = fields.length > 0 && !(field && field === written.field);
  Object.assign(written, { state, field: fields.length ? field : written.field });
  if (!fields.length && url.href === location.href && history.state) return; // (?tab: one address)
  if (push) history.pushState({ state }, "", url);
  else history.replaceState({ state }, "", url);
  $("#copy-link").textContent = "copy link"; // (a link copied before is of another state)
}

// Back or forward while a change was still being posted: that change's state (an older
// generation than the one the entry's state gets) must not become a new entry, which would
// drop the entries ahead of this one. Until the entry's state arrives, or the first POST after
// the travel is answered, the states of older generations go unwritten (a refusal of a change
// posted before the travel too); the refusal of a POST after it ends the wait (refusedPost).
let travelled = null; // { state: the entry's, after: POSTs started before, generation: of the next }

function inHistory(msg) {
  if (!travelled) return true;
  const arrived = JSON.stringify(msg.state) === JSON.stringify(travelled.state);
  if (!arrived && (travelled.generation === null || msg.generation < travelled.generation)) return false;
  travelled = null;
  return true;
}

// Whether ``msg`` brings the state of the entry that back or forward went to: the controls then
// show it all, the one with the focus too (what it holds was left for the history's entry).
export function travelledTo(msg) {
  return travelled !== null && JSON.stringify(msg.state) === JSON.stringify(travelled.state);
}

// A session's state (an event's) into the address and the history, unless a travel waits.
export function remember(msg) {
  if (inHistory(msg)) rememberInUrl(msg.state).catch((err) => console.warn("the link's state:", err));
}

// Back or forward: the session is sent the entry's state (``send``), which makes no entry.
export function followHistory(send) {
  addEventListener("popstate", (ev) => {
    if (!ev.state) return;
    travelled = { state: ev.state.state, after: changesPosted(), generation: null };
    Object.assign(written, { state: ev.state.state, field: null });
    send(ev.state.state);
  });
}

// The POST of a change answered: the generation the travel waits for is the first POST's after it.
export function acceptedPost(body, post) {
  if (travelled && travelled.generation === null && post > travelled.after) travelled.generation = body.generation;
}

// The POST of a change sent after the travel refused: the entry's state will not come, and the
// state in force (``state``, its "refused" event's, written whenever it arrives) is the address's.
export function refusedPost(post, state) {
  if (!travelled || post <= travelled.after) return;
  travelled = null;
  rememberInUrl(state).catch((err) => console.warn("the link's state:", err));
}

async function deflated(text) {
  const stream = new Blob([text]).stream().pipeThrough(new CompressionStream("deflate-raw"));
  const bytes = new Uint8Array(await new Response(stream).arrayBuffer());
  let binary = "";
  for (const b of bytes) binary += String.fromCharCode(b);
  return btoa(binary).replaceAll("+", "-").replaceAll("/", "_").replace(/=+$/, "");
}

async function inflated(z) {
  const bytes = Uint8Array.from(atob(z.replaceAll("-", "+").replaceAll("_", "/")), (c) => c.charCodeAt(0));
  return new Response(new Blob([bytes]).stream().pipeThrough(new DecompressionStream("deflate-raw"))).text();
}

// The state in the page's address (none: {}); why a link's state is not taken goes to onNotice.
export async function stateFromUrl(onNotice) {
  const params = new URL(location.href).searchParams;
  let text = params.get("state");
  if (params.has("tab")) {
    text = sessionStorage.getItem(TAB_STATE);
    if (text === null) {
      onNotice("the link's state was too large for a link and stays in the tab that made it; showing the defaults");
      return {};
    }
  }
  if (params.has("z")) {
    try {
      text = await inflated(params.get("z"));
    } catch {
      // (the browser's own words for a broken stream, "Failed to fetch", read as a network error)
      onNotice("the link's state is damaged: it does not inflate (a link cut short or changed); showing the defaults");
      return {};
    }
  }
  if (!text) return {};
  try {
    const state = JSON.parse(text);
    if (state && typeof state === "object" && !Array.isArray(state)) return state;
    onNotice(`the link's state is not an object of the state's fields (${text}); showing the defaults`);
    return {};
  } catch (err) {
    onNotice(`the link's state is not valid JSON (${err.message}); showing the defaults`);
    return {};
  }
}

export function copyLink() {
  const button = $("#copy-link");
  if (new URL(location.href).searchParams.has("tab")) {
    button.textContent = "too large for a link";
    return;
  }
  navigator.clipboard.writeText(location.href).then(
    () => { button.textContent = "link copied"; },
    () => { button.textContent = "copy the address bar"; },
  );
}
