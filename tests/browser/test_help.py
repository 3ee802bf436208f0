"""Reading the page without the paper: one key of colours and line styles (header, every panel,
the 3D scene, saved images), units on mixed norms, help for every control and panel, and an
"about" section with links to the paper and the API docs."""

from __future__ import annotations

from pathlib import Path

import pytest

from tests.browser.conftest import probe

expect = pytest.importorskip("playwright.sync_api", reason="playwright not installed").expect
# A display check: in CI's slow step, to keep the default run under 8 minutes.
pytestmark = [pytest.mark.browser, pytest.mark.slow]


def test_one_key_everywhere_and_help_per_panel(tabs, config):
    tab = tabs.open()
    page = tab.page
    legend = page.locator("#legend")
    expect(legend).to_contain_text("pseudoinverse J^P# (8): solid line; translucent robot")
    expect(legend).to_contain_text("extended Jacobian J^E# (11): dashed line; opaque robot")
    tab.wait_scene_text("opaque robot")
    for panel in config["panels"]:
        head = page.locator(f"#plot-{panel['id']} > .panel-head")
        expect(head).to_contain_text("pseudoinverse J^P# (8)")
        expect(head).to_contain_text("extended Jacobian J^E# (11)")
        help_text = page.locator(f"#help-{panel['id']}")
        expect(help_text).to_be_hidden()
        head.locator("button.info").click()
        expect(help_text).to_have_text(panel["help"])
    # The drift is a norm of metres and radians: its axis says so.
    expect(page.locator("#plot-drift .ytitle")).to_contain_text("[m and rad mixed]")
    expect(page.locator("#verdict")).to_contain_text("[m and rad mixed]")
    tab.screenshots("help-panels")

    # Saved images carry the legend and the state they show.
    with page.expect_download() as saved:
        page.locator("#plot-drift .panel-tools button", has_text="SVG").click()
    svg = Path(saved.value.path()).read_text()
    assert "pseudoinverse J^P# (8)" in svg and "extended Jacobian J^E# (11)" in svg
    assert "jik · generation 1 · manipulator2, continuous mode" in svg


def test_controls_explain_the_papers_symbols_and_about_links(tabs):
    tab = tabs.open()
    page = tab.page
    gamma = page.locator("label", has=page.locator("#ctl-gamma"))
    assert "decay rate of the task error" in (gamma.get_attribute("title") or "")
    tab.select("#ctl-robot", "manipulator1")
    tab.change(lambda: page.click("#ctl-augmentation-e1_optimal"))
    c1 = page.locator("label", has=page.locator("#ctl-aug-C1"))
    assert "integration constants of the E1-optimal map (32)" in (c1.get_attribute("title") or "")
    tab.select("#ctl-robot", "unicycle")
    lam = page.locator("label", has=page.locator("#ctl-x0-0"))
    expect(lam).to_contain_text("x0: lambda10")  # (the help names the variable as the label)
    assert "u1 = lambda10 + lambda11 sin t" in (lam.get_attribute("title") or "")

    about = page.locator("#about")
    about.locator("summary").click()
    expect(about).to_contain_text("Repeatability.")
    expect(about).to_contain_text("What to try first.")
    assert page.get_attribute("#api-docs-link", "href") == "/docs"
    assert "amcs" in (page.get_attribute("#paper-link", "href") or "")
    about.scroll_into_view_if_needed()
    tab.screenshots("about")
    docs = page.request.get(tab.base + "/docs")
    assert docs.ok


def test_the_plots_texts_are_readable(tabs):
    """Every text of the plots, their notes included (the sensitivity panel's "E1 = ∞" under
    the map whose E1 diverges), has a contrast of at least 4.5:1 on the plots' white."""
    tab = tabs.open(scene=False)
    page = tab.page
    expect(page.locator("#plot-sensitivity:not(.stale) .annotation-text").first).to_contain_text(
        "= ∞"
    )
    assert page.evaluate(probe("low_contrast")) == []
