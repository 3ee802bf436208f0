// Resolve the moment `box` shows, to the text `text` showed then, having clicked `click` if
// given (a user who stops a computation as soon as its bar appears); reject after `timeout` ms.
// Playwright's own waits poll on animation frames, which software WebGL slows down to longer
// than the second or so that a second phase's bar shows on two cores.
({ box, text, click = null, timeout }) => new Promise((resolve, reject) => {
  const shown = document.querySelector(box);
  const seen = () => {
    const button = click && document.querySelector(click);
    if (shown.hidden || (button && button.disabled)) return false;
    const said = document.querySelector(text).textContent;
    if (button) button.click();
    resolve(said);
    return true;
  };
  if (seen()) return;
  const watch = new MutationObserver(() => { if (seen()) watch.disconnect(); });
  watch.observe(shown, { attributes: true });
  setTimeout(() => { watch.disconnect(); reject(new Error(`${box} did not show within ${timeout} ms`)); }, timeout);
})
