"""Choosing the algorithms in the page: a third one (the posture inverse) pressed among the
controls gives three traces in three colours in the drift panel, drawn in those colours, three
keys, its gain as a slider, and the verdict's sentence comparing it with the paper's two."""

from __future__ import annotations

import math

import pytest

from tests.browser.conftest import ALL_COLORS_RGB, TIMEOUT, Tab, probe

expect = pytest.importorskip("playwright.sync_api", reason="playwright not installed").expect
# ~15 s: in CI's slow step, to keep the default run under 8 minutes (the default run checks the
# choice through the session API: tests/app/test_dashboard_algorithms.py).
pytestmark = [pytest.mark.browser, pytest.mark.slow]

THREE = ["pseudoinverse", "extended", "posture"]


def test_three_algorithms_chosen_in_the_page(tabs, config):
    tab = tabs.open(scene=False)
    page = tab.page
    posture = page.locator("#ctl-algorithms-posture")
    expect(posture).to_have_attribute("aria-pressed", "false")
    tab.change(lambda: posture.click())
    expect(posture).to_have_attribute("aria-pressed", "true")
    assert tab.snapshot()["state"]["algorithms"] == THREE
    assert tab.url_state()["algorithms"] == THREE  # (a link keeps the choice)
    expect(page.locator("#ctl-alg-gain")).to_be_visible()

    drift = page.evaluate(probe("drift_lines"))
    assert [c for c, _ in drift["traces"]] == [config["colors"][a] for a in THREE]
    assert len({d for _, d in drift["traces"]}) == 3  # (one line style each)
    drawn = {tuple(int(v) for v in s[4:-1].split(",")) for s in drift["strokes"]}
    assert {ALL_COLORS_RGB[a] for a in THREE} <= drawn

    keys = page.locator("#legend .key[data-algorithm]:visible")
    expect(keys).to_have_count(3, timeout=TIMEOUT)
    said = page.locator('#verdict p[data-algorithm="posture"].why')
    expect(said).to_contain_text("less than the pseudoinverse's")
    expect(said).to_contain_text("does not reach the extended Jacobian's")

    # The gain slider's box: a new gain is a new posture run, the others' stay cached.
    generation = tab.change(
        lambda: (page.fill("#ctl-alg-gain-value", "3"), page.press("#ctl-alg-gain-value", "Enter"))
    )
    summary = tab.snapshot()["summary"]
    assert generation > 1 and tab.snapshot()["state"]["algorithm_parameters"] == {"gain": 3.0}
    assert summary["pseudoinverse"]["cached"] and not summary["posture"]["cached"]


def _curves(tab, config) -> dict[str, list[float]]:
    """Each chosen algorithm's drift line as the page holds it, by algorithm."""
    return {
        a: tab.page.evaluate(probe("trace_y"), {"plot": "plot-drift", "name": config["labels"][a]})
        for a in THREE
    }


def test_the_posture_rest_in_the_page(tabs, config):
    """Choosing the posture inverse shows its rest, one slider per joint at the start x0 (the
    default of a robot without home) and a 'rest = x0' button; moving a rest coordinate gives a
    new posture line in the drift panel, the others' stay (cached), and the verdict names the
    rest. A second tab of the same browser has its own session: its rest is the default, and
    its change does not reach the first."""
    tab = tabs.open(scene=False)
    page = tab.page
    expect(page.locator("#ctl-alg-rest-0")).to_have_count(0)
    tab.change(lambda: page.locator("#ctl-algorithms-posture").click())
    x0 = tab.snapshot()["state"]["x0"]
    for i in range(3):
        expect(page.locator(f"#ctl-alg-rest-{i}")).to_be_visible()
        expect(page.locator(f"#ctl-alg-rest-{i}-value")).to_have_value(f"{x0[i]:.3f}")
    expect(page.locator("#ctl-preset-rest-x0")).to_be_visible()
    expect(page.locator("#ctl-preset-rest-home")).to_have_count(0)  # (Manipulator 2: no home)
    before = _curves(tab, config)
    assert all(len(before[a]) == 3 for a in THREE)  # (three cycles each)

    generation = tab.set_slider("#ctl-alg-rest-1", 0.5)
    snapshot = tab.snapshot()
    rest = snapshot["state"]["algorithm_parameters"]["rest"]
    assert rest[0] == x0[0] and rest[1] == pytest.approx(0.495) and rest[2] == x0[2]
    assert tab.url_state()["algorithm_parameters"]["rest"] == rest  # (a link keeps it)
    summary = snapshot["summary"]
    assert not summary["posture"]["cached"]
    assert summary["pseudoinverse"]["cached"] and summary["extended"]["cached"]
    after = _curves(tab, config)
    assert tab.generation == generation
    assert after["pseudoinverse"] == before["pseudoinverse"]
    assert after["extended"] == before["extended"]
    assert max(abs(a - b) for a, b in zip(after["posture"], before["posture"], strict=True)) > 0.05
    said = page.locator('#verdict p[data-algorithm="posture"].why')
    expect(said).to_contain_text(f"x_rest = (0, 0.495, {x0[2]:.4g}) (set)")

    # A second tab of the same browser: its own session, its own rest.
    other = tabs.new_page(page.context)
    other.goto(tabs.base + "/")
    second = Tab(other, tabs.base)
    second.wait_drawn(1)
    assert second.session_id != tab.session_id
    second.change(lambda: other.locator("#ctl-algorithms-posture").click())
    expect(other.locator("#ctl-alg-rest-1-value")).to_have_value(f"{x0[1]:.3f}")
    assert "rest" not in second.snapshot()["state"]["algorithm_parameters"]
    second.set_slider("#ctl-alg-rest-0", -0.99)  # (on the step, 0.015)
    assert second.snapshot()["state"]["algorithm_parameters"]["rest"][0] == pytest.approx(-0.99)
    assert tab.snapshot()["state"]["algorithm_parameters"]["rest"] == rest
    expect(page.locator("#ctl-alg-rest-0-value")).to_have_value(f"{x0[0]:.3f}")

    # Back to the start: 'rest = x0' is the default again, which the state then leaves out.
    tab.change(lambda: page.locator("#ctl-preset-rest-x0").click())
    assert "rest" not in tab.snapshot()["state"]["algorithm_parameters"]
    expect(page.locator("#ctl-alg-rest-1-value")).to_have_value(f"{x0[1]:.3f}")
    assert _curves(tab, config)["posture"] == before["posture"]


def test_a_rest_outside_the_box_is_refused_beside_its_slider(tabs):
    """A rest coordinate typed beyond its range: the page says why beside that slider, in the
    server's words naming the field, and the state keeps its rest."""
    tabs.allow_console("422")
    tab = tabs.open(scene=False)
    page = tab.page
    tab.change(lambda: page.locator("#ctl-algorithms-posture").click())
    response = tab.posting(
        lambda: (
            page.fill("#ctl-alg-rest-2-value", "9"),
            page.press("#ctl-alg-rest-2-value", "Enter"),
        )
    )
    assert response.status == 422
    note = page.locator("#controls .field-error")
    expect(note).to_contain_text(
        "algorithm_parameters.rest[2]: rest x3 must be in [-3.14159, 6.28319]"
    )
    assert "rest" not in tab.snapshot()["state"]["algorithm_parameters"]


def test_the_rest_sliders_of_a_chain_with_limits(tabs):
    """A planar chain with joint limits, started outside them (a link): the rest's sliders and
    x0's span the limits (the start outside them shows in x0's exact box, where another is
    typed); the verdict says what a rest slider moved makes of the default rest outside the
    limits, and moving one is accepted, the untouched coordinates at their nearest limit in
    their boxes."""
    import json
    from urllib.parse import quote

    chain = {
        "name": "planar_chain",
        "joints": "RRR",
        "lengths": [1.0, 1.0, 1.0],
        "limits": [[-1.0, 1.0], [None, 1.2], [-4.0, 4.0]],
        "x0": [1.5, 0.3, 0.3],
    }
    state = {"robot": "planar_chain", "robot_definition": chain, "algorithms": THREE}
    tab = tabs.open("/?state=" + quote(json.dumps(state)), scene=False)
    page = tab.page
    rest = [page.locator(f"#ctl-alg-rest-{i}") for i in range(3)]
    spans = [(r.get_attribute("min"), r.get_attribute("max")) for r in rest]
    assert [(float(a), float(b)) for a, b in spans] == [(-1, 1), (-math.pi, 1.2), (-4, 4)]
    x0 = [page.locator(f"#ctl-x0-{i}") for i in range(3)]
    assert [(float(r.get_attribute("min")), float(r.get_attribute("max"))) for r in x0] == [
        (-1, 1),
        (-math.pi, 1.2),
        (-4, 4),
    ]
    expect(page.locator("#ctl-x0-0-value")).to_have_value("1.500")
    expect(page.locator("#ctl-alg-rest-0-value")).to_have_value("1.500")  # (the default: x0)
    said = page.locator('#verdict p[data-algorithm="posture"].why')
    expect(said).to_contain_text(
        "x_rest = x0 (1.5, 0.3, 0.3), the default, outside the joint limits: moving a rest "
        "slider sets the rest with x1 = 1, the nearest values within them"
    )
    tab.set_slider("#ctl-alg-rest-2", 0.5)
    assert tab.snapshot()["state"]["algorithm_parameters"]["rest"] == [1.0, 0.3, 0.5]
    expect(page.locator("#ctl-alg-rest-0-value")).to_have_value("1.000")
    expect(said).to_contain_text("x_rest = (1, 0.3, 0.5) (set)")
    # A start beyond the limits, past x0's slider, is typed in its exact box and accepted.
    tab.change(
        lambda: (page.fill("#ctl-x0-1-value", "1.8"), page.press("#ctl-x0-1-value", "Enter"))
    )
    assert tab.snapshot()["state"]["x0"] == [1.5, 1.8, 0.3]
