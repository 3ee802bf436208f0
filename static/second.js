// A result's second phase (app/dashboard/second_phase.py): E1, E2 and their sensitivity, and h
// on a grid when each value of h solves a problem (the unicycle). Cancelled, the result stays on
// screen; the panels the phase would have drawn say what was not computed (the server's
// figures), with a button that computes it again.
import { api } from "./api.js";
import { el } from "./dom.js";
import { markStale } from "./panels.js";

// state: "cancelling" (asked), "cancelled" (its panels say so), "again" (computed again), null.
// message: the cancelled phase's event (its panels are marked again if a run again is refused).
const phase = { generation: 0, state: null, panels: [], message: null };

const post = (path, generation) => fetch(api(path), {
  method: "POST", headers: { "Content-Type": "application/json" }, body: JSON.stringify({ generation }),
});
const detail = async (res) => (await res.json().catch(() => ({}))).detail || `${res.status} ${res.statusText}`;

// Whether the progress of ``generation``'s second phase is wanted: not once it was cancelled
// (its last steps may still report before the server stops it).
export function secondWanted(generation) {
  return phase.generation !== generation || !["cancelling", "cancelled"].includes(phase.state);
}

// Cancel the second phase of the result on screen; its "functionals" event then says what was
// not computed (or, when it finished first, brings E1, E2 after all).
export async function cancelSecond(generation, say) {
  Object.assign(phase, { generation, state: "cancelling" });
  say(`cancelling E1/E2 of generation ${generation}…`);
  const res = await post("/functionals/cancel", generation);
  if (!res.ok && res.status !== 409) say(`the cancel failed: ${await detail(res)}`, true);
}

// Take the cancelled marks off the panels (a new result, or the phase computed again).
export function clearCancelled() {
  for (const div of document.querySelectorAll(".panel.cancelled")) {
    div.classList.remove("cancelled");
    div.querySelectorAll(":scope > .recompute").forEach((b) => b.remove());
  }
}

// After a "functionals" event of the result on screen was drawn: a cancelled phase marks its
// panels and says so in the header (``say``, or null when a newer generation is computing);
// a finished one clears the marks and, after a cancel or a run again, says the page is current.
export function afterSecond(msg, say) {
  clearCancelled();
  if (msg.cancelled) {
    const { what, fraction, panels } = msg.cancelled;
    Object.assign(phase, { generation: msg.generation, state: "cancelled", panels, message: msg });
    for (const key of panels) {
      const div = document.getElementById(`plot-${key}`);
      if (!div) continue;
      div.classList.remove("stale");
      div.classList.add("cancelled");
      const fig = (msg.figures || {})[key];
      if (fig && !fig.data.length) { // (a panel with nothing drawn: the button where the plot would be)
        div.append(el("button", {
          type: "button", className: "recompute", title: "compute them for the result on screen",
          onclick: () => again(msg.generation, say),
        }, key === "augmenting" ? "compute h and E1, E2" : "compute E1, E2"));
      }
    }
    const missing = what === "h on a grid" ? "h on a grid, E1, E2 and their sensitivity" : "E1, E2 and their sensitivity";
    if (say) say(`generation ${msg.generation} shown; not computed: ${missing} (cancelled at ${Math.round(100 * fraction)}%)`);
    return;
  }
  for (const key of phase.panels) {
    const div = document.getElementById(`plot-${key}`);
    if (div) div.classList.remove("stale");
  }
  if (say && (phase.state === "cancelling" || phase.state === "again") && phase.generation === msg.generation) {
    say(`up to date (generation ${msg.generation})${phase.state === "cancelling" ? "; E1, E2 were done before the cancel" : ""}`);
  }
  Object.assign(phase, { state: null, panels: [] });
}

// Compute again the cancelled phase of ``generation``: its panels wait (dimmed) for it.
async function again(generation, say) {
  const panels = phase.panels;
  Object.assign(phase, { generation, state: "again" });
  clearCancelled();
  markStale(panels, "computing E1, E2 again…");
  if (say) say(`computing E1/E2 of generation ${generation} again…`);
  const { message } = phase;
  const res = await post("/functionals", generation);
  if (res.ok || phase.state !== "again") return;
  afterSecond(message, null); // (still not computed: the panels say so again)
  if (say) say(`E1, E2 were not computed again: ${await detail(res)}`, true);
}
