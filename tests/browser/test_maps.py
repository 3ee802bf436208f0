"""The paper's map parameters one click from a robot's default view, and a map singular in its
design region says where."""

from __future__ import annotations

import re

import pytest

expect = pytest.importorskip("playwright.sync_api", reason="playwright not installed").expect
pytestmark = pytest.mark.browser


# (CI's slow step: among the longest browser checks; the default run stays under 8 minutes)
@pytest.mark.slow
def test_c1_c2_one_click_away_and_a_singular_map_says_where(tabs):
    """Manipulator 1's default view shows a button per map; one click on e1_optimal (32) shows
    C1 and C2. C2 = -1 makes g(x1) of (32) vanish near x1 = 0.48 inside the design region: the
    verdict warns, naming where; C2 = 1 takes the warning away."""
    tab = tabs.open()
    page = tab.page
    tab.select("#ctl-robot", "manipulator1")
    buttons = page.locator("#ctl-augmentation button")
    expect(buttons).to_have_text(["e2_optimal (36)", "e1_optimal (32)", "e1_taylor (33)"])
    expect(page.locator("#ctl-aug-a")).to_be_visible()  # (the default map's a and b)
    tab.change(lambda: page.click("#ctl-augmentation-e1_optimal"))
    expect(page.locator("#ctl-augmentation-e1_optimal")).to_have_attribute("aria-checked", "true")
    for name in ("C1", "C2"):
        expect(page.locator(f"#ctl-aug-{name}")).to_be_visible()
        expect(page.locator(f"#ctl-aug-{name}-value")).to_be_visible()
    verdict = page.locator("#verdict")
    expect(verdict.locator(".warning")).to_have_count(0)

    c2 = page.locator("#ctl-aug-C2-value")
    c2.fill("-1")
    tab.change(lambda: c2.dispatch_event("change"))
    warning = verdict.locator(".warning")
    expect(warning).to_contain_text("e1_optimal (C1 = 1, C2 = -1) is singular in the design region")
    expect(warning).to_contain_text(re.compile(r"at x1 ∈ \[0\.4\d*, 0\.5\d*\], any x2, any x3"))
    # The extended run stops on its third leg (no drift to draw): the pseudoinverse's three
    # cycles stay drawn in the drift panel.
    expect(page.locator("#plot-drift .scatterlayer .trace .points path")).to_have_count(3)
    tab.screenshots("singular-map")

    c2.fill("1")
    tab.change(lambda: c2.dispatch_event("change"))
    expect(warning).to_have_count(0)
