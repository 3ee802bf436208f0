"""The page by keyboard and screen reader: a change made by keyboard that rebuilds the controls
leaves the focus where it was, Tab never lands on a control drawn off screen, a table wider
than its panel scrolls by keyboard, the status line is read out as it changes, and the arrow
keys choose in a radio group."""

from __future__ import annotations

import pytest

expect = pytest.importorskip("playwright.sync_api", reason="playwright not installed").expect
pytestmark = pytest.mark.browser


def test_a_keyboard_change_that_rebuilds_the_controls_keeps_the_focus(tabs):
    """Another robot (or mode) brings other controls: the one changed by keyboard keeps the
    focus, so the next arrow key changes it again instead of scrolling the page."""
    tab = tabs.open(scene=False)
    page = tab.page
    robot = page.locator("#ctl-robot")
    robot.focus()
    tab.change(lambda: page.keyboard.press("ArrowDown"))
    expect(robot).to_have_value("unicycle")
    expect(robot).to_be_focused()
    tab.change(lambda: page.keyboard.press("ArrowUp"))
    expect(robot).to_have_value("manipulator2")
    expect(robot).to_be_focused()
    mode = page.locator("#ctl-mode")
    mode.focus()
    tab.change(lambda: page.keyboard.press("ArrowDown"))
    expect(mode).to_have_value("discrete")
    expect(mode).to_be_focused()


def test_tab_never_lands_on_a_control_off_screen(tabs):
    """Past the page's last control, Tab does not walk through the toolbars of the panels
    drawn off screen ahead of a switch of robot: every control it reaches is on the page."""
    tab = tabs.open(scene=False)
    page = tab.page
    # (another robot's panels, drawn off screen while the page is idle)
    page.wait_for_selector(".ahead .modebar-btn", state="attached")
    page.locator("#copy-link").focus()
    for _ in range(10):
        page.keyboard.press("Tab")
        box = page.evaluate(
            "() => document.activeElement === document.body ? null"
            " : document.activeElement.getBoundingClientRect().toJSON()"
        )
        if box is None:
            break
        assert box["x"] + box["width"] > 0, f"Tab reached a control off screen at {box}"


def test_a_table_wider_than_its_panel_scrolls_by_keyboard(tabs):
    """Table 1 at 1366x768 is wider than its panel: its box is reached with Tab (named by its
    title) and the arrow keys bring its last column into view."""
    tab = tabs.open(scene=False, viewport={"width": 1366, "height": 768})
    page = tab.page
    panel = page.locator("#plot-table")
    last = panel.locator("thead th").last
    expect(last).to_contain_text("(printed)")
    scroller = page.get_by_role("region", name="Table 1 of the paper")
    panel.get_by_role("button", name="CSV").focus()
    page.keyboard.press("Tab")
    expect(scroller).to_be_focused()
    for _ in range(20):
        page.keyboard.press("ArrowRight")
    # (the box scrolls smoothly: its last column comes into view within its right edge)
    page.wait_for_function(
        "([box, cell]) => cell.getBoundingClientRect().right"
        " <= box.getBoundingClientRect().right + 1",
        arg=[scroller.element_handle(), last.element_handle()],
    )


def test_the_status_line_is_read_out(tabs):
    """The header's status is a live region: a screen reader says "up to date" or what failed
    when it changes, without the user going to it."""
    tab = tabs.open(scene=False)
    status = tab.page.get_by_role("status").filter(has_text="up to date")
    expect(status).to_have_text(f"up to date (generation {tab.generation})")


def test_the_arrow_keys_choose_in_a_radio_group(tabs):
    """The augmenting map's options are a radio group: one Tab stop, the map chosen, and the
    arrow keys choose the next or previous map, which is computed as a click's would be."""
    tab = tabs.open(scene=False)
    page = tab.page
    first = page.get_by_role("radio", name="paper_cubic")
    second = page.get_by_role("radio", name="e2_synthesized")
    page.locator("#ctl-l-value").focus()
    page.keyboard.press("Tab")
    expect(first).to_be_focused()
    tab.change(lambda: page.keyboard.press("ArrowRight"))
    expect(second).to_be_checked()
    expect(second).to_be_focused()
    assert tab.snapshot()["state"]["augmentation"] == "e2_synthesized"
    page.keyboard.press("Tab")  # (past the group: the first algorithm's button)
    expect(page.locator("#ctl-algorithms-pseudoinverse")).to_be_focused()
    page.keyboard.press("Shift+Tab")
    expect(second).to_be_focused()
    tab.change(lambda: page.keyboard.press("ArrowLeft"))
    expect(first).to_be_checked()
    assert tab.snapshot()["state"]["augmentation"] == "paper_cubic"


def test_each_panels_help_button_is_named_for_its_panel(tabs):
    """A screen reader hears what each "?" is about ("what this panel shows: Repeatability"),
    not seven buttons named "?"."""
    page = tabs.open(scene=False).page
    buttons = page.locator(".panel-head button.info")
    expect(buttons.first).to_be_attached()
    names = [b.get_attribute("aria-label") for b in buttons.all()]
    assert len(names) >= 7 and len(set(names)) == len(names), names
    assert all(n.startswith("what this panel shows: ") and len(n) > 24 for n in names), names
    expect(page.get_by_role("button", name="what this panel shows: Repeatability")).to_be_visible()
