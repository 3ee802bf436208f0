"""The 3D scene's playback: it animates while the page is edited, and its Pause/Play button
pauses and resumes it."""

from __future__ import annotations

import pytest

expect = pytest.importorskip("playwright.sync_api", reason="playwright not installed").expect
pytestmark = pytest.mark.browser


def test_the_animation_plays_on_while_the_page_is_edited(tabs):
    """With the pointer and the focus on the page's controls, and a slider changed there, the
    scene's position slider keeps advancing: nothing holds the animation."""
    tab = tabs.open(playing=True)
    assert tab.wait_scene_drawn(1)["playing"] is True
    tab.scene_control("position", unlike=tab.scene_control("position")["value"])

    generation = tab.set_slider("#ctl-x0-1", 0.3)  # (hovers and focuses it first)
    tab.wait_scene_drawn(generation)
    for _ in range(2):
        position = tab.scene_control("position")["value"]
        tab.scene_control("position", unlike=position)
    assert tab.page.evaluate("document.activeElement.id") == "ctl-x0-1"
    assert tab.page.locator("#ctl-x0-1:hover").count() == 1
    assert tab.snapshot()["scene"]["playing"] is True


def test_pause_and_play_in_the_scene(tabs):
    """The scene's Pause button stops the animation (the session's scene says it is not
    playing), Play starts it again (the position slider advances)."""
    tab = tabs.open(playing=True)
    assert tab.wait_scene_drawn(1)["playing"] is True
    scene = tab.page.frame_locator("#scene")
    tab.pause_scene()
    expect(scene.get_by_role("button", name="Play")).to_be_visible()
    position = tab.scene_control("position")["value"]

    tab.click_scene_button("Play")
    tab.wait_snapshot(lambda s: s["scene"]["playing"] is True, "the scene playing again")
    expect(scene.get_by_role("button", name="Pause")).to_be_visible()
    tab.scene_control("position", unlike=position)


def test_the_scene_offers_no_share_link(tabs):
    """viser's own share button (a public link to the viser instance, next to the page's "copy
    link") is not in the scene."""
    tab = tabs.open(playing=True)
    tab.wait_scene_drawn(1)
    scene = tab.page.frame_locator("#scene")
    expect(scene.get_by_role("button", name="Pause")).to_be_visible()
    # (viser's settings button, beside where the share button would be, is there)
    expect(scene.locator("button:has(svg.tabler-icon-adjustments)")).to_have_count(1)
    expect(scene.locator("button:has(svg.tabler-icon-share)")).to_have_count(0)
