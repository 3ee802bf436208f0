// Runs in the viser client of the 3D scene (app/scene.py sends it when the scene starts; viser
// replays it to every client that connects). It tells the page that frames the scene when the
// pointer is on the scene's GUI panel, or the keyboard works in it, so that the page holds the
// animation still while the user edits there as on the page's own controls (static/app.js,
// "holding the scene still"). The Playback folder does not hold: its speed and position are
// for watching the animation. Nothing is sent when the scene is not framed.
(() => {
  if (window.jikSceneHold || window.parent === window) return;
  window.jikSceneHold = { pointer: false, keyboard: false };
  const state = window.jikSceneHold;
  // viser's control panel (docked, or floating if the user undocks it).
  const PANEL = "[data-dock-region], [data-testid='floating-panel']";
  const inPlayback = (el) => {
    const folder = el.closest("[data-with-border]");
    return Boolean(folder && folder.firstElementChild
      && folder.firstElementChild.textContent.trim() === "Playback");
  };
  const editing = (el) => el instanceof Element && Boolean(el.closest(PANEL)) && !inPlayback(el);
  const send = () => window.parent.postMessage({ jik: "scene-hold", ...state }, "*");
  // The pointer, from its moves only: it can leave the frame without an event here, and the
  // browser then re-reads the hover under its last place in the frame when the panel changes
  // (pointerover without a move). The page forgets the pointer when it moves on the page, and
  // hears of it again at the next move here (sent on a change, and at least every 150 ms).
  let sentAt = -Infinity;
  document.addEventListener("pointermove", (ev) => {
    const on = editing(ev.target);
    if (on === state.pointer && ev.timeStamp - sentAt < 150) return;
    state.pointer = on;
    sentAt = ev.timeStamp;
    send();
  }, { capture: true, passive: true });
  document.addEventListener("pointerout", (ev) => {
    if (ev.relatedTarget === null) { state.pointer = false; send(); } // (left the frame)
  }, true);
  // The keyboard: focus in the panel that came from a key, not from a press (viser's slider
  // takes the focus on a press, and :focus-visible cannot tell which here).
  let keys = false;
  document.addEventListener("keydown", () => { keys = true; }, true);
  document.addEventListener("pointerdown", () => {
    keys = false;
    if (state.keyboard) { state.keyboard = false; send(); }
  }, true);
  document.addEventListener("focusin", (ev) => { state.keyboard = keys && editing(ev.target); send(); }, true);
  document.addEventListener("focusout", (ev) => {
    if (!editing(ev.relatedTarget)) { state.keyboard = false; send(); }
  }, true);
  window.addEventListener("pagehide", () => { state.pointer = state.keyboard = false; send(); });
})();
