"""What the page writes about a result: the engine's message where a run fails (the unicycle
from q0 = B), and a verdict computed from the numbers (repeatable or not, by how much, why)."""

from __future__ import annotations

import json
import math
import re
from urllib.parse import quote

import pytest

expect = pytest.importorskip("playwright.sync_api", reason="playwright not installed").expect
pytestmark = pytest.mark.browser


# (CI's slow step: among the longest browser checks; the default run stays under 8 minutes)
@pytest.mark.slow
def test_unicycle_from_b_shows_the_engines_message(tabs):
    """Unicycle, q0 = B: the extended Jacobian's h is undefined after a few iterations. The
    page shows that message in the verdict, says the result is the current one, and no
    "internal error"; a new viewer of the same state sees the same (not "computing…")."""
    tab = tabs.open()
    tab.select("#ctl-robot", "unicycle")
    generation = tab.change(lambda: tab.page.click("#ctl-preset-q0-B"))
    verdict = tab.page.locator("#verdict")
    expect(verdict).to_contain_text("extended Jacobian J^E# stopped")
    expect(verdict).to_contain_text("is undefined")
    # Why, and that this is the paper's run (Figs. 13-14) with its erratum.
    why = verdict.locator("p.why.e")
    expect(why).to_contain_text("characteristic (28)")
    expect(why).to_contain_text("took lambda10 from 0.0659 to -0.0777, across lambda10 = 0")
    expect(why).to_contain_text("out of the domain of the map's foliation")
    note = verdict.locator("p.note.e")
    expect(note).to_contain_text("the paper's run from q0 = B (sec. 6.2, Figs. 13")
    expect(note).to_contain_text("docs/paper-errata.md")
    assert "h was not conserved" not in (verdict.text_content() or "")
    expect(tab.page.locator("#about")).to_contain_text("from B the discrete extended run leaves")
    status = tab.page.locator("#status-text")
    expect(status).to_have_text(f"up to date (generation {generation})")
    assert "internal error" not in (verdict.text_content() or "")
    summary = tab.snapshot()["summary"]
    assert not summary["extended"]["success"]
    assert summary["extended"]["message"] in (verdict.text_content() or "")
    tab.screenshots("unicycle-b")

    state = tab.url_state()
    viewer = tabs.open("/?state=" + quote(json.dumps(state)))
    expect(viewer.page.locator("#verdict")).to_contain_text("is undefined")
    assert viewer.status().startswith("up to date")


def _extended_drift(tab) -> float:
    return tab.snapshot()["summary"]["extended"]["drift"][-1]


def test_the_verdict_follows_the_numbers(tabs):
    """Manipulator 2: continuous, the extended Jacobian is repeatable; discrete at gamma = 1
    it drifts and the page says so with its drift and h's change, and why; at gamma near 2 the
    page says the iteration is near its limit."""
    tab = tabs.open()
    verdict = tab.page.locator("#verdict")
    expect(verdict).to_contain_text("extended Jacobian J^E#: repeatable")

    tab.select("#ctl-mode", "discrete")
    drift = _extended_drift(tab)
    h = tab.snapshot()["summary"]["extended"]["h_change"]
    expect(verdict.locator("p.e.finding")).to_contain_text("not repeatable")
    expect(verdict).to_contain_text(f"‖x − x0‖ = {drift:.3g}")
    expect(verdict).to_contain_text(f"h was not conserved: it changed by {h:.3g}")
    expect(verdict).to_contain_text("keeps h only approximately")
    assert "closed task paths give closed joint paths" not in (verdict.text_content() or "")
    tab.screenshots("verdict-discrete")

    tab.set_slider("#ctl-gamma", math.log10(1.89))
    gamma = tab.snapshot()["state"]["gamma"]
    assert gamma == pytest.approx(1.89, abs=0.02)
    expect(verdict).to_contain_text(re.compile(r"γ = 1\.\d+ is near 2"))
    expect(verdict).to_contain_text(f"‖x − x0‖ = {_extended_drift(tab):.3g}")

    # the tolerance, a select of numbers, is sent as a number
    tab.select("#ctl-tolerance", "1e-6")
    assert tab.snapshot()["state"]["tolerance"] == 1e-6


def test_an_unreachable_target_is_named_by_the_reach(tabs):
    """A planar 3R arm (reach 2.4) asked for a target 5 from its base: the verdict says the
    target is out of reach, with the distance and the reach, not "a singularity or"."""
    arm = {"name": "planar_chain", "joints": "RRR", "lengths": [1.0, 0.8, 0.6]}
    state = {
        "robot": "planar_chain",
        "robot_definition": arm,
        "task": "target",
        "target": [5.0, 0.0],
    }
    tab = tabs.open("/?state=" + quote(json.dumps(state)), scene=False)
    tab.wait_settled(lambda s: s["state"]["robot"] == "planar_chain", "the arm's result")
    verdict = tab.page.locator("#verdict")
    expect(verdict.locator("p.failure.p")).to_contain_text(
        "the target is out of reach: it is 5 from the base, beyond the arm's reach 2.4"
    )
    assert "or the target is unreachable" not in (verdict.text_content() or "")
