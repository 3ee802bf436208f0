// The page's controls, built from the session's control specification (app/dashboard/controls.py, sent
// with every state): the same controls, labels, ranges and values as the 3D scene's panel. A
// control's change is sent by its key ({"x0.1": 0.4}); the server turns it into a state change.
import { el, fmt } from "./dom.js";

let shape = null; // JSON of the controls on screen: rebuilt only when it changes
const inputs = new Map(); // control key -> element with setValue()

function slider(c, value, send) {
  const toPos = (v) => (c.log ? Math.log10(v) : v);
  const fromPos = (p) => (c.log ? 10 ** p : p);
  const show = (v) => (c.integer ? String(Math.round(v)) : fmt(v));
  const input = el("input", {
    type: "range", id: c.id, min: toPos(c.minimum), max: toPos(c.maximum),
    step: c.log ? (toPos(c.maximum) - toPos(c.minimum)) / 200 : c.step, value: toPos(value),
  });
  const out = el("output", {}, show(value));
  input.addEventListener("input", () => {
    // On the specification's step (as the scene's slider), exactly: k * step, printed short.
    const v = c.integer ? Math.round(fromPos(+input.value)) : +(Math.round(fromPos(+input.value) / c.step) * c.step).toPrecision(12);
    out.textContent = show(v);
    send(v);
  });
  input.setValue = (v) => { input.value = toPos(v); out.textContent = show(v); };
  return el("label", { title: c.help }, el("span", {}, c.label, " ", out), input);
}

function select(c, value, send) {
  const s = el("select", { id: c.id });
  for (const [v, text] of c.options) s.append(el("option", { value: v, selected: v === value }, text));
  s.addEventListener("change", () => send(s.value));
  s.setValue = (v) => { s.value = v; };
  return el("label", { title: c.help }, c.label, s);
}

// A vector: one number box per coordinate; a change sends the whole vector.
function vector(c, value, send) {
  const boxes = value.map((v, i) => {
    const box = el("input", { type: "number", id: `${c.id}-${i}`, step: c.step, value: +(+v).toFixed(4) });
    if (c.minimum) { box.min = c.minimum[i]; box.max = c.maximum[i]; }
    box.addEventListener("change", () => send(boxes.map((b) => +b.value)));
    return box;
  });
  const group = el("span", { className: "vector" }, ...boxes);
  group.setValue = (v) => v.forEach((x, i) => { boxes[i].value = +(+x).toFixed(4); });
  return el("label", { title: c.help }, c.label, group);
}

function text(c, value, send) {
  const input = el("input", { type: "text", id: c.id, value, placeholder: c.format });
  input.addEventListener("change", () => send(input.value));
  input.setValue = (v) => { input.value = v; };
  return el("label", { title: `${c.help} (${c.format})` }, c.label, input);
}

function preset(c, send) {
  return el("button", { type: "button", id: c.id, title: c.help, onclick: () => send(c.value) }, c.label);
}

const BUILD = { slider, select, vector, text };

// Show the controls of a state message ({groups, controls, values}): built anew when the
// controls differ from those on screen (another robot, map, mode or task), else only their
// values set: not the one being edited, unless ``force`` (a refusal: the values in force).
export function showControls(msg, change, force = false) {
  const next = JSON.stringify(msg.controls);
  if (next !== shape) {
    shape = next;
    inputs.clear();
    const form = document.getElementById("controls");
    form.replaceChildren(...msg.groups.map(([group, title]) => {
      const set = el("fieldset", { dataset: { group } }, el("legend", {}, title));
      for (const c of msg.controls.filter((k) => k.group === group)) {
        const send = (v) => change({ [c.key]: v });
        if (c.kind === "preset") { set.append(preset(c, send)); continue; }
        const label = BUILD[c.kind](c, msg.values[c.key], send);
        inputs.set(c.key, label.querySelector("input,select,.vector"));
        set.append(label);
      }
      return set;
    }));
    return;
  }
  for (const [key, input] of inputs) {
    if (!force && input.contains(document.activeElement)) continue;
    if (key in msg.values) input.setValue(msg.values[key]);
  }
}
