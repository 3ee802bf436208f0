// Saving a panel: a table as CSV, a plot as PNG or SVG, each with the result and state it shows
// (an exported file alone still says what it is).
import { el } from "./dom.js";

// What an exported file says under its plot: the result and the state it shows.
let exportNote = "";
let exportName = "";
export function setExportNote(text, name = "") { exportNote = text; exportName = name; }

// A table panel as CSV: '#' lines with the state it shows, its title, notes and the cells that
// differ from the paper's print, then the table as on screen.
export function saveTable(div, key) {
  const quote = (v) => (/[",\n]/.test(v) ? `"${v.replace(/"/g, '""')}"` : v);
  const header = [...div.querySelectorAll("thead th")].map((th) => th.textContent);
  const rows = [...div.querySelectorAll("tbody tr")].map((tr) => [...tr.children].map((td) => td.textContent));
  const lines = [`# ${exportNote}`, `# ${div.querySelector(".table-title").textContent}`];
  for (const note of div.querySelectorAll(".table-note")) lines.push(`# ${note.textContent}`);
  div.querySelectorAll("td.differs").forEach((td) => {
    const row = td.parentElement.children[0].textContent;
    lines.push(`# differs from the print: row ${row}, ${header[td.cellIndex]}: ${td.textContent} (${td.title})`);
  });
  lines.push(header.map(quote).join(","), ...rows.map((r) => r.map(quote).join(",")));
  const link = el("a", { href: URL.createObjectURL(new Blob([`${lines.join("\n")}\n`], { type: "text/csv" })), download: `jik-${document.body.dataset.robot || "robot"}-${key}-${exportName}-${stamp()}.csv` });
  document.body.append(link);
  link.click();
  link.remove();
  setTimeout(() => URL.revokeObjectURL(link.href), 1000);
}

// The panel as an image: the figure on screen with its legend and, under it, the result and
// state it shows, wrapped to the image's width (an image saved alone still says what it is).
// The legend's height is measured in an off-screen copy first, so that the image's bottom margin
// holds the legend and the caption inside the image. ``algorithms``: the chosen algorithms'
// [label, colour]; those the figure draws without legend entries go into the caption.
const CAPTION_FONT = 9;
const CAPTION_LINE = 12;
export async function saveImage(div, key, format, algorithms) {
  if (!div.layout) return null; // (nothing drawn yet)
  const width = div.clientWidth;
  const layout = JSON.parse(JSON.stringify(div.layout));
  const plotHeight = layout.height || div.clientHeight;
  const chars = Math.max(20, Math.floor((width - 16) / (0.62 * CAPTION_FONT)));
  let lines = wrapText(exportNote, chars);
  const legend = { orientation: "h", x: 0, xanchor: "left", yref: "container", yanchor: "bottom", font: { size: 10 } };
  const host = el("div", { className: "export-host" });
  host.style.cssText = `position: fixed; left: -20000px; top: 0; width: ${width}px;`;
  document.body.append(host);
  try {
    const probe = { ...layout, width, height: plotHeight + 400, showlegend: true, legend: { ...legend, y: 0 }, margin: { ...(layout.margin || {}), b: ((layout.margin || {}).b || 48) + 400 } };
    await Plotly.newPlot(host, div.data, probe, { staticPlot: true });
    const box = host.querySelector(".legend");
    const legendHeight = box ? Math.ceil(box.getBBox().height) + 6 : 0;
    // The algorithms a figure draws without legend entries (runs drawn as shapes): their key
    // goes into the caption, in their colours.
    const named = [...host.querySelectorAll(".legendtext")].map((t) => t.textContent);
    const drawnAs = JSON.stringify([div.data, layout.shapes || []]);
    const keys = algorithms.filter(([label, colour]) => !named.includes(label) && drawnAs.includes(colour))
      .map(([label, colour]) => [`▬ ${label}`, colour]);
    const coloured = ([words, colour]) => `<span style="color:${colour}">${words}</span>`;
    const oneLine = keys.map(([words]) => words).join(" · ").length <= chars;
    if (keys.length) lines = [...(oneLine ? [keys.map(coloured).join(" · ")] : keys.map(coloured)), ...lines];
    const caption = CAPTION_LINE * lines.length + 10;
    const extra = legendHeight + caption + 8;
    const height = plotHeight + extra;
    const margin = { ...(layout.margin || {}), b: ((layout.margin || {}).b || 48) + extra };
    const note = {
      text: lines.join("<br>"), xref: "paper", yref: "paper", x: 0, y: 0, yshift: -margin.b + 4,
      xanchor: "left", yanchor: "bottom", align: "left", showarrow: false, font: { size: CAPTION_FONT, color: "#444" },
    };
    Object.assign(layout, {
      showlegend: true, width, height, margin, legend: { ...legend, y: (caption + 6) / height },
      annotations: [...(layout.annotations || []), note],
    });
    const robot = document.body.dataset.robot || "robot";
    return await Plotly.downloadImage({ data: div.data, layout }, {
      format, filename: `jik-${robot}-${key}-${exportName}-${stamp()}`, scale: format === "png" ? 2 : 1, width, height,
    });
  } finally {
    Plotly.purge(host);
    host.remove();
  }
}

// Words of ``text`` in lines of at most ``n`` characters.
function wrapText(text, n) {
  const lines = [];
  let line = "";
  for (const word of text.split(" ")) {
    if (line && line.length + 1 + word.length > n) { lines.push(line); line = word; } else line = line ? `${line} ${word}` : word;
  }
  if (line) lines.push(line);
  return lines;
}

// The time of a download, in a file name: 20261126T204824Z (UTC).
const stamp = () => new Date().toISOString().replace(/[-:]/g, "").replace(/\.\d+Z$/, "Z");
