"""The configuration-space panel: both joint paths in 3D with the level surface h = h(x0) and the
self-motion manifolds of the path's corners; the unicycle's three λ coordinates are picked."""

from __future__ import annotations

import pytest

expect = pytest.importorskip("playwright.sync_api", reason="playwright not installed").expect
# A display check: in CI's slow step, to keep the default run under 8 minutes.
pytestmark = [pytest.mark.browser, pytest.mark.slow]


def _legend(tab) -> list[str]:
    return tab.page.locator("#plot-cspace .legendtext").all_text_contents()


def test_configuration_space_of_both_algorithms(tabs):
    tab = tabs.open()
    panel = tab.page.locator("#plot-cspace")
    expect(panel.locator(".gtitle")).to_contain_text("Configuration space (x1, x2, x3)")
    expect(panel.locator(".gl-container canvas").first).to_be_visible()
    expect(tab.page.locator("#scene")).to_have_count(1)  # (its 3D axes take no page's id)
    legend = _legend(tab)
    assert any(t.startswith("level surface h = h(x0)") for t in legend), legend
    assert "self-motion manifolds k(x) = corner" in legend
    assert "pseudoinverse J^P# (8)" in legend and "extended Jacobian J^E# (11)" in legend
    panel.scroll_into_view_if_needed()
    tab.screenshots("cspace-manipulator2")

    tab.select("#ctl-robot", "manipulator1")
    expect(panel.locator(".gtitle")).to_contain_text("Configuration space (x1, x2, x3)")
    assert any(t.startswith("level surface") for t in _legend(tab))

    tab.select("#ctl-robot", "unicycle")
    expect(panel.locator(".gtitle")).to_contain_text(
        "Configuration space (lambda10, lambda11, lambda20)"
    )
    tab.select("#ctl-cspace_axes", "123")
    expect(panel.locator(".gtitle")).to_contain_text(
        "Configuration space (lambda11, lambda20, lambda21)"
    )
    expect(panel.locator(".gtitle")).to_contain_text("lambda10 not shown")
    assert "self-motion manifolds k(x) = corner" in _legend(tab)
    panel.scroll_into_view_if_needed()
    tab.screenshots("cspace-unicycle")
