// Record what the header shows from now on: whether the progress bar was ever visible, and
// every status text and when it showed, in ms (window.jikSeen), to check what a user saw during
// a long computation.
() => {
  const seen = (window.jikSeen = { progress: false, statuses: [], at: [] });
  const look = () => {
    if (!document.getElementById("progress-box").hidden) seen.progress = true;
    const text = document.getElementById("status-text").textContent;
    if (seen.statuses[seen.statuses.length - 1] !== text) {
      seen.statuses.push(text);
      seen.at.push(performance.now());
    }
  };
  new MutationObserver(look).observe(document.querySelector("header"), {
    attributes: true, childList: true, subtree: true, characterData: true,
  });
  look();
}
