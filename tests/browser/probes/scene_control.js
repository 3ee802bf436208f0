// The input of viser's GUI panel (in the scene's iframe) labelled `label`: its kind, its value (a
// slider's, a select's option label, a text box's text), the text it shows (a slider's number
// box; else the value) and the box where a press changes it (a slider's track, else the input),
// in the iframe's viewport; null if no row has that label.
// With `unlike` (or `like`): null unless the value differs from (equals) that, so that it can be
// waited for. With `reveal`: the panel is scrolled to show the row first.
({ label, unlike, like, reveal }) => {
  const row = [...document.querySelectorAll("label")]
    .filter((l) => l.textContent.trim() === label)
    .map((l) => l.closest(".mantine-Flex-root"))
    .find((r) => r !== null);
  if (!row) return null;
  const slider = row.querySelector(".mantine-Slider-root");
  const select = row.querySelector(".mantine-Select-input");
  const text = row.querySelector(".mantine-TextInput-input, .mantine-Textarea-input");
  let control = null;
  if (slider) {
    const track = slider.querySelector(".mantine-Slider-trackContainer") || slider;
    const value = slider.querySelector("input[type=hidden]").value;
    const shown = row.querySelector(".mantine-NumberInput-input").value;
    control = { kind: "slider", value, shown, element: track };
  } else if (select) {
    control = { kind: "select", value: select.value, shown: select.value, element: select };
  } else if (text) {
    control = { kind: "text", value: text.value, shown: text.value, element: text };
  }
  if (!control) return null;
  if (unlike !== undefined && control.value === unlike) return null;
  if (like !== undefined && control.value !== like) return null;
  if (reveal) row.scrollIntoView({ block: "nearest" });
  const r = control.element.getBoundingClientRect();
  return {
    kind: control.kind,
    value: control.value,
    shown: control.shown,
    box: { x: r.x, y: r.y, width: r.width, height: r.height },
  };
}
