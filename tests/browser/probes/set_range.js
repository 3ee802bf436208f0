// Move a range input to `position` as a drag does: the value, then an "input" event.
(input, position) => {
  input.value = position;
  input.dispatchEvent(new Event("input", { bubbles: true }));
  return Number(input.value);
}
