"""The browser's half of ``jik bench latency`` (:mod:`jik.benchmarks.bench_latency`): each
change made in a dashboard page driven by Playwright in Debian's chromium, timed from the
control's event to the plots drawn and to the scene shown, against the page reloaded with the
changed state."""

from __future__ import annotations

import contextlib
import json
import math
import re
import time
from typing import Any
from urllib.parse import parse_qs, quote, urlsplit

from ..bench_latency import CHROMIUM, Change, _progress
from ..latency_server import CHANGE_TIMEOUT, quiet

# In every document, from its start: when each generation first shows. The page sets
# body[data-generation] once a result's plots are drawn; the viser client's status shows
# "generation N: ..." once the scene has drawn it.
_WATCH = """(() => {
    const shown = window.jikShown = {};
    const now = () => performance.timeOrigin + performance.now();
    if (location.pathname.startsWith("/scene")) {
        const note = () => {
            const text = document.body ? document.body.textContent : "";
            for (const m of text.matchAll(/generation (\\d+):/g)) {
                if (!(m[1] in shown)) shown[m[1]] = now();
            }
        };
        new MutationObserver(note).observe(document,
            {childList: true, subtree: true, characterData: true});
    } else {
        new MutationObserver(() => {
            const g = document.body && document.body.dataset.generation;
            if (g && !(g in shown)) shown[g] = now();
        }).observe(document, {attributes: true, subtree: true,
                              attributeFilter: ["data-generation"]});
    }
})();"""

# In the page, once plotly is loaded: the plotly calls in flight, and when the last one began
# or ended (to wait for the page's background drawing: E1/E2, the panels drawn ahead).
_PLOTLY_WATCH = """() => {
    if (window.jikPlotly) return;
    const watch = window.jikPlotly = {busy: 0, last: performance.now()};
    for (const name of ["react", "newPlot", "relayout", "animate", "restyle", "update"]) {
        const call = Plotly[name];
        Plotly[name] = function (...args) {
            watch.busy += 1;
            watch.last = performance.now();
            const done = () => { watch.busy -= 1; watch.last = performance.now(); };
            const p = call.apply(this, args);
            Promise.resolve(p).then(done, done);
            return p;
        };
    }
}"""
# No plotly call in flight, and none began or ended within the last 250 ms.
_IDLE = "() => jikPlotly.busy === 0 && performance.now() - jikPlotly.last > 250"
# When generation g or a later one first showed (epoch ms), or null. (Functions, not
# expressions: the page's Content-Security-Policy forbids evaluating strings.)
_SHOWN = """(g) => {
    const t = Object.keys(jikShown).filter((k) => Number(k) >= g).map((k) => jikShown[k]);
    return t.length ? Math.min(...t) : null;
}"""

_CHANGE = """({selector, event, position}) => {
    const input = document.querySelector(selector);
    if (!input) throw new Error(`the page has no control ${selector}`);
    const old = input.value;
    input.value = String(position);
    if (input.value === old) throw new Error(`${selector} is already at ${old}`);
    const t0 = performance.timeOrigin + performance.now();
    input.dispatchEvent(new Event(event, {bubbles: true}));
    return t0;
}"""

# The page's session, from its scene's address (/scene/?websocket=.../api/sessions/{id}/scene).
_SESSION = """() => {
    const src = (document.querySelector("#scene") || {}).src || "";
    const ws = src ? new URL(src).searchParams.get("websocket") || "" : "";
    const m = ws.match(/\\/api\\/sessions\\/([^/]+)\\/scene/);
    return m ? m[1] : null;
}"""


def _playwright():
    """``playwright.sync_api``, or None: an optional dependency (the ``test`` extra installs
    it), without which the benchmark measures the server alone."""
    try:
        import playwright.sync_api
    except ImportError:
        return None
    return playwright.sync_api


class Tab:
    """A page of the dashboard: its session, its scene's frame, when each generation showed."""

    def __init__(self, page, base: str, pid: int) -> None:
        self.page, self.base, self.pid = page, base, pid
        self.ms = CHANGE_TIMEOUT * 1e3
        self.session: str | None = None  # (known once the page has opened it)
        self.scene: Any = None  # the viser client's frame (a playwright Frame)

    def opened(self) -> None:
        """After a navigation: wait for the first result in the page and the scene."""
        self.page.wait_for_function(_SESSION, timeout=self.ms)
        self.session = self.page.evaluate(_SESSION)
        self.scene = self._scene_frame()
        self.shown_at(1)
        self.page.evaluate(_PLOTLY_WATCH)

    def _scene_frame(self):
        deadline = time.monotonic() + CHANGE_TIMEOUT
        while time.monotonic() < deadline:
            for frame in self.page.frames:
                if frame.parent_frame is not None and "/scene/" in frame.url:
                    return frame
            self.page.wait_for_timeout(50)
        raise TimeoutError("the page did not frame its 3D scene")

    def generation(self) -> int:
        """The session's generation (the server's)."""
        import httpx

        r = httpx.get(f"{self.base}/api/sessions/{self.session}", timeout=10)
        r.raise_for_status()
        return int(r.json()["generation"])

    def shown_at(self, generation: int) -> tuple[float, float]:
        """When ``generation`` (or a later one) first showed in the plots and in the scene
        (epoch ms), waiting for both."""
        out = []
        for frame in (self.page, self.scene):
            frame.wait_for_function(_SHOWN, arg=generation, polling=50, timeout=self.ms)
            out.append(frame.evaluate(_SHOWN, generation))
        return out[0], out[1]

    def compute_ms(self, generation: int) -> float:
        """The server's computation of ``generation`` as the page's footer shows it."""
        text = self.page.evaluate(
            "() => (document.querySelector('#timing') || {}).textContent || ''"
        )
        found = re.match(r"generation (\d+): compute (\d+) ms", text)
        return float(found[2]) if found and int(found[1]) == generation else math.nan

    def settle(self) -> None:
        """Wait until the server's processes are idle, then the page's plotly calls."""
        quiet(self.pid)
        self.page.wait_for_function(_IDLE, polling=50, timeout=self.ms)

    def change(self, change: Change) -> dict:
        """The control changed in the page: latencies to the plots and to the scene [ms]."""
        generation = self.generation() + 1
        arg = {"selector": change.selector, "event": change.event, "position": change.position}
        t0 = self.page.evaluate(_CHANGE, arg)
        plots, scene = self.shown_at(generation)
        return {
            "plots_ms": plots - t0,
            "scene_ms": scene - t0,
            "compute_ms": self.compute_ms(generation),
        }

    def reload(self, change: Change) -> dict:
        """The page loaded anew with the changed state in its link: latencies from the
        navigation's start to the plots and to the scene [ms]."""
        query = parse_qs(urlsplit(self.page.url).query)
        state = change.linked(json.loads(query["state"][0]))
        self.page.goto(f"{self.base}/?state={quote(json.dumps(state))}")
        t0 = self.page.evaluate("() => performance.timeOrigin")
        self.opened()
        plots, scene = self.shown_at(1)
        return {"plots_ms": plots - t0, "scene_ms": scene - t0, "compute_ms": self.compute_ms(1)}


def browser(base: str, pid: int, sessions: list[list[Change]]) -> list[dict]:
    """Each session's changes in a page of its own, changes of each kind alternating between
    the page's own update and a reload with the changed state."""
    import httpx

    samples: list[dict] = []
    count: dict[str, int] = {}
    with _playwright().sync_playwright() as pw:
        chromium = pw.chromium.launch(executable_path=CHROMIUM, args=["--no-sandbox"])
        try:
            context = chromium.new_context(viewport={"width": 1600, "height": 1000})
            context.add_init_script(_WATCH)
            for p, changes in enumerate(sessions):
                tab = Tab(context.new_page(), base, pid)
                tab.page.goto(f"{base}/")
                tab.opened()
                tab.settle()
                for i, change in enumerate(changes):
                    _progress(f"browser: page {p + 1} of {len(sessions)}, change {i + 1}")
                    k = count[change.kind] = count.get(change.kind, -1) + 1
                    mode = "reload" if k % 2 else "jik"
                    timing = tab.reload(change) if mode == "reload" else tab.change(change)
                    samples.append(
                        {"kind": change.kind, "family": change.family, "mode": mode, **timing}
                    )
                    tab.settle()
                tab.page.close()
                with contextlib.suppress(httpx.HTTPError):
                    httpx.delete(f"{base}/api/sessions/{tab.session}", timeout=10)
                quiet(pid)
        finally:
            chromium.close()
    return samples
