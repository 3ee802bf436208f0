// The page's controls, built from the session's control specification (app/dashboard/controls.py, sent
// with every state): the same controls, labels, ranges and values as the 3D scene's panel. A
// control's change is sent by its key ({"x0.1": 0.4}); the server turns it into a state change.
import { el, fieldNote, fmt, markInvalid } from "./dom.js";

let shape = null; // JSON of the controls on screen: rebuilt only when it changes
const inputs = new Map(); // control key -> element with setValue()
const inForce = new Map(); // control key -> JSON of its value in the last state shown

// A number as the user wrote it, or null when it is not a finite one ("abc", "", "1,5", "1e400").
export function parseNumber(text) {
  const t = String(text).trim();
  const n = /^[-+]?(\d+\.?\d*|\.\d+)(e[-+]?\d+)?$/i.test(t) ? Number(t) : null;
  return Number.isFinite(n) ? n : null;
}

// A slider and a box for an exact value: the slider lands on the specification's step within
// its range; the box sends what is typed, which the server checks as the REST API does (gamma
// in continuous mode, a start outside the joint limits: the box takes values beyond the
// slider's ends, and the slider then rests at its end).
function slider(c, value, send) {
  const toPos = (v) => (c.log ? Math.log10(v) : v);
  const fromPos = (p) => (c.log ? 10 ** p : p);
  const show = (v) => (c.integer ? String(Math.round(v)) : fmt(v));
  const input = el("input", {
    type: "range", id: c.id, min: toPos(c.minimum), max: toPos(c.maximum),
    step: c.log ? (toPos(c.maximum) - toPos(c.minimum)) / 200 : c.step, value: toPos(value),
  });
  input.setAttribute("aria-label", c.label);
  const box = el("input", { type: "text", id: `${c.id}-value`, className: "exact", value: show(value), inputMode: "decimal" });
  box.setAttribute("aria-label", `${c.label}: exact value`);
  input.addEventListener("input", () => {
    // On the specification's step (as the scene's slider), exactly: k * step, printed short.
    const v = c.integer ? Math.round(fromPos(+input.value)) : +(Math.round(fromPos(+input.value) / c.step) * c.step).toPrecision(12);
    box.value = show(v);
    send(v);
  });
  box.addEventListener("change", () => {
    const v = parseNumber(box.value);
    if (v === null) { notANumber(c, box.value); return; }
    input.value = toPos(v);
    send(v, box.value);
  });
  const group = el("span", { className: "slider" }, input, box);
  group.setValue = (v) => { input.value = toPos(v); box.value = show(v); };
  return el("label", { title: c.help }, el("span", {}, c.label), group);
}

const rows = new Map(); // control key -> its label (where its errors show)
// The controls a refused field is about (the server's list, by app/dashboard/controls.py's
// about(): the field, its coordinates, or the vector holding it) that are on this page.
const onPage = (keys) => (keys || []).filter((k) => rows.has(k));
const keysOf = (note) => note.dataset.controls.split(" ");

// An error beside the first control of ``keys``, quoting what the user wrote; every control of
// ``keys`` (the key's own, or all of x0's) is marked invalid while the note stays (``clear``).
function fieldError(keys, typed, message) {
  const row = rows.get(keys[0]);
  if (!row) return null;
  const was = row.querySelector(":scope > .field-error");
  if (was) invalid(keysOf(was), false);
  const note = fieldNote(row, typed === undefined ? message : `“${typed}” ${message}`);
  note.dataset.controls = keys.join(" ");
  invalid(keys, true);
  return note;
}

function invalid(keys, on) {
  for (const key of keys) if (rows.has(key)) markInvalid(rows.get(key), on);
}

function clear(note) {
  invalid(keysOf(note), false);
  note.remove();
}

// Text typed into a number box that is not a number: said beside the control and, replacing
// an earlier refusal there, in the page's header (``onNotSent``: main.js's status).
let notSent = () => {};
export function onNotSent(show) { notSent = show; }
function notANumber(c, typed) {
  fieldError([c.key], typed, "is not a number; nothing was sent");
  notSent(`not sent (here): ${c.label}: “${typed}” is not a number`);
}

// A refusal of the server shown beside the controls it is about (``about``: their keys), with
// the text the user typed there when there was one; whether a control was found.
const typedText = new Map(); // control key -> the text last sent from a box
export function showRefusal(about, message) {
  const keys = onPage(about);
  if (!keys.length) return false;
  const typed = typedText.get(keys[0]);
  return fieldError(keys, typed, typed === undefined ? message : `was refused: ${message}`) !== null;
}

// The inputs where a result's runs stopped (a run's ``field``: x0, a singular start), marked as
// a refusal is, with the runs' messages, until they change or a result without them comes.
export function showStopped(summary) {
  document.querySelectorAll("#controls .field-error[data-run]").forEach(clear);
  const messages = new Map(); // keys of the controls about a field -> the messages of the runs stopped there
  for (const run of Object.values(summary)) {
    const keys = onPage(run.controls).join(" ");
    if (keys) messages.set(keys, [...(messages.get(keys) || []), run.message]);
  }
  for (const [keys, said] of messages) {
    const note = fieldError(keys.split(" "), undefined, said.join("; "));
    if (note) note.dataset.run = "";
  }
}

// The errors about a control, once its value changed (here, in the 3D scene, another client):
// what they quoted is no longer what the control holds.
function clearFieldError(key) {
  for (const note of document.querySelectorAll("#controls .field-error")) if (keysOf(note).includes(key)) clear(note);
}

export function clearFieldErrors() {
  document.querySelectorAll("#controls .field-error").forEach(clear);
}

// A select shown as buttons (c.inline): every option one click away.
function choice(c, value, send) {
  const group = el("span", { className: "choice", id: c.id, role: "radiogroup" });
  group.setAttribute("aria-label", c.label);
  const buttons = c.options.map(([v, text]) => {
    const b = el("button", { type: "button", id: `${c.id}-${v}`, onclick: () => { group.setValue(v); send(v); } }, text);
    b.dataset.value = v;
    b.setAttribute("role", "radio");
    return b;
  });
  group.append(...buttons);
  // One Tab stop, the option chosen (the first when none is); the arrow keys choose the next or
  // the previous option, as in any radio group.
  group.setValue = (v) => {
    const some = buttons.some((b) => b.dataset.value === v);
    buttons.forEach((b, i) => {
      b.setAttribute("aria-checked", String(b.dataset.value === v));
      b.tabIndex = b.dataset.value === v || (!some && i === 0) ? 0 : -1;
    });
  };
  group.setValue(value);
  group.addEventListener("keydown", (e) => {
    const step = { ArrowRight: 1, ArrowDown: 1, ArrowLeft: -1, ArrowUp: -1 }[e.key];
    const at = buttons.indexOf(document.activeElement);
    if (!step || at < 0) return;
    e.preventDefault();
    const next = buttons[(at + step + buttons.length) % buttons.length];
    next.focus();
    next.click();
  });
  // (a div, not a label: a click on a label's text would press its first button)
  return el("div", { className: "ctl", title: c.help }, el("span", {}, c.label), group);
}

// Any of the options (c.kind "checks": the chosen algorithms), as toggle buttons; the list of
// those pressed is sent (the server refuses an empty one, naming the control).
function checks(c, value, send) {
  const group = el("span", { className: "choice checks", id: c.id, role: "group" });
  group.setAttribute("aria-label", c.label);
  let chosen = [...value];
  const buttons = c.options.map(([v, text]) => {
    const b = el("button", { type: "button", id: `${c.id}-${v}`, onclick: () => {
      chosen = chosen.includes(v) ? chosen.filter((k) => k !== v) : [...chosen, v];
      group.setValue(chosen);
      send(c.options.map(([k]) => k).filter((k) => chosen.includes(k)));
    } }, text);
    b.dataset.value = v;
    b.style.setProperty("--alg", `var(--${v})`);
    return b;
  });
  group.append(...buttons);
  group.setValue = (v) => { chosen = [...v]; buttons.forEach((b) => b.setAttribute("aria-pressed", String(chosen.includes(b.dataset.value)))); };
  group.setValue(value);
  return el("div", { className: "ctl", title: c.help }, el("span", {}, c.label), group);
}

function select(c, value, send) {
  if (c.inline) return choice(c, value, send);
  const s = el("select", { id: c.id });
  for (const [v, text] of c.options) s.append(el("option", { value: v, selected: v === value }, text));
  // (the option's value as the specification gives it: a number stays a number)
  s.addEventListener("change", () => send(c.options.find(([v]) => String(v) === s.value)[0]));
  s.setValue = (v) => { s.value = v; };
  return el("label", { title: c.help }, c.label, s);
}

// A vector: one box per coordinate, each showing its value to 4 decimals; a change sends the
// whole vector, the boxes the user did not edit at their exact values (not the 4 decimals
// shown), unless a box does not hold a number (then it says so beside the control, in the
// user's text).
function vector(c, value, send) {
  const short = (v) => String(+(+v).toFixed(4));
  let exact = [...value];
  const boxes = value.map((v, i) => {
    const box = el("input", { type: "text", inputMode: "decimal", id: `${c.id}-${i}`, className: "coordinate", value: short(v) });
    box.setAttribute("aria-label", `${c.label}, coordinate ${i + 1}`);
    box.addEventListener("change", () => {
      const values = boxes.map((b, k) => (b.value.trim() === short(exact[k]) ? exact[k] : parseNumber(b.value)));
      const bad = boxes.find((b, k) => values[k] === null);
      if (bad) { notANumber(c, bad.value); return; }
      send(values, boxes.map((b) => b.value.trim()).join(", "));
    });
    return box;
  });
  const group = el("span", { className: "vector" }, ...boxes);
  group.setValue = (v) => { exact = [...v]; v.forEach((x, i) => { boxes[i].value = short(x); }); };
  return el("label", { title: c.help }, c.label, group);
}

// A text (the closed path, which the server writes a point per line): a box as tall as its
// lines and as wide as its longest, so that the whole path shows. Enter sends it, as in a
// one-line box; Shift+Enter starts a new line (a point).
function text(c, value, send) {
  const box = el("textarea", { id: c.id, value, placeholder: c.format, spellcheck: false });
  const fit = () => { // (where the browser does not size it by its text: style.css)
    const lines = box.value.split("\n");
    box.rows = lines.length;
    box.cols = Math.max(12, ...lines.map((line) => line.length)) + 1;
  };
  let sent = value; // (a change and the Enter before it send once)
  const commit = () => {
    if (box.value === sent) return;
    sent = box.value;
    send(box.value, box.value);
  };
  box.addEventListener("keydown", (e) => {
    if (e.key !== "Enter" || e.shiftKey || e.isComposing) return;
    e.preventDefault();
    commit();
  });
  box.addEventListener("change", commit);
  box.addEventListener("input", fit);
  box.setValue = (v) => { box.value = v; sent = v; fit(); };
  fit();
  return el("label", { title: c.help }, c.label, box);
}

function preset(c, send) {
  return el("button", { type: "button", id: c.id, title: c.help, onclick: () => send(c.value) }, c.label);
}

const BUILD = { slider, select, vector, text, checks };

// Show the controls of a state message ({groups, controls, values}): built anew when the
// controls differ from those on screen (another robot, map, mode or task), else only their
// values set: not the one being edited, unless ``force`` (a refusal: the values in force).
export function showControls(msg, change, force = false) {
  const next = JSON.stringify(msg.controls);
  const changed = (key) => {
    const value = JSON.stringify(msg.values[key]);
    const was = inForce.get(key);
    inForce.set(key, value);
    return was !== undefined && was !== value;
  };
  if (next !== shape) {
    shape = next;
    inputs.clear();
    rows.clear();
    inForce.clear();
    Object.keys(msg.values).forEach(changed);
    const form = document.getElementById("controls");
    // (the control that had the focus, a select changed by keyboard, has it again: by its id)
    const focused = form.contains(document.activeElement) ? document.activeElement.id : "";
    form.replaceChildren(...msg.groups.map(([group, title]) => {
      const set = el("fieldset", { dataset: { group } }, el("legend", {}, title));
      for (const c of msg.controls.filter((k) => k.group === group)) {
        const send = (v, typed) => {
          clearFieldErrors();
          if (typed === undefined) typedText.delete(c.key); else typedText.set(c.key, typed);
          change({ [c.key]: v });
        };
        if (c.kind === "preset") { set.append(preset(c, send)); continue; }
        const label = BUILD[c.kind](c, msg.values[c.key], send);
        rows.set(c.key, label);
        inputs.set(c.key, label.querySelector(".slider,.vector,.choice,input,textarea,select"));
        set.append(label);
      }
      return set;
    }));
    if (focused) document.getElementById(focused)?.focus();
    return;
  }
  for (const [key, input] of inputs) {
    if (!(key in msg.values)) continue;
    if (changed(key)) clearFieldError(key);
    if (!force && input.contains(document.activeElement)) continue;
    input.setValue(msg.values[key]);
  }
}
