"""A catalogue arm in the dashboard: the user picks the Franka Panda (7 joints, the pose task
x y z rx ry rz), sees it in the 3D scene with its targets as pose frames, runs both algorithms
with its E2-synthesized map (its E2 shown beside E2 of each single joint), reads in the verdict
that the pseudoinverse drifts and the extended run comes back and stays within the joint
limits, and computes the arm's atlas."""

from __future__ import annotations

import re

import pytest

from tests.browser.conftest import get_json

expect = pytest.importorskip("playwright.sync_api", reason="playwright not installed").expect
pytestmark = [pytest.mark.browser, pytest.mark.slow]


def test_the_panda_with_its_pose_task(tabs):
    tab = tabs.open()
    page = tab.page
    generation = tab.select("#ctl-robot", "panda")
    snapshot = tab.wait_settled(lambda s: s["state"]["robot"] == "panda", "the Panda")
    state = snapshot["state"]
    assert state["robot_definition"] == {"name": "panda", "task": "pose"}
    assert len(state["x0"]) == 7 and all(len(p) == 6 for p in state["path"])
    assert state["augmentation"] == "e2_synthesized"
    # Its controls: seven start sliders, the path as 6-coordinate pose points.
    for k in range(7):
        expect(page.locator(f"#ctl-x0-{k}")).to_be_attached()
    path = page.locator("#ctl-path")
    assert len(path.input_value().split(";")[0].split(",")) == 6
    # As a user types them: the rotation vector's computed 1.29e-17 shows as 0.
    expect(path).to_have_value(re.compile(r"^0\.3034, 0\.0459, 0\.5903, 0, 0, -0\.15;\n"))

    summary = snapshot["summary"]
    assert summary["pseudoinverse"]["drift"][-1] > 1e-5  # the pseudoinverse drifts
    assert max(summary["extended"]["drift"]) < 1e-9  # the synthesized map keeps x0
    for a in ("pseudoinverse", "extended"):
        assert summary[a]["limits"] == {
            "within": True,
            "violation": None,
            "farthest": None,
            "ends_outside": False,
        }
    verdict = page.locator("#verdict")
    expect(verdict).to_contain_text("pseudoinverse J^P#: not repeatable")
    expect(verdict).to_contain_text("extended Jacobian J^E#: repeatable")
    expect(verdict).to_contain_text("stayed within the joint limits of the Franka Panda")
    expect(verdict).not_to_have_class(re.compile(r"\bpending\b"))  # (dimmed while computing)

    scene = tab.wait_scene_drawn(generation)
    assert scene["robot"] == "panda" and scene["mechanism"] == "Chain"
    assert scene["joints"] == 10  # base link, 7 joints, the flange, the end (fixed ones drawn)
    assert scene["pose_frames"] == 4  # the path's three pose targets and k(x0)
    tab.screenshots("arm-panda")
    # The task panel: position and rotation vector against theta; E2 of the 7-joint map beside
    # E2 of each single joint, and its E1 (the second phase's Sobol rule).
    expect(page.locator("#plot-task")).to_contain_text("rz [rad]")
    sensitivity = page.locator("#plot-sensitivity")
    expect(sensitivity).to_contain_text("of a single joint held", timeout=120_000)
    expect(sensitivity).to_contain_text("h = +x1")
    expect(sensitivity).to_contain_text("E1 (13) of h = 0.002346 ± 1e-06")  # (the same nodes)
    expect(page.locator("#plot-augmenting")).to_contain_text(
        "E1 = 0.002346 ± 1e-06, E2 = 0.0001731 ± 1e-07"
    )

    # Its atlas: 16 starts on the self-motion curve of k(x0), two cycles, both algorithms.
    page.locator("#atlas").scroll_into_view_if_needed()
    page.fill("#atlas-starts", "16")
    page.fill("#atlas-cycles", "2")
    with page.expect_response(
        lambda r: r.request.method == "POST" and r.url.endswith("/atlas")
    ) as response:
        page.click("#atlas-compute")
    assert response.value.status == 202, response.value.text()
    job = response.value.json()["id"]
    expect(page.locator("#atlas-status")).to_contain_text("Atlas done", timeout=240_000)
    expect(page.locator("#plot-atlas .heatmaplayer image")).to_have_count(2)
    expect(page.locator("#plot-atlas")).to_contain_text("runs left the joint limits")
    atlas = get_json(f"{tab.base}/api/sessions/{tab.session_id}/atlas/{job}")
    assert len(atlas["starts"][0]) == 16 and len(atlas["starts"][0][0]) == 7
    assert atlas["request"]["robot"]["name"] == "panda"


def test_the_panda_with_a_position_task_and_four_formula_maps(tabs):
    """p - r = 4: from the robot editor, the Panda's task "xyz" with h = (x2, x3, x5, x7); a
    closed path of 3-coordinate points typed in the path box; the extended inverse comes back,
    the pseudoinverse does not, the h panel says what it shows for p - r > 1 and the E1/E2
    panel gives E2 of the vector."""
    tab = tabs.open(scene=False)
    page = tab.page
    tab.select("#ctl-robot", "panda")
    page.click("#robot-editor-open")
    expect(page.locator("#robot-kind")).to_have_value("panda")
    page.fill("#robot-field-task", "xyz")
    page.fill("#robot-field-augmentations", '[{"name": "formula", "h": ["x2", "x3", "x5", "x7"]}]')
    tab.change(lambda: page.click("#robot-apply"))
    page.fill("#ctl-path", "0.35, 0.05, 0.55; 0.3, 0.1, 0.6")
    tab.change(lambda: page.dispatch_event("#ctl-path", "change"))
    snapshot = tab.wait_settled(lambda s: len(s["state"]["path"]) == 2, "the typed path")
    assert snapshot["state"]["robot_definition"]["task"] == "xyz"
    summary = snapshot["summary"]
    assert summary["pseudoinverse"]["drift"][-1] > 1e-4
    assert max(summary["extended"]["drift"]) < 1e-9
    assert summary["extended"]["h_change"] < 1e-9  # (each of the four components is conserved)
    expect(page.locator("#plot-augmenting")).to_contain_text("a vector of p − r = 4")
    # The E1/E2 panel scores the vector over the seven joints, E2 in the frame it names.
    sensitivity = page.locator("#plot-sensitivity")
    expect(sensitivity).to_contain_text("E1, E2 of the vector formula: h = x2, x3, x5, x7")
    expect(sensitivity).to_contain_text("E2 in the kernel frame of joints [1, 5, 6, 7]")
