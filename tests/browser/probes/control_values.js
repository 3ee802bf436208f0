// The page's controls as a user sees them: each input's and select's value, by element id.
() => Object.fromEntries(
  [...document.querySelectorAll("#controls input, #controls textarea, #controls select")].map((e) => [e.id, e.value]),
)
