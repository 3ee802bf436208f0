"""The robot editor: a user defines a planar RRR arm on the page, sees a bad length
refused next to its field, fixes it, applies, and sees both algorithms' result for the new
robot, in the verdict and in the 3D scene."""

from __future__ import annotations

import pytest

expect = pytest.importorskip("playwright.sync_api", reason="playwright not installed").expect
pytestmark = pytest.mark.browser


def test_a_planar_rrr_arm_from_the_editor(tabs):
    tabs.allow_console(r"status of 422")  # the page's POST of the refused definition
    tab = tabs.open()
    tab.wait_drawn(1)
    page = tab.page
    page.click("#robot-editor-open")
    page.select_option("#robot-kind", "planar_chain")
    # The fields are the engine's description of the kind (robot_kinds), served to the page.
    expect(page.locator("#robot-field-joints")).to_be_visible()
    page.fill("#robot-field-joints", "RRR")
    page.fill("#robot-field-lengths", "1, 0.8")  # one length short
    response = tab.posting(lambda: page.click("#robot-apply"))
    assert response.status == 422
    error = page.locator("[data-field=lengths] .field-error")
    expect(error).to_be_visible()
    expect(error).to_contain_text("one entry per joint (3), got 2")
    expect(page.locator("#robot-field-lengths")).to_have_attribute("aria-invalid", "true")
    expect(page.locator("#robot-note")).to_contain_text("not applied")
    tab.screenshots("robot-editor-refused")

    page.fill("#robot-field-lengths", "1, 0.8, 0.6")
    generation = tab.change(lambda: page.click("#robot-apply"))
    expect(error).to_be_hidden()
    expect(page.locator("#robot-field-lengths")).not_to_have_attribute("aria-invalid", "true")
    assert tab.robot == "planar_chain"
    snapshot = tab.wait_settled(lambda s: s["state"]["robot"] == "planar_chain", "the new arm")
    state = snapshot["state"]
    assert state["robot_definition"] == {
        "name": "planar_chain",
        "joints": "RRR",
        "lengths": [1.0, 0.8, 0.6],
    }
    assert tab.url_state()["robot_definition"] == state["robot_definition"]  # (the link)
    summary = snapshot["summary"]
    assert summary["pseudoinverse"]["success"] and summary["extended"]["success"]
    assert summary["pseudoinverse"]["drift"][-1] > 1e-4  # the pseudoinverse drifts
    assert summary["extended"]["drift"][-1] < 1e-9  # h = x3 is kept: repeatable
    verdict = page.locator("#verdict")
    expect(verdict).to_contain_text("pseudoinverse")
    expect(verdict).to_contain_text("extended Jacobian")
    # Its default map is shown as what it is, h = x3, not as "formula (9)".
    expect(page.locator("#ctl-augmentation")).to_have_text("formula: h = x3")
    expect(page.locator("#plot-augmenting .gtitle")).to_contain_text("formula: h = x3")

    scene = tab.wait_scene_drawn(generation)
    assert scene["robot"] == "planar_chain"
    assert scene["mechanism"] == "Chain" and scene["joints"] == 4  # base, 2 elbows, the end
    tab.screenshots("robot-editor-rrr")


def test_a_urdf_arm_from_a_link_is_drawn_in_the_scene(tabs):
    """The 4-joint URDF arm shipped with the tests: a link holding its definition
    opens a session that computes both algorithms and a scene that draws the arm's chain."""
    import json
    from pathlib import Path
    from urllib.parse import quote

    urdf = (Path(__file__).resolve().parents[1] / "data" / "arm4.urdf").read_text()
    state = {
        "robot": "urdf",
        "robot_definition": {"name": "urdf", "urdf": urdf, "end_link": "tool"},
    }
    tab = tabs.open("/?state=" + quote(json.dumps(state)))
    snapshot = tab.wait_settled(lambda s: s["state"]["robot"] == "urdf", "the URDF arm")
    assert snapshot["summary"]["pseudoinverse"]["success"]
    scene = tab.wait_scene_drawn(snapshot["generation"])
    assert scene["robot"] == "urdf"
    assert scene["mechanism"] == "Chain" and scene["joints"] == 7  # base link, 5 joints, the end
    tab.screenshots("robot-editor-urdf")


def _pasted_arm(tabs, extra: str):
    """A page whose robot is the 4-joint test arm's URDF with ``extra`` before ``</robot>``,
    pasted in the editor and applied; its tab and that URDF."""
    from pathlib import Path

    text = (Path(__file__).resolve().parents[1] / "data" / "arm4.urdf").read_text()
    urdf = text.replace("</robot>", extra + "</robot>")
    tab = tabs.open(scene=False)
    page = tab.page
    page.click("#robot-editor-open")
    page.select_option("#robot-kind", "urdf")
    page.fill("#robot-field-urdf", urdf)
    page.fill("#robot-field-end_link", "tool")
    tab.change(lambda: page.click("#robot-apply"))
    tab.wait_settled(lambda s: s["state"]["robot"] == "urdf", "the long URDF arm")
    return tab, urdf


def test_a_long_urdf_pasted_in_the_editor_survives_a_reload(tabs):
    """A URDF of some tens of kB (a real robot's) made the page's address, which holds the
    state, longer than the server takes (431 on a reload or a copied link): such a state is held
    deflated (?z=), and a reload opens the same robot."""
    pads = "".join(f'<link name="pad_{i:05d}"/>' for i in range(2500))  # (60 kB)
    tab, urdf = _pasted_arm(tabs, pads)
    page = tab.page
    assert "z=" in page.url and len(page.url) < 16 * 1024, len(page.url)
    assert tab.url_state()["robot_definition"]["urdf"] == urdf

    assert page.reload().status == 200
    tab.wait_drawn(1)  # (the new session's first generation)
    snapshot = tab.wait_settled(lambda s: s["state"]["robot"] == "urdf", "the arm, reloaded")
    assert snapshot["state"]["robot_definition"]["urdf"] == urdf


def test_a_urdf_too_long_for_a_link_stays_in_its_tab(tabs):
    """A URDF whose state is longer than a link can carry even deflated (the server refuses a
    request line over 64 kB) stays in the tab: a reload opens it, "copy link" says it is too
    large, and the same address in another tab says where the state is."""
    import random

    noise = random.Random(7).randbytes(60_000).hex()  # (120 kB that deflate cannot shorten)
    tab, urdf = _pasted_arm(tabs, f"<!-- {noise} -->")
    page = tab.page
    page.wait_for_url("**?*tab*")
    assert len(page.url) < 4096 and tab.url_state()["robot_definition"]["urdf"] == urdf
    page.click("#copy-link")
    expect(page.locator("#copy-link")).to_have_text("too large for a link")

    address = page.url
    assert page.reload().status == 200
    tab.wait_drawn(1)  # (the new session's first generation)
    snapshot = tab.wait_settled(lambda s: s["state"]["robot"] == "urdf", "the arm, reloaded")
    assert snapshot["state"]["robot_definition"]["urdf"] == urdf
    other = tabs.open(address, scene=False)
    expect(other.page.locator("#notice")).to_contain_text("stays in the tab that made it")


def test_a_refused_definition_keeps_what_was_typed(tabs):
    """A definition the session refuses leaves the editor as the user typed it (another kind
    than the robot in force included: a formula robot, a pasted URDF), with the error beside
    the field it names; a zero or negative link length is refused beside ``lengths``."""
    tabs.allow_console(r"status of 422")
    tab = tabs.open(scene=False)
    page = tab.page
    page.click("#robot-editor-open")
    page.select_option("#robot-kind", "planar_chain")
    page.fill("#robot-field-lengths", "1, -0.8, 0.6")
    page.fill("#robot-field-title", "my arm")
    assert tab.posting(lambda: page.click("#robot-apply")).status == 422
    expect(page.locator("[data-field=lengths] .field-error")).to_contain_text(
        "lengths[1]: must be positive (a link's length), got -0.8"
    )
    expect(page.locator("#robot-field-lengths")).to_have_value("1, -0.8, 0.6")
    expect(page.locator("#robot-field-title")).to_have_value("my arm")

    page.fill("#robot-field-lengths", "1, 0.8, 0.6")
    tab.change(lambda: page.click("#robot-apply"))  # a planar chain in force
    expect(page.locator("#robot-note")).to_contain_text("applied: planar_chain")
    # Another robot picked: the editor keeps the definition, and says it is not in use.
    tab.change(lambda: page.select_option("#ctl-robot", "manipulator1"))
    expect(page.locator("#robot-note")).to_have_text(
        "not in use (another robot is chosen): apply to use it again"
    )
    tab.change(lambda: page.click("#robot-apply"))
    expect(page.locator("#robot-note")).to_contain_text("applied: planar_chain")

    # A formula robot with a bad formula: refused while the planar chain stays in force.
    page.select_option("#robot-kind", "formula")
    page.fill("#robot-field-variables", "a, b, c")
    page.fill("#robot-field-task", "a +* b\nc")
    page.fill("#robot-field-title", "by formula")
    assert tab.posting(lambda: page.click("#robot-apply")).status == 422
    expect(page.locator("[data-field=task] .field-error")).to_have_text(
        "task[0]: expected a number, a name or '(' at position 3"
    )
    expect(page.locator("[data-field=task] .field-error")).to_be_visible()
    expect(page.locator("#robot-kind")).to_have_value("formula")
    expect(page.locator("#robot-field-variables")).to_have_value("a, b, c")
    expect(page.locator("#robot-field-task")).to_have_value("a +* b\nc")
    expect(page.locator("#robot-field-title")).to_have_value("by formula")
    expect(page.locator("#robot-note")).to_contain_text("not applied: see the field task")

    # A pasted URDF whose end link is not in it: the text stays, the error is at end_link.
    urdf = '<robot name="r"><link name="a"/></robot>'
    page.select_option("#robot-kind", "urdf")
    page.fill("#robot-field-urdf", urdf)
    assert tab.posting(lambda: page.click("#robot-apply")).status == 422
    expect(page.locator("[data-field=end_link] .field-error")).to_contain_text("is not a link")
    expect(page.locator("#robot-field-urdf")).to_have_value(urdf)

    # Back to the formula: what was typed there is still there.
    page.select_option("#robot-kind", "formula")
    expect(page.locator("#robot-field-task")).to_have_value("a +* b\nc")
    assert tab.snapshot()["state"]["robot"] == "planar_chain"


def test_a_planar_4r_chain_runs_with_two_degrees_of_redundancy(tabs):
    """A planar 4R chain (p - r = 2): both algorithms run (its default map h = (x3, x4), shown
    on the map's button), the drift and the scene work, and the panels of one scalar h say
    why they are empty; a single formula h for it is refused beside the augmentations field."""
    tabs.allow_console(r"status of 422")
    tab = tabs.open()
    page = tab.page
    page.click("#robot-editor-open")
    page.select_option("#robot-kind", "planar_chain")
    page.fill("#robot-field-joints", "RRRR")
    page.fill("#robot-field-lengths", "1, 0.8, 0.6, 0.4")
    generation = tab.change(lambda: page.click("#robot-apply"))
    snapshot = tab.wait_settled(lambda s: s["state"]["robot"] == "planar_chain", "the 4R chain")
    summary = snapshot["summary"]
    assert summary["pseudoinverse"]["success"] and summary["extended"]["success"]
    assert summary["pseudoinverse"]["drift"][-1] > 1e-4
    assert summary["extended"]["drift"][-1] < 1e-9
    verdict = page.locator("#verdict")
    expect(verdict).to_contain_text("pseudoinverse J^P#: not repeatable")
    expect(verdict).to_contain_text("extended Jacobian J^E#: repeatable")
    expect(page.locator("#ctl-augmentation")).to_contain_text("formula: h = x3, x4")
    expect(page.locator("#plot-augmenting")).to_contain_text("p − r = 2")
    scene = tab.wait_scene_drawn(generation)
    assert scene["robot"] == "planar_chain" and scene["joints"] == 5

    page.fill("#robot-field-augmentations", '[{"name": "formula", "h": "x4"}]')
    assert tab.posting(lambda: page.click("#robot-apply")).status == 422
    error = page.locator("[data-field=augmentations] .field-error")
    expect(error).to_contain_text("must be a list of 2 formulas (p - r = 2")
    expect(page.locator("#robot-field-joints")).to_have_value("RRRR")


def test_back_after_a_change_of_a_state_held_in_its_tab_brings_that_state_back(tabs):
    """A state too long for a link has the same address (?tab) whatever its values: a change of
    it made no history entry and left the entry's state the one before, so back left the arm
    altogether (to the state before it was pasted). Each change is an entry here too."""
    import random

    noise = random.Random(7).randbytes(60_000).hex()
    tab, urdf = _pasted_arm(tabs, f"<!-- {noise} -->")
    page = tab.page
    page.wait_for_url("**?*tab*")
    before, length = tab.url_state(), page.evaluate("history.length")
    task = "target" if before["task"] != "target" else "path"
    tab.select("#ctl-task", task)
    assert page.evaluate("history.length") == length + 1
    assert page.evaluate("history.state.state.task") == task
    tab.change(page.go_back)
    snapshot = tab.wait_settled(lambda s: s["state"]["task"] == before["task"], "the state before")
    assert snapshot["state"]["robot_definition"]["urdf"] == urdf


@pytest.mark.slow  # (CI's slow step: the default run stays under 8 minutes)
def test_applying_the_definition_in_force_again_says_it_is_applied(tabs):
    """Apply pressed twice on the same definition: the second changes nothing (no new
    generation, no state event), and the note says the definition is applied, not
    "applying…" for ever."""
    tab = tabs.open(scene=False)
    page = tab.page
    page.click("#robot-editor-open")
    page.select_option("#robot-kind", "planar_chain")
    generation = tab.change(lambda: page.click("#robot-apply"))
    expect(page.locator("#robot-note")).to_have_text("applied: planar_chain")
    response = tab.posting(lambda: page.click("#robot-apply"))
    assert response.ok and response.json()["generation"] == generation
    expect(page.locator("#robot-note")).to_have_text("applied: planar_chain")
    assert tab.generation == generation


@pytest.mark.slow  # (CI's slow step: the default run stays under 8 minutes)
def test_back_to_another_definition_shows_it_in_the_editor(tabs):
    """Back brings a definition other than the one the editor last applied: the editor's
    fields show the definition in force, and its note no longer says that the one applied is
    (nor, back from a robot of the picker, that the definition is not in use)."""
    tab = tabs.open(scene=False)
    page = tab.page
    page.click("#robot-editor-open")
    page.select_option("#robot-kind", "planar_chain")
    tab.change(lambda: page.click("#robot-apply"))  # the example: RRR, 1, 0.8, 0.6
    page.fill("#robot-field-joints", "RRRR")
    page.fill("#robot-field-lengths", "1, 1, 1, 1")
    tab.change(lambda: page.click("#robot-apply"))
    expect(page.locator("#robot-note")).to_have_text("applied: planar_chain")
    tab.change(page.go_back)
    tab.wait_settled(lambda s: s["state"]["robot_definition"]["joints"] == "RRR", "the RRR arm")
    expect(page.locator("#robot-field-joints")).to_have_value("RRR")
    expect(page.locator("#robot-field-lengths")).to_have_value("1, 0.8, 0.6")
    expect(page.locator("#robot-note")).to_have_text("")

    tab.change(lambda: page.select_option("#ctl-robot", "manipulator1"))
    page.fill("#robot-field-lengths", "1, 0.9, 0.6")
    tab.change(lambda: page.click("#robot-apply"))
    tab.change(lambda: page.select_option("#ctl-robot", "manipulator1"))
    expect(page.locator("#robot-note")).to_contain_text("not in use")
    tab.change(page.go_back)
    tab.wait_settled(lambda s: s["state"]["robot"] == "planar_chain", "the arm applied")
    expect(page.locator("#robot-field-lengths")).to_have_value("1, 0.9, 0.6")
    expect(page.locator("#robot-note")).not_to_contain_text("not in use")
