"""A result's second phase (h on a grid when it is expensive, E1, E2 and their sensitivity): its
progress, its cancellation (the result stays, nothing stale is shown as current) and running it
again, in the dashboard and over HTTP."""

from __future__ import annotations

import json
import math
import threading
import time
from dataclasses import replace

import pytest

from jik.app.dashboard import Dashboard, compute, default_state, updated_state
from jik.app.dashboard.analysis import grid_batches, kinematics_and_map
from jik.app.dashboard.functionals import (
    error_functionals,
    sensitivity,
    sensitivity_evaluations,
)
from jik.app.dashboard.runs import Cancelled
from jik.app.dashboard.second_phase import (
    FUNCTIONALS,
    GRID,
    SecondPhase,
    cancelled_message,
)

#: The unicycle over T = 20 s: its second phase (h by characteristics on a grid) is the longest.
LONG = {"robot": "unicycle", "robot_parameters": {"T": 20.0, "q0": [5.0, 0.0, math.pi / 2]}}


def _unicycle_result():
    state = updated_state(default_state("unicycle"), {"task": "target"})
    kin, amap = kinematics_and_map(state)
    return kin, amap, compute(state, with_augmenting=False)


def _phase(kin, amap, result, *, deferred, cancelled=lambda: False):
    seen: list[tuple[float, str]] = []
    phase = SecondPhase(
        kin,
        amap,
        result,
        deferred=deferred,
        cached=None,
        grid_before=None,
        progress=lambda f, what: seen.append((f, what)),
        cancelled=cancelled,
    )
    return phase, seen


def test_progress_counts_the_steps_of_the_grid_then_of_e1_e2():
    """The unicycle: every batch of the grid, then E1 and E2 (its sensitivity is not swept),
    each reported once, the fraction rising to 1; the values are those computed in one go."""
    kin, amap, result = _unicycle_result()
    phase, seen = _phase(kin, amap, result, deferred=True)
    functionals, sens = phase.run()
    steps = grid_batches(result.runs, amap)
    assert phase.steps == {GRID: steps, FUNCTIONALS: 2}
    assert [w for _, w in seen] == [GRID] * steps + [FUNCTIONALS] * 2
    fractions = [f for f, _ in seen]
    assert fractions == sorted(set(fractions)) and fractions[-1] == pytest.approx(1.0)
    assert phase.result.augmenting is not None and sens["kind"] == "unavailable"
    again = error_functionals(phase.result)
    assert json.dumps(functionals) == json.dumps(again)


def test_the_sweep_of_a_map_with_parameters_is_counted_evaluation_by_evaluation():
    """Manipulator 1, (36) with a and b: E1, E2, then 2 (1 + 2 (2 + 11)) values of the sweep."""
    state = default_state("manipulator1")
    kin, amap = kinematics_and_map(state)
    result = compute(state)
    phase, seen = _phase(kin, amap, result, deferred=False)
    _, sens = phase.run()
    assert sensitivity_evaluations(state, amap) == 54
    assert len(seen) == 56 and seen[-1][0] == pytest.approx(1.0)
    assert sens == sensitivity(result, error_functionals(result))
    polls = []
    with pytest.raises(Cancelled):  # (polled before each evaluation: the fourth is not made)
        sensitivity(result, error_functionals(result), lambda: polls.append(1) or len(polls) == 4)
    assert len(polls) == 4


def test_cancelled_during_the_grid_nothing_is_shown_as_computed():
    """Cancelled after two batches of the grid: no grid kept, no E1, E2; the h and E1/E2 panels
    say what was cancelled and how far, with no value of E1 or E2."""
    kin, amap, result = _unicycle_result()
    calls = []
    phase, _ = _phase(
        kin, amap, result, deferred=True, cancelled=lambda: calls.append(1) or len(calls) > 2
    )
    with pytest.raises(Cancelled):
        phase.run()
    assert phase.result.augmenting is None and phase.what == GRID
    message = json.loads(cancelled_message(phase, 7))
    assert message["functionals"] is None and message["sensitivity"] is None
    assert message["cancelled"]["panels"] == ["augmenting", "sensitivity"]
    percent = round(100 * phase.fraction)
    h = message["figures"]["augmenting"]["layout"]
    assert h["title"]["text"].endswith("<br><sup>h on a grid: cancelled</sup>")
    note = f"not computed: cancelled at {percent}% (while computing h on a grid)"
    assert h["annotations"][0]["text"].replace("<br>", " ") == note  # (wrapped to the panel)
    e = message["figures"]["sensitivity"]["layout"]
    assert e["title"]["text"] == "E1, E2 of characteristics: not computed"
    assert "E1 =" not in json.dumps(message) and "E2 =" not in json.dumps(message)


def test_cancelled_after_the_grid_keeps_h_and_says_e1_e2_were_not_computed():
    """Cancelled at E1: h on its grid stays (the whole panel, its contours), its title says E1,
    E2 were not computed."""
    kin, amap, result = _unicycle_result()
    phase = None

    def cancelled():
        return phase is not None and phase.what == FUNCTIONALS

    phase, _ = _phase(kin, amap, result, deferred=True, cancelled=cancelled)
    with pytest.raises(Cancelled):
        phase.run()
    assert phase.result.augmenting is not None
    message = json.loads(cancelled_message(phase, 7))
    h = message["figures"]["augmenting"]
    assert h["data"][0]["type"] == "contour"
    assert "E1, E2: not computed (cancelled)" in h["layout"]["title"]["text"]
    assert message["cancelled"]["what"] == FUNCTIONALS


def test_cancelled_with_h_on_screen_only_its_title_changes():
    """Manipulator 1 (h on its grid with the result): the h panel is retitled, not redrawn."""
    state = default_state("manipulator1")
    kin, amap = kinematics_and_map(state)
    phase, _ = _phase(kin, amap, compute(state), deferred=False, cancelled=lambda: True)
    with pytest.raises(Cancelled):
        phase.run()
    message = json.loads(cancelled_message(phase, 3))
    assert set(message["figures"]) == {"sensitivity"}
    assert "E1, E2: not computed (cancelled)" in message["titles"]["augmenting"]
    assert message["cancelled"]["panels"] == ["augmenting", "sensitivity"]


def _listen(dashboard, on_event=None):
    events, arrived = [], threading.Condition()

    def listener(event):
        if on_event is not None:
            on_event(event)
        with arrived:
            events.append((event.kind, event.generation, json.loads(event.data)))
            arrived.notify_all()

    def wait_for(test, what):
        with arrived:
            assert arrived.wait_for(lambda: any(test(*e) for e in events), 60), what
        return next(e[2] for e in events if test(*e))

    dashboard.subscribe(listener)
    return events, wait_for


def test_a_dashboard_reports_its_second_phase_cancels_it_and_computes_it_again():
    """The unicycle over T = 20 s: "second" progress events; cancel (at its first progress event)
    keeps the result on screen and announces what was not computed; compute again gives what
    an uninterrupted phase gives."""
    dashboard = Dashboard(updated_state(default_state(), LONG))
    first = []

    def cancel_at_first_progress(event):
        body = json.loads(event.data)
        if event.kind == "progress" and body.get("phase") == "second" and not first:
            first.append(body)
            assert dashboard.snapshot()["second_phase"] == "computing"
            assert dashboard.cancel_second_phase(event.generation)

    _, wait_for = _listen(dashboard, cancel_at_first_progress)
    try:
        stopped = wait_for(lambda k, g, d: k == "functionals", "the cancelled phase's event")
        assert first[0]["what"] == GRID and 0 < first[0]["fraction"] < 1
        assert stopped["cancelled"]["what"] == GRID and stopped["functionals"] is None
        snapshot = dashboard.snapshot()
        assert snapshot["second_phase"] == "cancelled" and snapshot["functionals"] is None
        assert snapshot["computed_generation"] == 1 and dashboard.result.augmenting is None
        assert not dashboard.cancel_second_phase(1)  # (nothing runs)
        assert not dashboard.compute_second_phase(2)  # (not the generation on screen)
        assert dashboard.compute_second_phase(1)
        assert not dashboard.compute_second_phase(1)  # (running again already)
        done = wait_for(lambda k, g, d: k == "functionals" and "cancelled" not in d, "E1, E2")
        assert dashboard.snapshot()["second_phase"] == "done"
        assert dashboard.result.augmenting is not None
        kin, amap = kinematics_and_map(dashboard.state)
        plain = SecondPhase(
            kin,
            amap,
            replace(dashboard.result, augmenting=None),
            deferred=True,
            cached=None,
            grid_before=None,
            progress=lambda f, w: None,
            cancelled=lambda: False,
        )
        functionals, _ = plain.run()
        assert json.dumps(done["functionals"]) == json.dumps(functionals)
        assert set(done["figures"]) == {"augmenting", "sensitivity"}
    finally:
        dashboard.stop()


def test_a_newer_change_stops_the_second_phase_without_a_cancelled_event():
    """A change while E1, E2 are computed: that phase ends unannounced (its result is no longer
    the state's), and the new generation's phase runs."""
    dashboard = Dashboard(updated_state(default_state(), LONG))
    changed = []

    def change_at_first_progress(event):
        body = json.loads(event.data)
        if event.kind == "progress" and body.get("phase") == "second" and not changed:
            changed.append(dashboard.update({"gamma": 0.2}))

    events, wait_for = _listen(dashboard, change_at_first_progress)
    try:
        wait_for(lambda k, g, d: k == "functionals" and g == 2, "generation 2's functionals")
        assert not [d for k, g, d in events if k == "functionals" and g == 1]
        assert not dashboard.compute_second_phase(1)
    finally:
        dashboard.stop()


def test_the_routes_cancel_and_compute_again(client, app):
    """``POST .../functionals/cancel`` and ``POST .../functionals``: 202 while it applies, 409
    saying why when not, 422 for a body that names no generation, 404 for no session."""
    created = client.post("/api/sessions", json={"state": LONG}).json()
    session = created["id"]
    url = f"/api/sessions/{session}/functionals"
    deadline = time.monotonic() + 60
    while client.get(f"/api/sessions/{session}").json()["second_phase"] != "computing":
        assert time.monotonic() < deadline, "the second phase never ran"
        time.sleep(0.005)
    r = client.post(f"{url}/cancel", json={"generation": 1})
    assert r.status_code == 202 and r.json() == {"generation": 1}
    dashboard = app.state.sessions.get(session).dashboard
    while dashboard.snapshot()["second_phase"] != "cancelled":
        assert time.monotonic() < deadline, "the cancel never took"
        time.sleep(0.01)
    r = client.post(f"{url}/cancel", json={"generation": 1})
    assert r.status_code == 409
    assert "E1, E2 of generation 1 are not being computed" in r.json()["detail"]
    assert client.post(url, json={"generation": 2}).status_code == 409
    assert client.post(url, json={"generation": "1"}).status_code == 422
    assert client.post(url, json={"generation": 1, "what": 1}).status_code == 422
    assert client.post("/api/sessions/nope/functionals", json={"generation": 1}).status_code == 404
    assert client.post(url, json={"generation": 1}).status_code == 202
    while dashboard.snapshot()["second_phase"] != "done":
        assert time.monotonic() < deadline, "computed again never finished"
        time.sleep(0.01)
    assert client.post(url, json={"generation": 1}).status_code == 409
