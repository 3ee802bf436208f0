// Where the colour `rgb` shows in a PNG (base64): the number of its pixels, their centre and
// their main direction (unit vector, from the covariance of their places), in the PNG's pixels.
async ({ png, rgb, tolerance }) => {
  const img = new Image();
  img.src = `data:image/png;base64,${png}`;
  await img.decode();
  const canvas = document.createElement("canvas");
  canvas.width = img.width;
  canvas.height = img.height;
  const ctx = canvas.getContext("2d");
  ctx.drawImage(img, 0, 0);
  const px = ctx.getImageData(0, 0, img.width, img.height).data;
  const xs = [];
  const ys = [];
  for (let i = 0; i < px.length; i += 4) {
    const d = Math.abs(px[i] - rgb[0]) + Math.abs(px[i + 1] - rgb[1]) + Math.abs(px[i + 2] - rgb[2]);
    if (d < tolerance) {
      xs.push((i / 4) % img.width);
      ys.push(Math.floor(i / 4 / img.width));
    }
  }
  const n = xs.length;
  if (!n) return { n: 0 };
  const mean = (v) => v.reduce((a, b) => a + b, 0) / n;
  const mx = mean(xs);
  const my = mean(ys);
  let sxx = 0;
  let syy = 0;
  let sxy = 0;
  for (let k = 0; k < n; k++) {
    const dx = xs[k] - mx;
    const dy = ys[k] - my;
    sxx += dx * dx;
    syy += dy * dy;
    sxy += dx * dy;
  }
  const angle = 0.5 * Math.atan2(2 * sxy, sxx - syy);
  return { n, x: mx, y: my, ux: Math.cos(angle), uy: Math.sin(angle) };
}
