// The robot editor: a robot of your own (a planar chain, kinematics by formula, a URDF arm).
// Its fields come from the server's description of each kind (engine/robot_kinds.py, in the
// page's config as robot_kinds), never written here; applying sends the definition as the
// session's robot_definition, and a refusal is shown next to the field it names.
import { $, el, fieldNote, markInvalid } from "./dom.js";

// How a field's text becomes JSON, by the description's type. A value that does not parse is
// sent as typed: the server says what is wrong with it, next to the field.
const NUMBER = (t) => (t.trim() !== "" && Number.isFinite(Number(t)) ? Number(t) : t.trim());
const PARSE = {
  string: (t) => t.trim(),
  text: (t) => t,
  numbers: (t) => t.split(",").map(NUMBER),
  names: (t) => t.split(",").map((s) => s.trim()).filter((s) => s),
  formulas: (t) => t.split("\n").map((s) => s.trim()).filter((s) => s),
  integer: NUMBER,
  mapping: json, points: json, augmentations: json,
};
const SHOW = {
  numbers: (v) => v.join(", "), names: (v) => v.join(", "), formulas: (v) => v.join("\n"),
  mapping: JSON.stringify, points: JSON.stringify, augmentations: JSON.stringify,
};
const MULTILINE = new Set(["text", "formulas"]);
// The common fields the editor offers besides the kind's own (the rest keep their defaults).
const COMMON = ["title", "x0", "augmentations"];

function json(t) {
  try { return JSON.parse(t); } catch (err) { return t; }
}

export function robotEditor(kinds, send) {
  const box = $("#robot-editor");
  const kind = el("select", { id: "robot-kind" },
    el("option", { value: "" }, "choose a kind…"),
    ...Object.keys(kinds.kinds).map((k) => el("option", { value: k }, k.replace("_", " "))));
  const fields = el("div", { id: "robot-fields", className: "robot-fields" });
  const apply = el("button", { type: "button", id: "robot-apply", disabled: true }, "apply");
  const note = el("p", { id: "robot-note", className: "note" });
  const inputs = new Map(); // field name -> [input, description, its row]
  // What the user typed, by kind (kept across a change of kind, a refusal and the session's
  // state events until a definition is applied), and whether the fields shown hold typing.
  const typed = new Map();
  let shownKind = "";
  let edited = false;
  let inForce; // JSON of the session's robot_definition last shown

  function build(k, values = {}) {
    shownKind = k;
    edited = false;
    inputs.clear();
    apply.disabled = !k;
    if (!k) { fields.replaceChildren(); return; }
    const common = kinds.common.filter((f) => COMMON.includes(f.name));
    fields.replaceChildren(...[...kinds.kinds[k], ...common].filter((f) => f.name !== "urdf_file").map((f) => {
      const id = `robot-field-${f.name}`;
      const value = f.name in values ? values[f.name] : f.example;
      const text = value === null || value === undefined ? "" : (SHOW[f.type] || String)(value);
      let input;
      if (f.type === "boolean") input = el("input", { type: "checkbox", id, checked: value === true });
      else if (MULTILINE.has(f.type)) input = el("textarea", { id, rows: f.type === "text" ? 6 : 2, value: text });
      else input = el("input", { type: "text", id, value: text });
      const label = el("label", { title: f.help, htmlFor: id }, `${f.name}${f.required ? " *" : ""}`);
      const row = el("div", { className: "robot-field", dataset: { field: f.name } }, label, input,
        el("small", {}, f.help));
      inputs.set(f.name, [input, f, row]);
      return row;
    }));
  }

  function definition() {
    const d = { name: shownKind };
    for (const [name, [input, f]] of inputs) {
      if (f.type === "boolean") { if (input.checked) d[name] = true; continue; }
      if (input.value.trim() === "") continue;
      d[name] = (PARSE[f.type] || String)(input.value);
    }
    return d;
  }

  // The fields' texts as typed (a checkbox: its state), to rebuild them as they were.
  function texts() {
    const t = {};
    for (const [name, [input, f]] of inputs) t[name] = f.type === "boolean" ? input.checked : input.value;
    return t;
  }

  function restore(k) {
    build(k);
    const t = typed.get(k);
    if (!t) return;
    for (const [name, [input, f]] of inputs) {
      if (!(name in t)) continue;
      if (f.type === "boolean") input.checked = t[name];
      else input.value = t[name];
    }
    edited = true;
  }

  function clearErrors() {
    for (const [, [, , row]] of inputs) { row.querySelector(":scope > .field-error")?.remove(); markInvalid(row, false); }
    note.textContent = "";
  }

  kind.addEventListener("change", () => {
    if (edited) typed.set(shownKind, texts());
    clearErrors();
    restore(kind.value);
  });
  fields.addEventListener("input", () => { edited = true; typed.set(shownKind, texts()); });
  fields.addEventListener("change", () => { edited = true; typed.set(shownKind, texts()); });
  apply.addEventListener("click", () => {
    clearErrors();
    note.textContent = "applying…";
    typed.set(shownKind, texts());
    send({ robot: shownKind, robot_definition: definition() });
  });
  box.append(el("div", { className: "robot-kind" }, el("label", { htmlFor: "robot-kind" }, "kind"), kind, apply), fields, note);

  return {
    // The session's state: a user robot's definition fills the editor (unless it shows the kind
    // being edited); a refusal then stays where it is.
    // What the user typed and did not apply stays (``refused``: the state in force after a
    // refusal, which is not what was applied).
    show(state, refused = false) {
      const applying = note.textContent === "applying…" && !refused;
      const applied = state.robot_definition && applying && state.robot === shownKind;
      if (applied) {
        typed.delete(shownKind);
        edited = false;
        note.textContent = `applied: ${state.robot}`;
      }
      // (a catalogue arm has a definition too, its name and task: the robot picker's)
      const editable = state.robot in kinds.kinds;
      // Another robot chosen in the picker: the definition shown is kept here, not in use.
      if (!editable && note.textContent.startsWith("applied: ")) {
        note.textContent = "not in use (another robot is chosen): apply to use it again";
      }
      // Another definition in force that was not applied here (back or forward, a catalogue
      // arm picked): the fields show it, unless they hold typing, and no note says otherwise.
      const definition = JSON.stringify(state.robot_definition ?? null);
      const arrived = definition !== inForce;
      inForce = definition;
      if (editable && state.robot_definition && (state.robot !== shownKind || arrived) && !edited) {
        kind.value = state.robot;
        build(state.robot, state.robot_definition);
        if (!applied && !applying) note.textContent = "";
      }
    },
    // A refused field under robot_definition: its message next to it; whether it was shown.
    refused(field, message) {
      if (!field.startsWith("robot_definition")) return false;
      box.open = true;
      const name = field.split(".")[1];
      const entry = inputs.get(name);
      if (!entry) { note.textContent = `not applied: ${message}`; return true; }
      note.textContent = `not applied: see the field ${name}`;
      // (the message names the field under the definition: "robot_definition.lengths[1]: ...")
      const own = message.startsWith("robot_definition.");
      fieldNote(entry[2], own ? message.slice("robot_definition.".length) : message);
      markInvalid(entry[2], true);
      entry[0].scrollIntoView({ block: "nearest" });
      return true;
    },
  };
}
