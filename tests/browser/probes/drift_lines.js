// The drift panel's lines: each trace's colour and dash, and the strokes the browser drew.
() => {
  const div = document.getElementById("plot-drift");
  return {
    traces: div.data.filter((t) => t.mode === "lines+markers").map((t) => [t.line.color, t.line.dash]),
    strokes: [...div.querySelectorAll(".scatterlayer path.js-line")].map((p) => getComputedStyle(p).stroke),
  };
}
