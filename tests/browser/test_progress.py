"""Long computations: a progress bar and a cancel button that goes back to the result on
screen; the cap on iterations that a leg's message names is a control."""

from __future__ import annotations

import pytest

from tests.browser.conftest import ARTIFACTS

expect = pytest.importorskip("playwright.sync_api", reason="playwright not installed").expect
pytestmark = pytest.mark.browser


def test_a_long_computation_shows_progress_and_can_be_cancelled(tabs):
    """Unicycle, closed path, gamma = 0.01 (ten times the iterations, many seconds): the
    progress bar shows; cancel stops it, the controls and the session go back to the values of
    the result on screen, and the header says which generation was cancelled."""
    tab = tabs.open()
    tab.select("#ctl-robot", "unicycle")
    shown = tab.select("#ctl-task", "path")
    before = tab.snapshot()["state"]
    box = tab.page.locator("#ctl-gamma-value")
    box.fill("0.01")
    running = tab.posting(lambda: box.dispatch_event("change")).json()["generation"]
    progress = tab.page.locator("#progress-box")
    expect(progress).to_be_visible()
    expect(tab.page.locator("#progress-text")).to_contain_text("computing")
    tab.page.screenshot(path=str(ARTIFACTS / "progress-1600.png"))
    tab.page.click("#cancel")
    status = tab.page.locator("#status-text")
    expect(status).to_contain_text(f"generation {running} was cancelled")
    expect(progress).to_be_hidden()
    snapshot = tab.wait_settled(lambda s: s["state"] == before, "back to the shown values")
    assert snapshot["summary"] is not None and tab.generation > shown
    expect(box).to_have_value("0.100")


def test_the_iteration_cap_is_a_control_the_message_names(tabs):
    """A cap of 10 integrator steps stops every leg; the verdict names the control, and raising
    it (its number box) gives converged legs."""
    tab = tabs.open()
    cap = tab.page.locator("#ctl-max_iterations-value")
    expect(cap).to_have_value("20000")
    cap.fill("10")
    tab.change(lambda: cap.dispatch_event("change"))
    verdict = tab.page.locator("#verdict")
    expect(verdict).to_contain_text("did not converge within 10 integrator steps")
    expect(verdict).to_contain_text("raise “max integrator steps per leg”")
    label = tab.page.locator("label", has=cap)
    expect(label).to_contain_text("max integrator steps per leg")
    cap.fill("20000")
    tab.change(lambda: cap.dispatch_event("change"))
    expect(verdict).to_contain_text("extended Jacobian J^E#: repeatable")
