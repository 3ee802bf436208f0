"""A dashboard's computation is bounded like a request's: it stops at the server's time limit
(with an error the page shows) and when its session ends (deleted, expired or evicted)."""

from __future__ import annotations

import json
import math
import threading

from jik.app.dashboard import Dashboard
from jik.app.dashboard.model import default_state, updated_state

#: About 170,000 discrete iterations a leg, 101 legs a cycle: half an hour on one core.
SLOW = {
    "robot": "manipulator1",
    "mode": "discrete",
    "gamma": 1.3e-4,
    "x0": [1.05, 0.25, 1.0],
    "max_iterations": 200_000,
    "cycles": 2,
    "task": "path",
    "path": [
        [0.8 + 0.3 * math.cos(2 * math.pi * i / 100), 1.3 + 0.3 * math.sin(2 * math.pi * i / 100)]
        for i in range(100)
    ],
    "algorithms": ["pseudoinverse"],
}


def _slow_dashboard(**options) -> tuple[Dashboard, list]:
    events: list = []
    dashboard = Dashboard(updated_state(default_state(), SLOW), **options)
    dashboard.subscribe(events.append)
    dashboard.start()
    return dashboard, events


def test_a_computation_past_the_time_limit_stops_with_an_error():
    dashboard, events = _slow_dashboard(time_limit=1.0)
    try:
        assert dashboard.wait(1, timeout=60)
        (error,) = [e for e in events if e.kind == "error"]
        message = json.loads(error.data)["message"]
        assert "exceeded the time limit of 1 s and was stopped" in message
        assert "max_iterations" in message
        assert not [e for e in events if e.kind == "result"]
    finally:
        dashboard.stop()


def test_ending_a_session_stops_its_computation():
    """(A deleted session's run had gone on for half an hour, holding a computation slot.)"""
    dashboard, events = _slow_dashboard()
    started = threading.Event()
    dashboard.subscribe(lambda e: e.kind == "progress" and started.set())
    assert started.wait(60)
    thread = dashboard._thread
    dashboard.stop()
    assert thread is not None
    thread.join(30)
    assert not thread.is_alive()
    assert [e.kind for e in events][-1] == "closed"
