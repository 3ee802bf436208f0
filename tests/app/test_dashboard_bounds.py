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


def test_a_long_unicycle_run_computes_only_the_platform_paths_it_draws():
    """A discrete run of thousands of iterations: the task panel and the export draw a few
    platform paths q(t), each as Unicycle.path gives it; computing all of them had taken the
    server gigabytes (0.4 MB and 1.4 ms an iteration)."""
    import numpy as np

    from jik.app.dashboard.export import export_file
    from jik.app.dashboard.figures import figure_specs
    from jik.app.dashboard.results import compute
    from jik.app.dashboard.robots import state_kinematics
    from jik.app.dashboard.runs import platform_time

    state = updated_state(
        default_state(),
        {
            "robot": "unicycle",
            "gamma": 0.002,
            "max_iterations": 20_000,
            "algorithms": ["pseudoinverse"],
        },
    )
    result = compute(state)
    run = result.runs["pseudoinverse"]
    assert len(run.platform) > 5000 and run.platform.shape[1:] == (96, 3)
    figure_specs(result, None, {"task"})
    export_file(result, "json")
    assert 0 < len(run.platform._kept) <= 20
    kin = state_kinematics(state)
    np.testing.assert_array_equal(run.platform[-1], kin.path(run.x[-1], platform_time(kin)))
    np.testing.assert_array_equal(
        run.platform[3, :, 0], kin.path(run.x[3], platform_time(kin))[:, 0]
    )


def _synthesis_state(degree: int):
    definition = {
        "name": "planar_chain",
        "joints": "RRR",
        "lengths": [1, 1, 1],
        "augmentations": [
            {
                "name": "e2_synthesized",
                "degree": degree,
                "region": {"x1": [0, 1], "x2": [0.2, 1], "x3": [0.2, 1]},
            }
        ],
    }
    state = updated_state(
        default_state(), {"robot": "planar_chain", "robot_definition": definition}
    )
    return updated_state(state, {"augmentation": "e2_synthesized"})


def test_a_map_synthesis_is_made_in_a_worker_within_its_memory_limit(monkeypatch):
    """With the server's pool, a definition's E2 synthesis is made in a compute worker and kept
    in the server's process, which synthesizes nothing itself; one too large for a worker's
    memory (512 MB here: a three-variable map of degree 16, whose Ritz matrix alone is 0.2 GB,
    takes more with its solve) is refused naming ``augmentation``."""
    import jik.engine.robot_synthesis as synthesis
    from jik.app.compute.pool import pool_in_thread
    from jik.app.compute.settings import Settings
    from jik.app.dashboard.analysis import state_maps

    def here(*args, **kwargs):
        raise AssertionError("a map was synthesized in the server's process")

    monkeypatch.setattr(synthesis, "synthesize_e2", here)
    with pool_in_thread(Settings(workers=1, timeout=60, worker_memory=512)) as pool:
        for degree, kind in ((4, "result"), (16, "error")):
            events: list = []
            dashboard = Dashboard(_synthesis_state(degree), pool=pool)
            dashboard.subscribe(events.append)
            dashboard.start()
            try:
                assert dashboard.wait(1, timeout=120)
                (done,) = [e for e in events if e.kind in ("result", "error")]
                assert done.kind == kind, done.data
            finally:
                dashboard.stop()
        message = json.loads(done.data)["message"]
        assert message.startswith("augmentation: the computation ran out of memory")
        assert "a lower degree or a smaller region" in message
    # The kept map is the worker's: the server's state builds it without synthesizing.
    _, amap = state_maps(_synthesis_state(4))
    assert amap.name == "e2_synthesized"
