"""Shared fixtures of the browser tests: `jik serve` on a free port, Debian's chromium driven by
Playwright's sync API, and :class:`Tab`, one dashboard page (its own session) with the helpers
the tests use: wait for a generation, set a slider, read and press the 3D scene's GUI.

Nothing is installed here: the tests use /usr/bin/chromium (``.ci/run`` installs it) and are
skipped, with the reason, when it or Playwright is missing. Every page opened through the
``tabs`` fixture records the requests that leave 127.0.0.1 and the page's errors (uncaught
errors, console errors, in the page and the scene's iframe); the fixture asserts there are none
when the test ends. JavaScript run in the pages lives in ``probes/*.js`` (:func:`probe`).

(Past 400 lines: the fixtures and :class:`Tab`'s helpers are what every browser test shares, and
a conftest is where pytest hands them to the tests without imports.)
"""

from __future__ import annotations

import base64
import functools
import json
import math
import os
import re
import socket
import subprocess
import sys
import time
import urllib.request
import zlib
from pathlib import Path
from urllib.parse import parse_qs, unquote, urlsplit

import pytest

from jik.app.dashboard.algorithms import COLORS, DEFAULT_ALGORITHMS

ROOT = Path(__file__).resolve().parents[2]
PROBES = Path(__file__).resolve().parent / "probes"
CHROMIUM = "/usr/bin/chromium"
ARGS = [
    "--no-sandbox",
    "--disable-background-networking",
    "--disable-component-update",
    "--disable-sync",
    "--no-first-run",
    "--no-default-browser-check",
]
VIEWPORT = {"width": 1600, "height": 1000}
#: The page's 3D scene (its iframe's viser client), left out by ``Tabs.open(scene=False)``.
SCENE_FRAME = re.compile(r"^http://127\.0\.0\.1:\d+/scene/")
#: Milliseconds a wait in a page may take: two cores and software WebGL, with other pages open.
TIMEOUT = 60_000
#: The window sizes of the screenshots in tests/artifacts (800 wide: a narrow window).
SCREEN_SIZES = ((1600, 1000), (1280, 720), (800, 1000))
ARTIFACTS = ROOT / "tests" / "artifacts"
#: The colour of the x arrow of the start point's gizmo (drei's PivotControls).
GIZMO_X_ARROW = (255, 32, 96)
#: The colours as RGB of any algorithm, and of the default view's: their lines in the plots,
#: their robots and traces in the scene.
ALL_COLORS_RGB = {a: tuple(int(c[i : i + 2], 16) for i in (1, 3, 5)) for a, c in COLORS.items()}
COLORS_RGB = {a: ALL_COLORS_RGB[a] for a in DEFAULT_ALGORITHMS}


@functools.cache
def probe(name: str) -> str:
    """The JavaScript function of ``probes/<name>.js`` (for evaluate and wait_for_function)."""
    return (PROBES / f"{name}.js").read_text()


def get_json(url: str) -> dict:
    with urllib.request.urlopen(url, timeout=30) as response:
        return json.loads(response.read())


def poll(condition, what: str, timeout: float = TIMEOUT / 1000):
    """Call ``condition()`` until it returns something truthy, and return that; fail after
    ``timeout`` seconds saying that ``what`` did not happen. (For conditions on the server, read
    over HTTP; conditions in a page are waited for with Playwright's wait_for_function.)"""
    deadline = time.monotonic() + timeout
    while True:
        value = condition()
        if value:
            return value
        if time.monotonic() > deadline:
            pytest.fail(f"{what}: not within {timeout:.0f} s")
        time.sleep(0.1)


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


@pytest.fixture(scope="session")
def chromium():
    """Skip the browser tests, saying why, where chromium or Playwright is missing."""
    if not os.path.exists(CHROMIUM):
        pytest.skip(f"{CHROMIUM} not found: install Debian's chromium (.ci/run does)")
    pytest.importorskip("playwright.sync_api", reason="playwright (Python package) not installed")
    return CHROMIUM


@pytest.fixture(scope="session")
def server(chromium, tmp_path_factory):
    """`python -m jik serve` on a free port, from the repository's root; yields its base URL."""
    port = _free_port()
    log = tmp_path_factory.mktemp("serve") / "jik-serve.log"
    with open(log, "w") as out:
        proc = subprocess.Popen(
            [sys.executable, "-m", "jik", "serve", "--port", str(port)],
            cwd=ROOT,
            stdout=out,
            stderr=subprocess.STDOUT,
        )
    base = f"http://127.0.0.1:{port}"

    def healthy() -> bool:
        if proc.poll() is not None:
            pytest.fail(f"jik serve exited with {proc.returncode}: {log.read_text()[-2000:]}")
        try:
            return get_json(f"{base}/health")["status"] == "ok"
        except OSError:
            return False

    try:
        poll(healthy, f"jik serve answering /health on {base}")
        yield base
    finally:
        proc.terminate()
        try:
            proc.wait(15)
        except subprocess.TimeoutExpired:
            proc.kill()
            proc.wait()


@pytest.fixture(scope="session")
def browser(chromium):
    from playwright.sync_api import expect, sync_playwright

    # expect()'s assertions have a timeout of their own (5 s), which set_default_timeout does
    # not change: on a loaded machine they need the pages' TIMEOUT too.
    expect.set_options(timeout=TIMEOUT)
    with sync_playwright() as p:
        browser = p.chromium.launch(executable_path=chromium, args=ARGS)
        yield browser
        browser.close()


@pytest.fixture(scope="session")
def config(server) -> dict:
    """The dashboard's configuration (panels, colours, progress_after)."""
    return get_json(f"{server}/api/dashboard/config")


class Tab:
    """One dashboard page in its own browser context, hence its own session."""

    def __init__(self, page, base: str, *, scene: bool = True) -> None:
        self.page = page
        self.base = base
        self.has_scene = scene  # (whether the page loaded its 3D scene's frame)

    # -- the page and its session -----------------------------------------------------------
    @property
    def session_id(self) -> str:
        """The page's session, from its scene's websocket (``/api/sessions/{id}/scene``)."""
        src = self.page.get_attribute("#scene", "src")
        assert src, "the scene's iframe has no src"
        socket_url = unquote(parse_qs(urlsplit(src).query)["websocket"][0])
        match = re.search(r"/api/sessions/([^/]+)/scene$", socket_url)
        assert match, f"no session in the scene's websocket {socket_url!r}"
        return match.group(1)

    def snapshot(self) -> dict:
        """The session as the server has it (state, generation, summary, scene)."""
        return get_json(f"{self.base}/api/sessions/{self.session_id}")

    def url_state(self) -> dict:
        """The state the page keeps in its URL (``?state=<JSON>``, or ``?z=`` its JSON deflated
        and in base64url when long, or ``?tab``: in the tab's sessionStorage when too long for a
        link)."""
        query = parse_qs(urlsplit(self.page.url).query, keep_blank_values=True)
        if "tab" in query:
            return json.loads(self.page.evaluate("sessionStorage.getItem('jik-state')"))
        if "z" in query:
            z = query["z"][0]
            raw = base64.urlsafe_b64decode(z + "=" * (-len(z) % 4))
            return json.loads(zlib.decompress(raw, wbits=-15))
        return json.loads(query["state"][0])

    def wait_snapshot(self, condition, what: str) -> dict:
        """Wait until ``condition(snapshot)`` holds for the session's snapshot; return it."""

        def holds() -> dict | None:
            snapshot = self.snapshot()
            return snapshot if condition(snapshot) else None

        return poll(holds, what)

    def wait_settled(self, condition, what: str) -> dict:
        """Wait until the session's snapshot meets ``condition``, its newest generation is
        computed and drawn on the page, and the page's URL holds its state (after changes made
        in the scene, which the test does not see posted); return the snapshot."""

        def settled() -> dict | None:
            s = self.snapshot()
            done = condition(s) and s["computed_generation"] == s["generation"] == self.generation
            return s if done and self.url_state() == s["state"] else None

        return poll(settled, what)

    def controls(self) -> dict[str, str]:
        """Every control's value as the page shows it, by element id."""
        return self.page.evaluate(probe("control_values"))

    @property
    def generation(self) -> int:
        """The generation whose plots the page shows."""
        return int(self.page.evaluate("document.body.dataset.generation"))

    @property
    def robot(self) -> str | None:
        return self.page.evaluate("document.body.dataset.robot")

    def status(self) -> str:
        return self.page.text_content("#status-text") or ""

    def watch_header(self) -> None:
        """Record from now on what the header shows (probes/watch_progress.js): read it with
        :meth:`header_seen`."""
        self.page.evaluate(probe("watch_progress"))

    def header_seen(self) -> dict:
        """Whether the progress bar showed since :meth:`watch_header`, and each status text."""
        return self.page.evaluate("window.jikSeen")

    def wait_drawn(self, generation: int, timeout: float = TIMEOUT) -> int:
        """Wait until the page has drawn the plots of ``generation`` or a later one."""
        self.page.wait_for_function(
            "g => Number(document.body.dataset.generation) >= g", arg=generation, timeout=timeout
        )
        return self.generation

    def posting(self, action):
        """Run ``action`` (a change made on the page) and return the response to the POST of
        the session's state that it sends."""
        with self.page.expect_response(
            lambda r: r.request.method == "POST" and r.url.endswith("/state"), timeout=TIMEOUT
        ) as response:
            action()
        return response.value

    def change(self, action) -> int:
        """Run ``action`` (a change made on the page), wait until its result is drawn and
        return the change's generation."""
        response = self.posting(action)
        assert response.ok, f"the change was refused: {response.status} {response.text()}"
        generation = response.json()["generation"]
        self.wait_drawn(generation)
        return generation

    def set_slider(self, selector: str, position: float) -> int:
        """Move the range input ``selector`` to ``position`` as a user does (the pointer on it,
        then an input event); returns the change's generation, drawn."""
        self.page.hover(selector)
        self.page.focus(selector)
        return self.change(
            lambda: self.page.locator(selector).evaluate(probe("set_range"), position)
        )

    def select(self, selector: str, value: str) -> int:
        """Choose ``value`` in the select ``selector``; returns the change's generation, drawn."""
        return self.change(lambda: self.page.select_option(selector, value))

    def screenshots(self, name: str) -> list[Path]:
        """Screenshots of the page at each of :data:`SCREEN_SIZES`, saved as
        tests/artifacts/<name>-<width>.png (the window goes back to its size after)."""
        ARTIFACTS.mkdir(parents=True, exist_ok=True)
        size = self.page.viewport_size
        paths = []
        for width, height in SCREEN_SIZES:
            self.page.set_viewport_size({"width": width, "height": height})
            self.page.wait_for_function("() => document.fonts.status === 'loaded'")
            path = ARTIFACTS / f"{name}-{width}.png"
            self.page.screenshot(path=str(path))
            paths.append(path)
        if size is not None:
            self.page.set_viewport_size(size)
        return paths

    # -- the 3D scene (viser's client in the iframe) ------------------------------------------
    @property
    def scene(self):
        """The scene's frame (for evaluate and wait_for_function)."""
        assert self.has_scene, "this tab was opened without its scene (Tabs.open(scene=False))"
        frame = self.page.locator("#scene").element_handle().content_frame()
        assert frame is not None, "the scene's iframe has no frame"
        return frame

    def scene_control(
        self, label: str, *, unlike: str | None = None, like: str | None = None, reveal=False
    ) -> dict:
        """The input of the scene's GUI labelled ``label`` (probes/scene_control.js): waited
        for, and for a value unlike (or like) the one given; ``reveal``: scrolled into view."""
        arg: dict = {"label": label, "reveal": reveal}
        if unlike is not None:
            arg["unlike"] = unlike
        if like is not None:
            arg["like"] = like
        handle = self.scene.wait_for_function(probe("scene_control"), arg=arg, timeout=TIMEOUT)
        return handle.json_value()

    def scene_input(self, label: str):
        """A locator of the input (a text box: its textarea) in the row of the scene's GUI
        labelled ``label``."""
        row = f"//label[normalize-space()='{label}']/ancestor::div[contains(@class,'Flex-root')][1]"
        box = "[self::input[not(@type='hidden')] or self::textarea]"
        return self.page.frame_locator("#scene").locator(f"xpath={row}//*{box}")

    def wait_scene_text(self, text: str, timeout: float = TIMEOUT) -> None:
        """Wait until the scene's GUI shows ``text`` (its status, a label)."""
        self.scene.wait_for_function(
            "t => document.body.innerText.includes(t)", arg=text, timeout=timeout
        )

    def wait_scene_drawn(self, generation: int) -> dict:
        """Wait until the session's scene has drawn ``generation`` (or a later one) and its
        status says so; returns the scene's status from the session's snapshot."""
        scene = self.wait_snapshot(
            lambda s: s["scene"].get("generation", 0) >= generation,
            f"the scene drawing generation {generation}",
        )["scene"]
        self.scene.wait_for_function(
            r"g => [...document.body.innerText.matchAll(/generation (\d+):/g)]"
            r".some((m) => Number(m[1]) >= g)",
            arg=generation,
            timeout=TIMEOUT,
        )
        return scene

    def click_scene_button(self, name: str) -> None:
        """Click the button ``name`` of the scene's GUI (Pause, Play). dispatch_event: while
        the scene animates, software WebGL keeps the frame busy, and the actionability checks of
        a click would wait for it to settle."""
        self.page.frame_locator("#scene").get_by_role("button", name=name).dispatch_event("click")

    def pause_scene(self) -> None:
        """Pause the scene's animation and wait until the session's scene says so (a still scene
        renders only on changes: its screenshots and pointer events are quick)."""
        self.click_scene_button("Pause")
        self.wait_snapshot(lambda s: s["scene"].get("playing") is False, "the scene paused")

    def press_scene_slider(self, label: str, fraction: float) -> None:
        """Press the track of the scene's slider ``label`` at ``fraction`` of its length (viser
        takes the value there on the press)."""
        box = self.scene_control(label, reveal=True)["box"]
        frame = self.page.locator("#scene").bounding_box()
        assert frame is not None
        x = frame["x"] + box["x"] + fraction * box["width"]
        y = frame["y"] + box["y"] + box["height"] / 2
        self.page.mouse.click(x, y)

    def find_in_scene(self, rgb, timeout: float = TIMEOUT / 1000) -> dict:
        """Where the colour ``rgb`` shows in the scene (page coordinates, and the main direction
        of its pixels), once two screenshots in a row put it within a pixel of each other."""
        frame = self.page.locator("#scene")

        def look() -> dict:
            png = base64.b64encode(frame.screenshot()).decode()
            arg = {"png": png, "rgb": list(rgb), "tolerance": 40}
            return self.page.evaluate(probe("find_colour"), arg)

        last = {"n": 0}

        def settled():
            nonlocal last
            now = look()
            still = now["n"] > 10 and last["n"] > 10
            still = still and math.hypot(now["x"] - last["x"], now["y"] - last["y"]) < 1.0
            last = now
            return now if still else None

        found = poll(settled, f"the colour {rgb} shown still in the scene", timeout)
        box = frame.bounding_box()
        assert box is not None
        return {**found, "x": box["x"] + found["x"], "y": box["y"] + found["y"]}

    def drag_start_point(self, pixels: float = 30.0) -> None:
        """Drag the start point's gizmo in the scene by its x arrow, ``pixels`` along it."""
        arrow = self.find_in_scene(GIZMO_X_ARROW)
        x, y = arrow["x"], arrow["y"]
        mouse = self.page.mouse
        mouse.move(x, y)
        mouse.down()
        mouse.move(x + pixels * arrow["ux"], y + pixels * arrow["uy"], steps=3)
        mouse.up()


class Tabs:
    """Browser contexts and pages of one test, watched: requests that leave 127.0.0.1 and the
    pages' errors are recorded (:meth:`check`)."""

    def __init__(self, browser, base: str) -> None:
        self.browser = browser
        self.base = base
        self.contexts: list = []
        self.external: list[str] = []
        self.errors: list[str] = []
        self._allowed: list[re.Pattern] = []
        self.checked = False

    def allow_console(self, pattern: str) -> None:
        """Console errors matching ``pattern`` are expected (a refused change's 422 response,
        which chromium logs as a failed resource)."""
        self._allowed.append(re.compile(pattern))

    def context(self, **options):
        """A new browser context (its own cookies, storage and permissions)."""
        context = self.browser.new_context(**{"viewport": VIEWPORT, **options})
        context.set_default_timeout(TIMEOUT)
        context.on("request", lambda r: self._request(r.url))
        self.contexts.append(context)
        return context

    def new_page(self, context):
        """A page of ``context`` whose errors and external requests are recorded."""
        page = context.new_page()
        page.on("pageerror", lambda e: self.errors.append(f"pageerror: {e}"))
        page.on("console", self._console)
        page.on("websocket", lambda ws: self._request(ws.url))
        return page

    def open(self, url: str = "/", *, playing: bool = False, scene: bool = True, **options) -> Tab:
        """The dashboard at ``url`` (a path or a whole link) in a new context, its first
        generation drawn; its scene's playback paused unless ``playing`` (the tests of the
        animation): a scene animating in software WebGL takes most of two cores, which the
        page and the server under test then lack. ``scene=False``: the page without its 3D
        scene's frame (the tests of the page's own controls and panels: the frame's viser client
        is the heaviest part of the page to load and draw in software WebGL)."""
        context = self.context(**options)
        if not scene:
            context.route(SCENE_FRAME, lambda route: route.abort())
        page = self.new_page(context)
        page.goto(url if "://" in url else self.base + url)
        tab = Tab(page, self.base, scene=scene)
        tab.wait_drawn(1)
        if scene:
            # (viser takes a client's clicks and edits only once its camera reported)
            tab.wait_snapshot(lambda s: s["scene"].get("viewers", 0) >= 1, "the scene's viewer")
            if not playing:
                tab.pause_scene()
        return tab

    def _request(self, url: str) -> None:
        parts = urlsplit(url)
        if parts.scheme not in ("data", "blob") and parts.hostname != "127.0.0.1":
            self.external.append(url)

    def _console(self, message) -> None:
        if message.type != "error":
            return
        text = message.text
        if not any(p.search(text) for p in self._allowed):
            self.errors.append(f"console error: {text} ({message.location.get('url')})")

    def set_aside(self, url: str) -> bool:
        """Take the requests of ``url`` (a known product bug) out of the records, with the
        console errors of their failure; whether there were any."""
        if url not in self.external:
            return False
        self.external = [u for u in self.external if u != url]
        self.errors = [e for e in self.errors if url not in e]
        return True

    def check(self) -> None:
        """Assert that no request left 127.0.0.1 and that no page had an error (the fixture
        does at the end of the test, unless the test did)."""
        self.checked = True
        assert not self.external, f"requests left 127.0.0.1: {self.external}"
        assert not self.errors, f"errors in the pages: {self.errors}"

    def close(self) -> None:
        for context in self.contexts:
            context.close()


@pytest.fixture
def tabs(browser, server):
    """Open dashboards in fresh contexts; asserts at the end that no request left 127.0.0.1
    and that no page had an error."""
    tabs = Tabs(browser, server)
    try:
        yield tabs
        if not tabs.checked:
            tabs.check()
    finally:
        tabs.close()
