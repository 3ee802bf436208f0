// Resolve the moment `box` shows with a `text` that starts with `prefix` (any, by default), to
// that text, having clicked `click` if given (a user who stops a computation as soon as its bar
// appears); reject after `timeout` ms. Playwright's own waits poll on animation frames, which
// software WebGL slows down to longer than the second or so that a second phase's bar shows on
// two cores; a watch started before the change that makes the bar (`prefix`: the phase it
// waits for) cannot miss it.
({ box, text, click = null, prefix = "", timeout }) => new Promise((resolve, reject) => {
  const shown = document.querySelector(box);
  const words = document.querySelector(text);
  const seen = () => {
    const button = click && document.querySelector(click);
    if (shown.hidden || (button && button.disabled)) return false;
    const said = words.textContent;
    if (!said.startsWith(prefix)) return false;
    if (button) button.click();
    resolve(said);
    return true;
  };
  if (seen()) return;
  const watch = new MutationObserver(() => { if (seen()) watch.disconnect(); });
  watch.observe(shown, { attributes: true });
  watch.observe(words, { childList: true, characterData: true, subtree: true });
  setTimeout(() => { watch.disconnect(); reject(new Error(`${box} did not show within ${timeout} ms`)); }, timeout);
})
