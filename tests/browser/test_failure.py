"""After a generation fails, the page says what failed where the result would be, which result
(if any) is still on screen, dims it, and offers no export of it as current; a new viewer of a
state that fails sees the failure, not "computing…" forever. The server is `jik serve` whose
computations of gamma = 2.5 raise (tests/browser/failing_serve.py)."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path
from urllib.parse import quote

import pytest

from tests.browser.conftest import ROOT, Tab, Tabs, _free_port, get_json, poll
from tests.browser.failing_serve import MESSAGE, SLOW_GAMMA

expect = pytest.importorskip("playwright.sync_api", reason="playwright not installed").expect
# A display check: in CI's slow step, to keep the default run under 8 minutes.
pytestmark = [pytest.mark.browser, pytest.mark.slow]


@pytest.fixture(scope="module")
def failing_server(chromium, tmp_path_factory):
    port = _free_port()
    log = tmp_path_factory.mktemp("failing") / "serve.log"
    with open(log, "w") as out:
        proc = subprocess.Popen(
            [sys.executable, str(ROOT / "tests" / "browser" / "failing_serve.py"), str(port)],
            cwd=ROOT,
            stdout=out,
            stderr=subprocess.STDOUT,
        )
    base = f"http://127.0.0.1:{port}"

    def healthy() -> bool:
        if proc.poll() is not None:
            pytest.fail(f"failing_serve exited: {log.read_text()[-2000:]}")
        try:
            return get_json(f"{base}/health")["status"] == "ok"
        except OSError:
            return False

    try:
        poll(healthy, "the failing server answering")
        yield base
    finally:
        proc.terminate()
        proc.wait(15)


@pytest.fixture
def failing_tabs(browser, failing_server):
    tabs = Tabs(browser, failing_server)
    try:
        yield tabs
        tabs.check()
    finally:
        tabs.close()


def test_a_failure_names_the_result_still_on_screen(failing_tabs):
    tab = failing_tabs.open()
    page = tab.page
    gamma = page.locator("#ctl-gamma-value")
    gamma.fill("2.5")
    generation = tab.posting(lambda: gamma.dispatch_event("change")).json()["generation"]
    failure = page.locator("#failure")
    expect(failure).to_have_text(f"Generation {generation} failed: {MESSAGE}")
    expect(page.locator("#still-shown")).to_have_text(
        "The plots below still show generation 1 (manipulator2, continuous mode, γ = 1.000, "
        "l = 1.00, closed path, 3 cycles), not the controls' values."
    )
    expect(page.locator("#status-text")).to_have_text(f"generation {generation} failed")
    expect(page.locator("#panels")).to_have_class("panels outdated")
    export = page.locator("#export-json")
    expect(export).to_contain_text("off: generation")
    assert export.get_attribute("href") is None
    assert tab.snapshot()["error"]["shown"]["generation"] == 1
    tab.screenshots("failure")

    # A new viewer of that state: its first generation fails, and nothing is on screen.
    viewer = failing_tabs.new_page(failing_tabs.context())
    viewer.goto(failing_tabs.base + "/?state=" + quote(json.dumps(tab.url_state())))
    expect(viewer.locator("#failure")).to_contain_text(f"Generation 1 failed: {MESSAGE}")
    expect(viewer.locator("#still-shown")).to_have_text("No result is on screen.")
    assert Tab(viewer, failing_tabs.base).status() == "generation 1 failed"

    # The next good change brings a current result back.
    gamma.fill("1.5")
    tab.change(lambda: gamma.dispatch_event("change"))
    expect(failure).to_have_count(0)
    expect(page.locator("#panels")).to_have_class("panels")
    expect(export).to_contain_text(f"(generation {tab.generation})")


def test_an_export_while_a_newer_generation_computes_is_the_one_its_link_names(failing_tabs):
    """The footer's export link names the generation on screen; clicked while a newer one
    computes (gamma 2.25, late), it downloads the generation it names, at once, not the newer
    one once that is in; the link then names the newer one."""
    tab = failing_tabs.open(scene=False)
    page = tab.page
    export = page.locator("#export-json")
    expect(export).to_have_text("export JSON (generation 1)")
    gamma = page.locator("#ctl-gamma-value")
    gamma.fill(str(SLOW_GAMMA))
    generation = tab.posting(lambda: gamma.dispatch_event("change")).json()["generation"]
    expect(export).to_have_text("export JSON (generation 1)")  # (the plots on screen)
    with page.expect_download() as saved:
        export.click()
    data = json.loads(Path(saved.value.path()).read_text())
    assert data["generation"] == 1 and data["state"]["gamma"] == 1.0
    assert tab.snapshot()["computed_generation"] == 1  # (the newer one was not in yet)
    tab.wait_drawn(generation)
    expect(export).to_have_text(f"export JSON (generation {generation})")
