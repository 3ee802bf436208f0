// What the browser sets on a tab hidden behind another (`hidden` true) or shown again: the
// document's `hidden` and its "visibilitychange" event (headless pages are never hidden).
(hidden) => {
  if (hidden) Object.defineProperty(document, "hidden", { value: true, configurable: true });
  else delete document.hidden;
  document.dispatchEvent(new Event("visibilitychange"));
}
