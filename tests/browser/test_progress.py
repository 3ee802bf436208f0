"""Long computations: a progress bar and a cancel button that goes back to the result on
screen; the second phase of a result (h on a grid, E1, E2) shows its progress and can be
cancelled, the result staying; the cap on iterations that a leg's message names is a control."""

from __future__ import annotations

import re

import pytest

from jik.app.dashboard.controls import PROGRESS_AFTER
from tests.browser.conftest import ARTIFACTS, TIMEOUT, probe

expect = pytest.importorskip("playwright.sync_api", reason="playwright not installed").expect
pytestmark = pytest.mark.browser


def test_a_long_computation_shows_progress_and_can_be_cancelled(tabs):
    """Unicycle, closed path, gamma = 0.01 (ten times the iterations, many seconds): the
    progress bar shows; cancel stops it, the controls and the session go back to the values of
    the result on screen, and the header says which generation was cancelled."""
    tab = tabs.open(scene=False)
    tab.select("#ctl-robot", "unicycle")
    shown = tab.select("#ctl-task", "path")
    second_phase_done(tab, shown)  # (else the bar below may be its E1/E2's, and cancel stop that)
    before = tab.snapshot()["state"]
    box = tab.page.locator("#ctl-gamma-value")
    box.fill("0.01")
    running = tab.posting(lambda: box.dispatch_event("change")).json()["generation"]
    progress = tab.page.locator("#progress-box")
    expect(progress).to_be_visible()
    expect(tab.page.locator("#progress-text")).to_have_text(re.compile(r"^computing \d+%$"))
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
    tab = tabs.open(scene=False)
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


def second_phase_done(tab, generation: int) -> None:
    """Wait until the second phase of ``generation`` is done on the server and its bar gone
    from the page (the status says "up to date" as soon as the runs are drawn, before it)."""
    done = tab.wait_snapshot(
        lambda s: s["computed_generation"] == generation and s["second_phase"] == "done",
        f"the second phase of generation {generation} done",
    )
    assert done["generation"] == generation
    expect(tab.page.locator("#progress-box")).to_be_hidden()


# (CI's slow step: among the longest browser checks; the default run stays under 8 minutes)
@pytest.mark.slow
def test_the_second_phase_shows_its_progress_and_can_be_cancelled(tabs):
    """The unicycle from pose B over T = 20 s: after its runs are drawn, h by characteristics on
    a grid, then E1, E2 take a second or two. The header shows what is computed and how far; cancel
    stops it: the result stays on screen, the h and E1/E2 panels say what was not computed (no
    value of E1, E2 anywhere) and a button computes it, with its progress again."""
    tab = tabs.open()
    tab.select("#ctl-robot", "unicycle")
    preset = tab.change(lambda: tab.page.click("#ctl-preset-q0-B"))  # (pose B: the paper's longest)
    status, progress = tab.page.locator("#status-text"), tab.page.locator("#progress-box")
    second_phase_done(tab, preset)  # (else the watch below may catch the preset's bar)
    box = tab.page.locator("#ctl-T-value")
    box.fill("20")
    # (The bar shows for a second or so: its cancel is clicked the moment it shows, by a watch
    # started before the change, which a loaded machine's slow return from the change could
    # otherwise let the second phase outrun.)
    bar = {"box": "#progress-box", "text": "#progress-text", "timeout": TIMEOUT}
    watch = {**bar, "click": "#cancel", "prefix": "computing h on a grid"}
    tab.page.evaluate(f"arg => {{ window.secondBar = ({probe('when_shown')})(arg); }}", watch)
    generation = tab.change(lambda: box.dispatch_event("change"))
    shown = tab.page.evaluate("() => window.secondBar")
    assert re.fullmatch(r"computing h on a grid \d+%", shown), shown
    expect(status).to_contain_text(f"generation {generation} shown; not computed: ")
    expect(progress).to_be_hidden()
    h, e = tab.page.locator("#plot-augmenting"), tab.page.locator("#plot-sensitivity")
    expect(e).to_contain_text("E1, E2 of characteristics: not computed")
    expect(e).to_contain_text(re.compile(r"E1, E2 not computed: cancelled at \d+%"))
    grid_cancelled = "h on a grid" in status.inner_text()
    if grid_cancelled:  # (the cancel came while h was computed)
        expect(h).to_contain_text("h on a grid: cancelled")
        expect(h).to_contain_text(re.compile(r"not computed: cancelled at \d+% \(while comput"))
        button = h.get_by_role("button", name="compute h and E1, E2")
    else:  # (h was done: it stays, its title says E1, E2 were not computed)
        expect(h).to_contain_text("E1, E2: not computed (cancelled)")
        button = e.get_by_role("button", name="compute E1, E2")
    for panel in (h, e):
        expect(panel).to_have_class(re.compile(r"\bcancelled\b"))
        expect(panel).not_to_have_class(re.compile(r"\bstale\b"))
        expect(panel).not_to_contain_text(re.compile("E[12] ="))
    snapshot = tab.snapshot()
    assert snapshot["second_phase"] == "cancelled" and snapshot["functionals"] is None
    assert snapshot["computed_generation"] == generation == tab.generation
    assert snapshot["state"]["robot_parameters"]["T"] == pytest.approx(20.0)
    expect(box).to_have_value(re.compile(r"^20"))  # (the state stays: only E1, E2 stopped)
    h.scroll_into_view_if_needed()
    tab.screenshots("second-phase-cancelled")

    tab.watch_header()
    button.click()
    expect(status).to_have_text(f"up to date (generation {generation})")
    seen = tab.header_seen()
    assert f"computing E1/E2 of generation {generation} again…" in seen["statuses"], seen
    again = seen["statuses"].index(f"computing E1/E2 of generation {generation} again…")
    took = (seen["at"][-1] - seen["at"][again]) / 1000  # (until "up to date")
    # (a computation shorter than progress_after shows no bar, by design: a fast machine's is)
    if grid_cancelled and took > PROGRESS_AFTER + 0.25:
        assert seen["progress"], f"no progress bar for h on a grid again in {took:.2f} s"
    expect(h).to_contain_text("E1, E2 undefined")  # (h is undefined on part of this box)
    for panel in (h, e):
        expect(panel).not_to_have_class(re.compile(r"\b(cancelled|stale)\b"))
        expect(panel.locator(".recompute")).to_have_count(0)
    assert tab.snapshot()["second_phase"] == "done"
    h.scroll_into_view_if_needed()
    tab.screenshots("second-phase-again")
    tab.page.evaluate("() => window.scrollTo(0, 0)")

    box.fill("6.28")  # (and back to T = 20 s: its runs are cached, h on a grid is not)
    second_phase_done(tab, tab.change(lambda: box.dispatch_event("change")))
    box.fill("20")
    # (watched from before the change, as the first bar: it may be gone when the change returns)
    again = {**bar, "prefix": "computing h on a grid"}
    tab.page.evaluate(f"arg => {{ window.againBar = ({probe('when_shown')})(arg); }}", again)
    generation = tab.change(lambda: box.dispatch_event("change"))
    shown = tab.page.evaluate("() => window.againBar")
    tab.page.screenshot(path=str(ARTIFACTS / "second-phase-progress-1600.png"))
    assert re.fullmatch(r"computing h on a grid \d+%", shown), shown
    expect(status).to_have_text(f"up to date (generation {generation})")
