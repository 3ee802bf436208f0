"""Choosing the algorithms in the page: a third one (the posture inverse) pressed among the
controls gives three traces in three colours in the drift panel, drawn in those colours, three
keys, its gain as a slider, and the verdict's sentence comparing it with the paper's two."""

from __future__ import annotations

import pytest

from tests.browser.conftest import ALL_COLORS_RGB, TIMEOUT, probe

expect = pytest.importorskip("playwright.sync_api", reason="playwright not installed").expect
# ~15 s: in CI's slow step, to keep the default run under 8 minutes (the default run checks the
# choice through the session API: tests/app/test_dashboard_algorithms.py).
pytestmark = [pytest.mark.browser, pytest.mark.slow]

THREE = ["pseudoinverse", "extended", "posture"]


def test_three_algorithms_chosen_in_the_page(tabs, config):
    tab = tabs.open()
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
