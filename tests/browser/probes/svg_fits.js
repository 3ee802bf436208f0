// Where an exported SVG's legend and caption (its last annotation) lie, measured in the page:
// {width, height, legend: {top, bottom, right} or null, caption: {lines, right, bottom}}.
(text) => {
  const host = document.createElement("div");
  host.style.cssText = "position: fixed; left: 0; top: 0; visibility: hidden;";
  host.innerHTML = text;
  document.body.append(host);
  const svg = host.querySelector("svg");
  const frame = svg.getBoundingClientRect();
  const box = (e) => {
    const r = e.getBoundingClientRect();
    return { top: r.top - frame.top, bottom: r.bottom - frame.top, left: r.left - frame.left, right: r.right - frame.left };
  };
  const legend = svg.querySelector(".legend");
  const notes = svg.querySelectorAll(".annotation");
  const caption = notes[notes.length - 1];
  const lines = [...caption.querySelectorAll("tspan.line")].map((t) => t.textContent);
  const out = {
    width: frame.width, height: frame.height,
    legend: legend ? box(legend) : null,
    legendItems: legend ? [...legend.querySelectorAll(".legendtext")].map((t) => t.textContent) : [],
    caption: { lines: lines.length ? lines : [caption.textContent], ...box(caption.querySelector("text")) },
  };
  host.remove();
  return out;
}
