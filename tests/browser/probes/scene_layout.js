// The 3D view and viser's control panel in the scene's iframe, as boxes [x, y, width, height] in
// the iframe's viewport: the WebGL canvas, and the panel (the box of the GUI's title, "jik
// scene", widened to the panel that holds it: the first ancestor 200 px tall).
() => {
  const box = (e) => {
    const b = e.getBoundingClientRect();
    return [b.x, b.y, b.width, b.height];
  };
  const canvas = document.querySelector("canvas");
  const title = [...document.querySelectorAll("body *")]
    .find((e) => e.childElementCount === 0 && e.textContent.trim() === "jik scene");
  let panel = title || null;
  while (panel && panel.getBoundingClientRect().height < 200) panel = panel.parentElement;
  return {
    viewport: [innerWidth, innerHeight],
    canvas: canvas ? box(canvas) : null,
    panel: panel ? box(panel) : null,
  };
}
