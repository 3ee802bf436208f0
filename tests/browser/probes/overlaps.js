// Pairs of tick labels of a panel whose boxes intersect (their texts), whether the panel's
// title lines fit its width, and whether plotly's toolbar (shown while the mouse is over the
// panel) leaves the title and the plots clear: what a reader sees as overlapping or cut off.
(panel) => {
  const div = document.getElementById(`plot-${panel}`);
  const box = div.getBoundingClientRect();
  const labels = [...div.querySelectorAll(".xtick text, .ytick text")]
    .map((t) => ({ text: t.textContent, r: t.getBoundingClientRect() }))
    .filter((t) => t.r.width > 0);
  const hit = (a, b) => a.left < b.right - 1 && b.left < a.right - 1 && a.top < b.bottom - 1 && b.top < a.bottom - 1;
  const overlaps = [];
  for (let i = 0; i < labels.length; i++) {
    for (let j = i + 1; j < labels.length; j++) {
      if (hit(labels[i].r, labels[j].r)) overlaps.push([labels[i].text, labels[j].text]);
    }
  }
  const title = div.querySelector(".gtitle");
  const t = title ? title.getBoundingClientRect() : null;
  const head = div.querySelector(".panel-head");
  const plots = [...div.querySelectorAll(".nsewdrag")].map((d) => d.getBoundingClientRect().top);
  const notes = [...div.querySelectorAll(".annotation")].map((a) => a.getBoundingClientRect()).filter((r) => r.width > 0);
  const bar = div.querySelector(".modebar");
  const b = bar ? bar.getBoundingClientRect() : null;
  // (the plots: 2D plot areas, colour bars, 3D scenes)
  const drags = [...div.querySelectorAll(".nsewdrag, .colorbar, .gl-container > div")].map((d) => d.getBoundingClientRect());
  let notesOverlap = false;
  for (let i = 0; i < notes.length; i++) for (let j = i + 1; j < notes.length; j++) notesOverlap ||= hit(notes[i], notes[j]);
  return {
    overlaps,
    titleFits: !t || (t.left >= box.left - 1 && t.right <= box.right + 1),
    titleAbovePlot: !t || !plots.length || t.bottom <= Math.min(...plots) + 1,
    notesOverlap,
    toolbarClearOfTitle: !t || !b || !hit(t, b),
    toolbarClearOfPlots: !b || !drags.some((d) => hit(d, b)),
    toolbar: b && [b.left, b.top, b.right, b.bottom],
    plots: drags.map((d) => [d.left, d.top, d.right, d.bottom]),
    titleBelowHead: !t || !head || t.top >= head.getBoundingClientRect().bottom - 1,
    annotations: [...div.querySelectorAll(".annotation-text")].map((a) => a.textContent),
  };
}
