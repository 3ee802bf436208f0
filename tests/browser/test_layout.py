"""The page at 1280x720: the scene fits below the sticky header, panel titles are not under their
buttons nor under plotly's toolbar (which leaves the plots clear too), tick labels do not
overlap, subtitles are not cut off, a panel with nothing to plot says why, and the unicycle's
animation shows its iteration; at every size the scene's control panel sits beside the 3D view,
never over the robot."""

from __future__ import annotations

import base64

import pytest

from tests.browser.conftest import COLORS_RGB, TIMEOUT, probe

expect = pytest.importorskip("playwright.sync_api", reason="playwright not installed").expect
# A display check: in CI's slow step, to keep the default run under 8 minutes.
pytestmark = [pytest.mark.browser, pytest.mark.slow]


def _check_panels(tab, panels) -> None:
    for panel in panels:
        seen = tab.page.evaluate(probe("overlaps"), panel)
        assert not seen["overlaps"], (panel, seen["overlaps"])
        assert seen["titleFits"], f"{panel}: its title runs past the panel"
        assert seen["titleBelowHead"], f"{panel}: its title is under the panel's buttons"
        assert seen["titleAbovePlot"], f"{panel}: its title runs into the plot"
        assert not seen["notesOverlap"], f"{panel}: its annotations overlap"
        assert seen["toolbarClearOfTitle"], f"{panel}: plotly's toolbar covers its title"
        assert seen["toolbarClearOfPlots"], f"{panel}: plotly's toolbar covers its plots"


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
    _check_panels(tab, ["task", "drift", "joints", "augmenting", "sensitivity", "cspace"])
    tab.page.evaluate("() => window.scrollTo(0, 0)")

    tab.select("#ctl-robot", "manipulator1")
    page.wait_for_selector("#plot-sensitivity:not(.stale) g.xtick text")
    _check_panels(tab, ["sensitivity", "augmenting"])
    tab.screenshots("layout-manipulator1")

    tab.select("#ctl-robot", "unicycle")
    page.wait_for_selector("#plot-sensitivity:not(.stale) .annotation-text")
    _check_panels(tab, ["task", "joints", "augmenting", "sensitivity"])
    seen = page.evaluate(probe("overlaps"), "sensitivity")
    assert any("collocation" in a for a in seen["annotations"])
    tab.wait_scene_text("iteration ")
    page.evaluate("() => window.scrollTo(0, document.querySelector('main').offsetTop)")
    tab.screenshots("layout-unicycle")


def _overlap(a, b) -> float:
    """The area two boxes [x, y, width, height] share."""
    w = min(a[0] + a[2], b[0] + b[2]) - max(a[0], b[0])
    h = min(a[1] + a[3], b[1] + b[3]) - max(a[1], b[1])
    return max(0.0, w) * max(0.0, h)


@pytest.mark.parametrize("size", [(1600, 1000), (1280, 720), (800, 900)])
def test_the_scenes_panel_never_covers_the_robot(tabs, size):
    """viser's control panel is docked beside the 3D view (its canvas ends where the panel
    begins), never laid over it as the sheet viser gives a narrow window; the robots are drawn
    in that view: the extended Jacobian's blue robot and trace, and the pseudoinverse's red, in
    the canvas's own pixels, and again after the window is resized to each other size."""
    width, height = size
    tab = tabs.open(viewport={"width": width, "height": height})
    tab.wait_scene_drawn(1)
    for w, h in [size, *[s for s in ((1600, 1000), (1280, 720), (800, 900)) if s != size]]:
        tab.page.set_viewport_size({"width": w, "height": h})
        tab.page.locator("#scene").scroll_into_view_if_needed()
        seen = tab.scene.wait_for_function(
            f"() => {{ const s = ({probe('scene_layout')})(); "
            "return s.canvas && s.panel && s.panel[2] > 200 ? s : null; }",
            timeout=TIMEOUT,
        ).json_value()
        canvas, panel = seen["canvas"], seen["panel"]
        assert _overlap(canvas, panel) == 0, (w, h, seen)
        assert canvas[2] >= 250 and canvas[3] >= 300, (w, h, seen)  # (a view, not a sliver)
        png = base64.b64encode(tab.scene.locator("canvas").first.screenshot()).decode()
        for algorithm, rgb in COLORS_RGB.items():
            found = tab.page.evaluate(
                probe("find_colour"), {"png": png, "rgb": list(rgb), "tolerance": 60}
            )
            assert found["n"] > 50, (w, h, algorithm, found)
    tab.page.set_viewport_size({"width": width, "height": height})
    tab.screenshots(f"scene-panel-{width}")


def test_a_window_resize_keeps_each_figure_s_height_and_takes_the_new_width(tabs):
    """After the window narrows and widens again, each panel is as tall as before (its
    figure's own height: an arm's joints panel is taller than the others) and its plot as wide
    as the panel (as plotly measures it); plotly's own resize had shrunk every figure to the
    panels' least height."""
    tab = tabs.open(viewport={"width": 1400, "height": 1000}, scene=False)
    page = tab.page
    sizes = (
        "() => [...document.querySelectorAll('.panels .js-plotly-plot')].map(p => [p.id, "
        "Math.round(p.getBoundingClientRect().height), parseFloat(getComputedStyle(p).width), "
        "Math.round(p.querySelector('.main-svg').getBoundingClientRect().width)])"
    )
    fitted = (
        "() => [...document.querySelectorAll('.panels .js-plotly-plot')].every(p => "
        "Math.abs(parseFloat(getComputedStyle(p).width) - "
        "p.querySelector('.main-svg').getBoundingClientRect().width) < 1)"
    )
    before = page.evaluate(sizes)
    assert len(before) >= 5
    for width in (1000, 1400):
        page.set_viewport_size({"width": width, "height": 1000})
        page.wait_for_function(fitted, timeout=TIMEOUT)
    after = page.evaluate(sizes)
    assert [(p, h) for p, h, *_ in after] == [(p, h) for p, h, *_ in before]
    assert all(abs(panel - plot) < 1 for _, _, panel, plot in after)
