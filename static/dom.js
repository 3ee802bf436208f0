// Small DOM helpers shared by the page's modules.
export const $ = (sel) => document.querySelector(sel);

export const el = (tag, attrs = {}, ...children) => {
  const e = document.createElement(tag);
  for (const [k, v] of Object.entries(attrs)) {
    if (k === "dataset") Object.assign(e.dataset, v);
    else if (k in e && k !== "list") e[k] = v;
    else e.setAttribute(k, v);
  }
  for (const c of children) e.append(c);
  return e;
};

// A value refused at a field of the page (``row``: the element holding its inputs): a note at
// the end of the row says why (read out as it appears: role alert), made or reused, and
// markInvalid marks the field's inputs (aria-invalid) while the note stays. The page's controls
// (controls.js), the atlas panel's boxes (atlas.js) and the robot editor's fields (editor.js)
// show their refusals this way.
export function fieldNote(row, text) {
  let note = row.querySelector(":scope > .field-error");
  if (!note) { note = el("span", { className: "field-error", role: "alert" }); row.append(note); }
  note.textContent = text;
  return note;
}

export function markInvalid(row, on) {
  for (const input of row.querySelectorAll("input, textarea, select, button")) {
    if (on) input.setAttribute("aria-invalid", "true"); else input.removeAttribute("aria-invalid");
  }
}

// A number as shown beside a control or in the verdict: 3 decimals, exponent when tiny or huge.
export const fmt = (v, d = 3) =>
  (Math.abs(v) >= 1e4 || (Math.abs(v) < 1e-3 && v !== 0) ? v.toExponential(2) : (+v).toFixed(d));

// A server's sentence with each mention of the errata's file as a link to the errata page
// (/errata), opened beside the dashboard.
const ERRATA_FILE = "docs/paper-errata.md";
export const withErrataLinks = (text) => text.split(ERRATA_FILE).flatMap((part, i) => (
  i ? [el("a", { href: "/errata", target: "_blank", rel: "noopener", className: "errata-link" }, ERRATA_FILE), part] : [part]));
