"""The page's controls and the 3D scene's GUI are two views of one session: a change made in
either shows in both, and a refused value leaves both showing the value in force."""

from __future__ import annotations

import json
import re
import urllib.request
from urllib.parse import quote

import numpy as np
import pytest

from jik.app.scene.controls import MARK

expect = pytest.importorskip("playwright.sync_api", reason="playwright not installed").expect
pytestmark = pytest.mark.browser


def refused_path(point: str) -> str:
    """The refusal of a closed path of one point ``point`` that is not numbers."""
    return f"path: point 1 of 1, '{point}', is not numbers separated by ',' " + (
        "(write 'y1, y2; y1, y2; ...')"
    )


# (CI's slow step: among the longest browser checks; the default run stays under 8 minutes)
@pytest.mark.slow
def test_a_refused_value_shows_in_both_with_the_value_in_force(tabs):
    """An unreadable closed path typed on the page, then in the scene, is refused: the page's
    status and the scene's status say so, the scene's path box is marked (its label), and the
    page's box, the scene's box and the server keep the path in force."""
    tabs.allow_console(r"status of 422")  # the page's POST of the refused value
    tab = tabs.open()
    tab.wait_scene_drawn(1)
    in_force = tab.controls()["ctl-path"]
    assert in_force == "1, 1;\n1, 2;\n0, 2;\n0, 1"  # (a point per line)
    assert tab.scene_control("closed path")["value"] == in_force
    generation = tab.snapshot()["generation"]
    status = tab.page.locator("#status-text")

    path = tab.page.locator("#ctl-path")
    path.fill("1, x")
    response = tab.posting(lambda: path.dispatch_event("change"))
    assert response.status == 422
    expect(status).to_have_text(f"refused (here): {refused_path('1, x')}")
    expect(status).to_have_class(re.compile(r"\berror\b"))
    tab.wait_scene_text(f"refused: {refused_path('1, x')}")
    expect(path).to_have_value(in_force)
    marked = MARK + "closed path"
    assert tab.scene_control(marked)["value"] == in_force

    tab.scene_input(marked).fill("2, y")
    tab.page.frame_locator("#scene").get_by_role("button", name="apply closed path").click()
    expect(status).to_have_text(f"refused (in the 3D scene): {refused_path('2, y')}")
    tab.wait_scene_text(f"refused: {refused_path('2, y')}")
    assert tab.scene_control(marked, like=in_force)["value"] == in_force
    expect(path).to_have_value(in_force)

    snapshot = tab.snapshot()
    assert snapshot["generation"] == generation
    assert snapshot["state"]["path"] == [[1, 1], [1, 2], [0, 2], [0, 1]]
    assert tab.url_state()["path"] == snapshot["state"]["path"]


def test_page_and_scene_show_the_same_values(tabs):
    """gamma and x1 of the start set on the page show in the scene's sliders; cycles pressed
    on the scene's slider show on the page's."""
    tab = tabs.open()
    tab.wait_scene_drawn(1)

    before = tab.scene_control("γ (decay rate)")["value"]
    tab.set_slider("#ctl-gamma", 0.30103)  # log10(2), snapped to the slider's step
    gamma = tab.snapshot()["state"]["gamma"]
    expect(tab.page.locator("#ctl-gamma-value")).to_have_value(f"{gamma:.3f}")
    scene = tab.scene_control("γ (decay rate)", unlike=before)
    assert float(scene["value"]) == pytest.approx(gamma, abs=1e-9)
    # The page's log-scale slider sends 4 significant digits (here 1.972); the scene's number
    # box shows the 2 decimals of its step (0.01).
    assert float(scene["shown"]) == pytest.approx(gamma, abs=0.005)

    before = tab.scene_control("x0: x1")["value"]
    tab.set_slider("#ctl-x0-0", 0.45)
    x1 = tab.snapshot()["state"]["x0"][0]
    assert x1 == pytest.approx(0.45, abs=1e-12)
    scene = tab.scene_control("x0: x1", unlike=before)
    assert float(scene["value"]) == pytest.approx(x1, abs=1e-9)
    assert scene["shown"] == "0.45"

    cycles = tab.snapshot()["state"]["cycles"]
    tab.press_scene_slider("cycles", 0.5)
    changed = tab.wait_settled(lambda s: s["state"]["cycles"] != cycles, "cycles changed, drawn")
    cycles = changed["state"]["cycles"]
    assert 8 <= cycles <= 12  # the middle of 1..20
    expect(tab.page.locator("#ctl-cycles")).to_have_value(str(cycles))
    expect(tab.page.locator("#ctl-cycles-value")).to_have_value(str(cycles))
    scene = tab.scene_control("cycles")
    assert scene["value"] == scene["shown"] == str(cycles)


def test_errors_show_beside_their_control_in_the_users_text(tabs):
    """A path with an unreadable point, a target coordinate "abc" and a number box out of range:
    each error shows beside its control, quoting what was typed; "abc" is not sent as 0."""
    tabs.allow_console(r"status of 422")
    tab = tabs.open()
    page = tab.page
    path = page.locator("#ctl-path")
    path.fill("1,1;;abc")
    assert tab.posting(lambda: path.dispatch_event("change")).status == 422
    row = page.locator("label", has=path)
    expect(row.locator(".field-error")).to_have_text(
        "“1,1;;abc” was refused: path: point 2 of 2, 'abc', is not numbers separated by ',' "
        "(write 'y1, y2; y1, y2; ...')"
    )

    tab.select("#ctl-task", "target")
    generation = tab.snapshot()["generation"]
    box = page.locator("#ctl-target-1")
    box.fill("abc")
    box.dispatch_event("change")
    target_row = page.locator("label", has=box)
    expect(target_row.locator(".field-error")).to_have_text(
        "“abc” is not a number; nothing was sent"
    )
    assert tab.snapshot()["generation"] == generation  # (not sent as 0)
    # The header says what is wrong now, not the path's earlier refusal.
    expect(page.locator("#status-text")).to_have_text(
        re.compile(r"^not sent \(here\): .+: “abc” is not a number$")
    )
    expect(row.locator(".field-error")).to_have_count(0)  # (the path row is gone, or clear)

    # Every slider has a box for an exact value.
    for slider in page.locator("#controls input[type=range]").all():
        expect(page.locator(f"#{slider.get_attribute('id')}-value")).to_be_visible()
    exact = page.locator("#ctl-gamma-value")
    exact.fill("0.437")
    generation = tab.change(lambda: exact.dispatch_event("change"))
    assert tab.snapshot()["state"]["gamma"] == 0.437
    cycles = page.locator("#ctl-cycles-value")
    if cycles.count() == 0:  # (the target task has no cycles: back to the path)
        tab.select("#ctl-task", "path")
    cycles.fill("50")
    assert tab.posting(lambda: cycles.dispatch_event("change")).status == 422
    expect(page.locator("label", has=cycles).locator(".field-error")).to_have_text(
        "“50” was refused: cycles: Input should be less than or equal to 20"
    )
    expect(cycles).to_have_value("3")  # (the value in force)
    tab.screenshots("field-errors")


@pytest.mark.slow
def test_a_refusal_beside_a_control_goes_when_its_value_changes_elsewhere(tabs):
    """γ = -1 typed on the page is refused beside its box; γ then set elsewhere (the 3D scene,
    or any client of the session) to 2: the box shows 2, and the refusal of "-1" is gone."""
    tabs.allow_console(r"status of 422")
    tab = tabs.open()
    page = tab.page
    box = page.locator("#ctl-gamma-value")
    box.fill("-1")
    assert tab.posting(lambda: box.press("Enter")).status == 422
    error = page.locator("label", has=box).locator(".field-error")
    expect(error).to_contain_text("“-1” was refused")
    box.blur()  # (the user moves on: a box being edited keeps what is typed in it)
    request = urllib.request.Request(
        f"{tab.base}/api/sessions/{tab.session_id}/state",
        data=json.dumps({"gamma": 2.0}).encode(),
        headers={"Content-Type": "application/json"},
    )
    generation = json.loads(urllib.request.urlopen(request, timeout=30).read())["generation"]
    tab.wait_drawn(generation)
    expect(box).to_have_value("2.000")
    expect(error).to_have_count(0)


@pytest.mark.slow
def test_a_singular_start_is_marked_at_the_starts_controls(tabs):
    """A link to the 3R arm stretched out, x0 = (0, 0, 0), where J J^T is singular: the runs stop
    at their first leg, and the start's controls are marked as a refused value's are (the
    engine's message beside them, each coordinate invalid), in the page and in the 3D scene; a
    coordinate moved off the singular set takes every mark away."""
    chain = {"name": "planar_chain", "joints": "RRR", "lengths": [1.0, 1.0, 1.0]}
    state = {"robot": "planar_chain", "robot_definition": chain, "x0": [0.0, 0.0, 0.0]}
    state |= {"task": "target", "target": [2.0, 1.0]}
    tab = tabs.open("/?state=" + quote(json.dumps(state)))
    page = tab.page
    boxes = [page.locator(f"#ctl-x0-{i}-value") for i in range(3)]
    note = page.locator("label", has=boxes[0]).locator(".field-error")
    expect(note).to_contain_text("J J^T is singular")
    expect(note).to_contain_text("at x = (0, 0, 0)")
    for i, box in enumerate(boxes):
        expect(box).to_have_attribute("aria-invalid", "true")
        expect(page.locator(f"#ctl-x0-{i}")).to_have_attribute("aria-invalid", "true")
    assert tab.snapshot()["summary"]["pseudoinverse"]["field"] == "x0"
    tab.scene_control(MARK + "x0: x2")  # (the scene marks its sliders too)

    boxes[1].fill("0.5")
    tab.change(lambda: boxes[1].dispatch_event("change"))
    assert tab.snapshot()["summary"]["pseudoinverse"]["success"]
    expect(page.locator("#controls .field-error")).to_have_count(0)
    expect(page.locator("#controls [aria-invalid]")).to_have_count(0)
    tab.scene_control("x0: x2")


# (CI's slow step: the Panda's runs take most of its 20 s; tests/app/test_controls.py checks the
# path's text a point per line in the default run)
@pytest.mark.slow
def test_a_pose_path_shows_whole_a_point_per_line(tabs):
    """The Franka Panda's closed path has 6 coordinates a point (x y z rx ry rz): its box shows
    every point whole, a line each, nothing scrolled out of sight and within the controls; a
    point added on a new line (Shift+Enter) and sent with Enter, as a one-line box is sent,
    becomes the path's last point, and the box grows to show it."""
    tab = tabs.open(scene=False)
    page = tab.page
    tab.select("#ctl-robot", "panda")
    points = tab.snapshot()["state"]["path"]
    path = page.locator("#ctl-path")
    lines = path.input_value().split("\n")
    assert len(lines) == len(points) >= 3
    assert all(len(line.rstrip(";").split(",")) == 6 for line in lines)
    hidden = "b => [b.scrollWidth - b.clientWidth, b.scrollHeight - b.clientHeight]"
    assert path.evaluate(hidden) == [0, 0]
    box, form = path.bounding_box(), page.locator("#controls").bounding_box()
    assert box is not None and form is not None
    assert box["x"] + box["width"] <= form["x"] + form["width"]
    height = box["height"]

    path.click()
    path.press("Control+End")
    path.press("Shift+Enter")
    path.press_sequentially("0.31, 0.05, 0.6, 0, 0, 0")
    tab.change(lambda: path.press("Enter"))
    # (the points as shown: to 4 decimals)
    shown = [*points, [0.31, 0.05, 0.6, 0.0, 0.0, 0.0]]
    np.testing.assert_allclose(tab.snapshot()["state"]["path"], shown, atol=1e-4)
    assert path.evaluate(hidden) == [0, 0]
    grown = path.bounding_box()
    assert grown is not None and grown["height"] > height


def test_one_coordinate_edited_leaves_the_others_exact(tabs):
    """A target of many decimals, shown to 4: editing its second coordinate sends the first as
    it is, not as shown."""
    tab = tabs.open(scene=False)
    page = tab.page
    tab.select("#ctl-task", "target")
    exact = 1.123456789
    request = urllib.request.Request(
        f"{tab.base}/api/sessions/{tab.session_id}/state",
        data=json.dumps({"target": [exact, 1.0]}).encode(),
        headers={"Content-Type": "application/json"},
    )
    tab.wait_drawn(json.loads(urllib.request.urlopen(request, timeout=30).read())["generation"])
    first = page.locator("#ctl-target-0")
    expect(first).to_have_value("1.1235")
    second = page.locator("#ctl-target-1")
    second.fill("1.5")
    tab.change(lambda: second.press("Enter"))
    assert tab.snapshot()["state"]["target"] == [exact, 1.5]


def test_a_value_in_force_typed_back_after_a_refusal_says_the_result_is_current(tabs):
    """A start where the runs stop (the 3R arm stretched out), its controls marked; a refused
    gamma, then the value in force typed back, which the server accepts without a new
    generation: the header says the result on screen is up to date instead of keeping the
    refusal, gamma's note is gone, and the start's marks of the stopped runs are back."""
    tabs.allow_console(r"status of 422")
    chain = {"name": "planar_chain", "joints": "RRR", "lengths": [1.0, 1.0, 1.0]}
    state = {"robot": "planar_chain", "robot_definition": chain, "x0": [0.0, 0.0, 0.0]}
    state |= {"task": "target", "target": [2.0, 1.0]}
    tab = tabs.open("/?state=" + quote(json.dumps(state)), scene=False)
    page = tab.page
    start = page.locator("label", has=page.locator("#ctl-x0-0-value")).locator(".field-error")
    expect(start).to_contain_text("J J^T is singular")

    status = page.locator("#status-text")
    box = page.locator("#ctl-gamma-value")
    gamma = page.locator("label", has=box).locator(".field-error")
    in_force = box.input_value()
    box.fill("-1")
    assert tab.posting(lambda: box.press("Enter")).status == 422
    expect(status).to_contain_text("refused (here): gamma")
    expect(gamma).to_contain_text("“-1” was refused")
    generation = tab.snapshot()["generation"]
    box.fill(str(float(in_force)))  # (the value in force, as typed: "1.0" where "1.000" shows)
    assert tab.posting(lambda: box.press("Enter")).json()["generation"] == generation
    expect(status).to_have_text(f"up to date (generation {generation})")
    expect(status).not_to_have_class(re.compile(r"\berror\b"))
    expect(gamma).to_have_count(0)
    expect(box).not_to_have_attribute("aria-invalid", "true")
    expect(start).to_contain_text("J J^T is singular")
    expect(page.locator("#ctl-x0-2-value")).to_have_attribute("aria-invalid", "true")
