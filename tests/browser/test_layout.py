"""The page at 1280x720: the scene fits below the sticky header, panel titles are not under their
buttons, tick labels do not overlap, subtitles are not cut off, a panel with nothing to plot
says why, and the unicycle's animation shows its iteration."""

from __future__ import annotations

import pytest

from tests.browser.conftest import probe

expect = pytest.importorskip("playwright.sync_api", reason="playwright not installed").expect
pytestmark = pytest.mark.browser


def _check_panels(tab, panels) -> None:
    for panel in panels:
        seen = tab.page.evaluate(probe("overlaps"), panel)
        assert not seen["overlaps"], (panel, seen["overlaps"])
        assert seen["titleFits"], f"{panel}: its title runs past the panel"
        assert seen["titleBelowHead"], f"{panel}: its title is under the panel's buttons"
        assert seen["titleAbovePlot"], f"{panel}: its title runs into the plot"
        assert not seen["notesOverlap"], f"{panel}: its annotations overlap"


def test_layout_at_1280x720(tabs):
    tab = tabs.open(viewport={"width": 1280, "height": 720})
    page = tab.page
    header = page.locator("header").bounding_box()
    assert header is not None and header["height"] < 90
    page.locator("main").scroll_into_view_if_needed()
    page.evaluate("() => window.scrollTo(0, document.querySelector('main').offsetTop)")
    scene = page.locator("#scene").bounding_box()
    assert scene is not None
    assert scene["y"] >= header["height"] - 1 and scene["y"] + scene["height"] <= 720 + 1
    _check_panels(tab, ["task", "drift", "joints", "augmenting", "sensitivity"])
    tab.page.evaluate("() => window.scrollTo(0, 0)")

    tab.select("#ctl-robot", "manipulator1")
    page.wait_for_selector("#plot-sensitivity:not(.stale) g.xtick text")
    _check_panels(tab, ["sensitivity", "augmenting"])
    tab.screenshots("layout-manipulator1")

    tab.select("#ctl-robot", "unicycle")
    page.wait_for_selector("#plot-sensitivity:not(.stale) .annotation-text")
    _check_panels(tab, ["task", "augmenting", "sensitivity"])
    seen = page.evaluate(probe("overlaps"), "sensitivity")
    assert any("collocation" in a for a in seen["annotations"])
    tab.wait_scene_text("iteration ")
    page.evaluate("() => window.scrollTo(0, document.querySelector('main').offsetTop)")
    tab.screenshots("layout-unicycle")
