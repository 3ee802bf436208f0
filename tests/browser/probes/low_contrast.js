// The texts of the panels' plots whose colour has a contrast below 4.5:1 (WCAG AA) on the
// plots' white background: [{text, colour, ratio}].
() => {
  const luminance = (rgb) => {
    const [r, g, b] = rgb.match(/[\d.]+/g).slice(0, 3).map((v) => {
      const c = Number(v) / 255;
      return c <= 0.03928 ? c / 12.92 : ((c + 0.055) / 1.055) ** 2.4;
    });
    return 0.2126 * r + 0.7152 * g + 0.0722 * b;
  };
  const low = [];
  for (const t of document.querySelectorAll("#panels svg text")) {
    const colour = getComputedStyle(t).fill;
    if (!colour.startsWith("rgb") || !t.textContent.trim()) continue;
    const ratio = 1.05 / (luminance(colour) + 0.05);
    if (ratio < 4.5) low.push({ text: t.textContent, colour, ratio: Math.round(ratio * 100) / 100 });
  }
  return low;
}
