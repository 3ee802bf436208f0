"""The dashboard's server-side state: validation, computation, caching, events, export."""

from __future__ import annotations

import json
import threading
import time

import numpy as np
import pytest

from jik.app.dashboard import (
    ALGORITHMS,
    Cancelled,
    Dashboard,
    compute,
    default_state,
    export_csv,
    export_json,
    runs_key,
    updated_state,
)
from jik.app.dashboard.algorithms import cache_key
from jik.app.dashboard.functionals import functionals_key
from jik.app.dashboard.robots import state_kinematics
from jik.app.dashboard.verdict import verdict
from jik.engine.exceptions import InvalidInputError
from jik.engine.registry import ROBOTS, make_inverse, robot_spec
from jik.engine.repeatability import repeatability
from jik.engine.solver import solve
from tests.helpers import count_picard_sweeps

DLS = ["pseudoinverse", "damped"]


@pytest.mark.parametrize("robot", sorted(ROBOTS))
def test_defaults_come_from_the_registry(robot):
    spec = robot_spec(robot)
    state = default_state(robot)
    assert state.x0 == tuple(spec.default_x0)
    assert state.augmentation == spec.default_augmentation
    assert state.gamma == spec.default_gamma and state.mode == spec.default_mode
    assert updated_state(state, {}) == state


def test_changing_the_robot_starts_from_its_defaults():
    state = updated_state(default_state("manipulator2"), {"gamma": 3.0})
    m1 = updated_state(state, {"robot": "manipulator1", "cycles": 2})
    assert m1.robot == "manipulator1" and m1.cycles == 2
    assert m1.x0 == tuple(robot_spec("manipulator1").default_x0)
    assert m1.gamma == robot_spec("manipulator1").default_gamma


def test_parameters_merge_and_augmentation_resets_its_parameters():
    s = updated_state(default_state("manipulator1"), {"augmentation_parameters": {"a": 0.5}})
    assert s.augmentation_parameters == {"a": 0.5, "b": 1.0}
    s = updated_state(s, {"augmentation": "e1_optimal"})
    assert s.augmentation_parameters == {"C1": 1.0, "C2": 1.0}


@pytest.mark.parametrize(
    ("patch", "message"),
    [
        ({"gamma": 0}, "gamma: Input should be greater than or equal to 0.000001"),
        ({"mode": "discrete", "gamma": 2.5}, "gamma: must be < 2 in discrete mode"),
        ({"x0": [1, 2]}, "x0: must have shape"),
        ({"cycles": 0}, "cycles"),
        ({"robot_parameters": {"l": 99}}, "robot_parameters.l: Input should be less than or"),
        ({"augmentation": "nope"}, "unknown augmentation 'nope'"),
        ({"speed": 1}, "speed: unknown field; remove it"),
        ({"robot": "r2d2"}, "unknown robot 'r2d2'"),
    ],
)
def test_bad_changes_are_refused_with_a_message(patch, message):
    with pytest.raises(InvalidInputError) as err:
        updated_state(default_state("manipulator2"), patch)
    assert message in str(err.value)


def test_closed_path_matches_the_engine_repeatability_test():
    """The leg-by-leg loop gives the same leg ends and drift as engine.repeatability."""
    state = updated_state(default_state("manipulator2"), {"cycles": 2})
    result = compute(state)
    kin = robot_spec("manipulator2").build()
    for a in ("pseudoinverse", "extended"):
        ref = repeatability(make_inverse(kin, a, robot="manipulator2"), state.x0, state.path, 2)
        run = result.runs[a]
        np.testing.assert_allclose(run.leg_end, ref.legs, atol=1e-9)
        np.testing.assert_allclose(run.drift, ref.drift, atol=1e-9)
        assert run.success
    assert result.runs["pseudoinverse"].drift[-1] > 0.5
    assert result.runs["extended"].drift[-1] < 1e-8


def test_later_cycles_start_from_the_previous_cycle_and_agree_with_a_cold_start(monkeypatch):
    """Each leg after the first cycle is guessed by the same leg of the cycle before (see
    engine.picard): the extended inverse, repeatable, then takes one or two sweeps a leg. The
    pseudoinverse's legs are guessed by a chain of all its legs
    (engine.picard_guesses.chain_guesses): one or two sweeps a leg too. Both give the numbers of
    a cold start."""
    from jik.engine import solver as engine_solver

    state = default_state("manipulator2")
    sweeps = count_picard_sweeps(monkeypatch)
    warm = compute(state)
    L = len(warm.targets)
    per_run = {a: sweeps[k * 3 * L : (k + 1) * 3 * L] for k, a in enumerate(ALGORITHMS)}
    first, later = per_run["extended"][:L], per_run["extended"][L:]
    assert sum(first) >= 20 and max(later) <= 2, per_run  # (cold: 13, 2, 13, 2)
    assert max(per_run["pseudoinverse"]) <= 2, per_run  # (cold: 8 to 12 a leg)
    monkeypatch.setattr(engine_solver, "picard_guesses", lambda *args: None)
    cold = compute(state)
    for a in ALGORITHMS:
        np.testing.assert_allclose(warm.runs[a].leg_end, cold.runs[a].leg_end, atol=1e-12)
        np.testing.assert_allclose(warm.runs[a].x, cold.runs[a].x, atol=1e-12)
        np.testing.assert_allclose(warm.runs[a].theta, cold.runs[a].theta, atol=1e-9)
    assert warm.runs["extended"].drift[-1] < 1e-13


def test_gamma_in_continuous_mode_rescales_theta_without_a_new_integration():
    cache: dict = {}
    s1 = updated_state(default_state("manipulator2"), {"task": "target"})
    r1 = compute(s1, cache=cache)
    s2 = updated_state(s1, {"gamma": 4.0})
    r2 = compute(s2, cache=cache)
    assert r2.cached == {"pseudoinverse": True, "extended": True}
    inv = make_inverse(robot_spec("manipulator2").build(), "pseudoinverse")
    direct = solve(inv, s2.x0, s2.target, gamma=4.0)
    run = r2.runs["pseudoinverse"]
    np.testing.assert_allclose(run.theta, direct.trajectory.theta, rtol=1e-12)
    np.testing.assert_allclose(run.x, direct.trajectory.x, atol=1e-12)
    np.testing.assert_allclose(r1.runs["pseudoinverse"].theta, 4.0 * run.theta, rtol=1e-12)


def test_only_the_extended_run_is_recomputed_for_a_new_augmentation_parameter():
    cache: dict = {}
    s = updated_state(default_state("manipulator1"), {"task": "target"})
    compute(s, cache=cache)
    r = compute(updated_state(s, {"augmentation_parameters": {"a": 0.3}}), cache=cache)
    assert r.cached == {"pseudoinverse": True, "extended": False}


def test_a_newer_change_cancels_the_computation():
    calls = []
    with pytest.raises(Cancelled):
        compute(default_state("manipulator2"), cancelled=lambda: calls.append(1) or len(calls) > 1)
    assert len(calls) == 2  # stopped before the second leg


def test_progress_reaches_one():
    fractions = []
    compute(updated_state(default_state("manipulator1"), {"cycles": 1}), progress=fractions.append)
    assert fractions == sorted(fractions) and fractions[-1] == pytest.approx(1.0)


def test_live_dashboard_pushes_state_and_result_events():
    dashboard = Dashboard(updated_state(default_state("manipulator2"), {"task": "target"}))
    events = []
    got_result = threading.Event()

    def listener(event):
        events.append(event)
        if event.kind == "result" and event.generation >= 2:
            got_result.set()

    unsubscribe = dashboard.subscribe(listener)
    generation, state = dashboard.update({"x0": [0.1, 0.0, 1.5]}, source="test")
    assert generation == 2 and state.x0 == (0.1, 0.0, 1.5)
    assert got_result.wait(60)
    unsubscribe()
    dashboard.stop()
    kinds = [e.kind for e in events]
    assert "state" in kinds and "result" in kinds
    result = next(e for e in events if e.kind == "result" and e.generation == 2)
    body = json.loads(result.data)
    assert body["state"]["x0"] == [0.1, 0.0, 1.5]
    # The E1/E2 panel follows in the second phase: the page dims it meanwhile.
    assert set(body["figures"]) == {"task", "joints", "drift", "table", "augmenting", "cspace"}
    assert body["stale"] == ["sensitivity"]
    assert body["summary"]["extended"]["success"]
    assert dashboard.snapshot()["computed_generation"] == 2


def test_a_refused_change_leaves_the_state_alone():
    dashboard = Dashboard()
    before = dashboard.state
    with pytest.raises(InvalidInputError):
        dashboard.update({"gamma": -1})
    assert dashboard.state == before and dashboard.generation == 1


def test_export_has_every_point_of_both_runs():
    result = compute(updated_state(default_state("manipulator1"), {"task": "target"}))
    lines = export_csv(result).strip().split("\n")
    context = [r for r in lines if r.startswith("#")]
    assert context[0].startswith("# jik export of generation 0") and '"task":"target"' in context[2]
    assert context[1].startswith("# jik ") and ", exported " in context[1]
    assert context[3].startswith(
        "# units: theta [dimensionless]; x_1 [m]; x_2 [m]; x_3 [dimensionless]; y_1 [m]; y_2 [m]"
    )
    assert context[4] == "# coordinates: x_1 x1; x_2 x2; x_3 x3; y_1 y1; y_2 y2"
    assert any(r.startswith("# extended leg ends") for r in context)
    assert not [r for r in context if r.rstrip().endswith(":")]  # every line has its value
    assert "# pseudoinverse h changed by: not recorded (this run has no h)" in context
    rows = lines[len(context) :]
    assert rows[0] == "algorithm,cycle,leg,theta,x_1,x_2,x_3,y_1,y_2,error,h"
    n = sum(len(r.theta) for r in result.runs.values())
    assert len(rows) == 1 + n
    body = export_json(result)
    assert len(body["runs"]["extended"]["x"]) == len(result.runs["extended"].x)
    last = rows[-1].split(",")
    assert last[0] == "extended" and float(last[9]) < 1e-9


def test_an_export_names_its_columns_as_the_engine_does():
    """The export's point columns are the engine's trajectory columns (``x_k``, ``y_k``, not
    the robot's joint and task names), its units keyed by them, cycle and leg from 1 in the CSV
    and the JSON, and the JSON's leg ends are "legs" as in the engine's results."""
    state = updated_state(default_state("manipulator2"), {"cycles": 2})
    result = compute(state)
    header, *rows = [r for r in export_csv(result).splitlines() if not r.startswith("#")]
    inverse = make_inverse(state_kinematics(state), "extended", state.augmentation)
    trajectory = solve(inverse, state.x0, result.targets[0], record=True).trajectory
    engine = trajectory.columns()
    assert header.split(",") == ["algorithm", "cycle", "leg", *engine]
    body = export_json(result)
    assert list(body["units"]) == list(engine)
    assert body["coordinates"] == {
        f"{v}_{k}": f"{v}{k}" for v, n in (("x", 3), ("y", 2)) for k in range(1, n + 1)
    }
    run, legs = body["runs"]["pseudoinverse"], len(result.targets)
    assert sorted(set(run["cycle"])) == [1, 2]
    assert sorted(set(run["leg"])) == list(range(1, legs + 1))
    first = [r.split(",") for r in rows if r.startswith("pseudoinverse,")]
    assert [int(r[1]) for r in first] == run["cycle"]
    assert [int(r[2]) for r in first] == run["leg"]
    rep = repeatability(inverse, state.x0, result.targets, cycles=1)
    assert set(trajectory.as_dict()) <= set(run)  # (theta, x, y, error, h)
    assert {"legs", "drift"} <= set(rep.as_dict()) & set(run) and "leg_end" not in run


def test_a_gamma_change_redraws_only_the_panels_with_theta_on_an_axis():
    """Continuous mode: x(theta) does not depend on gamma, so only the joint plot changes."""
    dashboard = Dashboard(updated_state(default_state("manipulator2"), {"cycles": 1}))
    results = {}
    done = threading.Event()

    def listener(event):
        if event.kind == "result":
            results[event.generation] = json.loads(event.data)
            if event.generation >= 2:
                done.set()

    dashboard.subscribe(listener)
    assert dashboard.wait(1, timeout=60)
    dashboard.update({"gamma": 2.5})
    assert done.wait(60)
    dashboard.stop()
    first, second = results[1], results[2]
    changed = {k for k in first["digests"] if first["digests"][k] != second["digests"][k]}
    assert changed == {"joints"}
    theta1 = second["summary"]["pseudoinverse"]["points"]
    assert theta1 == first["summary"]["pseudoinverse"]["points"]
    assert second["summary"]["extended"]["cached"] is True


def test_slow_listeners_come_last_and_functionals_only_retitle_the_h_panel():
    """The scene subscribes with last=True: the page's events are queued before it draws.
    With h already on screen, the E1/E2 event carries the h panel's new title, not a figure."""
    dashboard = Dashboard(updated_state(default_state("manipulator2"), {"cycles": 1}))
    order, functionals = [], threading.Event()
    messages = {}

    def slow(event):
        order.append(("slow", event.kind, event.generation))

    def fast(event):
        order.append(("fast", event.kind, event.generation))
        if event.kind == "functionals" and event.generation == 2:
            messages[event.generation] = json.loads(event.data)
            functionals.set()

    dashboard.subscribe(slow, last=True)
    dashboard.subscribe(fast)
    dashboard.update({"x0": [0.45, 0.0, 1.5]})
    assert functionals.wait(60)
    dashboard.stop()
    assert [who for who, kind, g in order if kind == "result" and g == 2] == ["fast", "slow"]
    body = messages[2]
    assert set(body["figures"]) == {"sensitivity"}  # the h panel is retitled, not redrawn
    assert "E1 = " in body["titles"]["augmenting"]
    assert body["sensitivity"]["kind"] == "alternatives"  # paper_cubic has no parameters


def test_functionals_are_keyed_by_the_map_and_the_variables_held_fixed():
    """E1, E2 on Manipulator 2's design region (x2, x3) hold x1 at its start value, but neither
    J nor h(x2, x3) depends on x1: x0, the path, the cycles and gamma leave them alone; l and
    the map do not."""
    m2 = default_state("manipulator2")
    key = functionals_key(m2)
    for patch in (
        {"x0": [0.0, 0.4, 1.2]},
        {"x0": [0.3, 0.0, 1.5]},
        {"cycles": 5},
        {"gamma": 3.0},
        {"path": [[1.0, 1.0], [0.5, 2.0]]},
    ):
        assert functionals_key(updated_state(m2, patch)) == key, patch
    for patch in ({"robot_parameters": {"l": 1.5}}, {"augmentation": "e2_synthesized"}):
        assert functionals_key(updated_state(m2, patch)) != key, patch
    # Manipulator 1's region covers every variable: no start value matters.
    m1 = default_state("manipulator1")
    assert functionals_key(updated_state(m1, {"x0": [0.1, 0.2, 0.3]})) == functionals_key(m1)
    assert functionals_key(
        updated_state(m1, {"augmentation_parameters": {"a": 0.5}})
    ) != functionals_key(m1)


def test_the_h_panel_names_only_the_fixed_variables_h_depends_on():
    """Manipulator 2's h(x2, x3) is drawn over (x2, x3): its title does not name x1, so a
    change of x1 leaves the title (and the E1/E2 in it) as they are."""
    from jik.app.dashboard.map_figures import augmenting_title

    state = default_state("manipulator2")
    a = compute(state)
    b = compute(updated_state(state, {"x0": [0.45, 0.0, state.x0[2]]}))
    assert "x1 =" not in augmenting_title(a) and augmenting_title(a) == augmenting_title(b)


def test_runs_key_ignores_gamma_only_in_continuous_mode():
    state = default_state("manipulator2")
    assert runs_key(updated_state(state, {"gamma": 3.0})) == runs_key(state)
    discrete = updated_state(state, {"mode": "discrete", "gamma": 0.5})
    assert runs_key(updated_state(discrete, {"gamma": 0.8})) != runs_key(discrete)


def test_known_functionals_are_drawn_with_the_first_result():
    """A change of the cycles keeps E1, E2: the result carries the E1/E2 panel and the h
    panel's title at once, nothing is dimmed, and the functionals event that follows carries
    no figure (only the h panel's title, for pages that connect later)."""
    dashboard = Dashboard(updated_state(default_state("manipulator2"), {"cycles": 1}))
    events, second = [], threading.Event()

    def listener(event):
        events.append((event.kind, event.generation, event.data))
        if event.kind == "functionals" and event.generation == 1:
            second.set()

    dashboard.subscribe(listener)
    assert second.wait(60)
    second.clear()
    generation, _ = dashboard.update({"cycles": 2})
    assert dashboard.wait(generation, timeout=60)
    deadline = time.monotonic() + 60
    while not any(k == "functionals" and g == generation for k, g, _ in events):
        assert time.monotonic() < deadline, "no functionals event for the change"
        time.sleep(0.02)
    dashboard.stop()
    result = next(json.loads(d) for k, g, d in events if k == "result" and g == generation)
    assert result["stale"] == []
    assert "sensitivity" in result["figures"]
    assert "E1 = " in result["figures"]["augmenting"]["layout"]["title"]["text"]
    (after,) = [json.loads(d) for k, g, d in events if k == "functionals" and g == generation]
    assert after["figures"] == {}
    assert (
        after["titles"]["augmenting"] == result["figures"]["augmenting"]["layout"]["title"]["text"]
    )
    assert dashboard.functionals is not None and dashboard.functionals["E2"] is not None


def test_offloaded_computation_is_the_same_and_can_be_cancelled():
    """A worker of the server's compute pool (the REST API's) computes the pseudoinverse exactly
    as the thread does; a newer generation gives the run up; if the worker dies, the run is
    redone here and a new worker serves the next."""
    from jik.app.compute.pool import pool_in_thread
    from jik.app.compute.settings import Settings
    from jik.app.dashboard import OffloadLane

    with pool_in_thread(Settings(workers=1, timeout=120.0)) as pool:
        offload = OffloadLane(pool)
        for robot in ("manipulator1", "manipulator2"):
            state = default_state(robot)
            here, there = compute(state), compute(state, 7, offload=offload)
            for a in here.runs:
                np.testing.assert_array_equal(here.runs[a].x, there.runs[a].x)
                np.testing.assert_array_equal(here.runs[a].theta, there.runs[a].theta)
                assert here.runs[a].message == there.runs[a].message
            assert there.cached == {"pseudoinverse": False, "extended": False}
        # More cycles go on from the cached run, over there too.
        cache: dict = {}
        base = default_state("manipulator2")
        compute(updated_state(base, {"cycles": 2}), 7, cache=cache, offload=offload)
        grown = compute(updated_state(base, {"cycles": 4}), 7, cache=cache, offload=offload)
        fresh = compute(updated_state(base, {"cycles": 4}))
        for a in grown.runs:
            np.testing.assert_array_equal(grown.runs[a].x, fresh.runs[a].x)
            np.testing.assert_array_equal(grown.runs[a].leg, fresh.runs[a].leg)
        # A newer generation gives up the older run.
        state = updated_state(default_state("manipulator2"), {"cycles": 5})
        future = offload.submit(state, "pseudoinverse", np.asarray(state.path), 5, 8)
        offload.newest(9)
        with pytest.raises(Cancelled):
            offload.result(future, lambda: pytest.fail("no fallback for a cancelled run"))
        # A worker that dies: the run is computed here, and the next goes to a new worker.
        for worker in list(pool._workers):
            worker.process.kill()
        again = compute(state, 10, offload=offload)
        np.testing.assert_array_equal(
            again.runs["pseudoinverse"].x, compute(state).runs["pseudoinverse"].x
        )
        assert compute(state, 11, offload=offload).runs["pseudoinverse"].success


def test_compute_workers_leave_with_a_killed_server(tmp_path):
    """A server that is killed (no shutdown) does not leave its compute workers behind."""
    import os
    import signal
    import subprocess
    import sys
    import time
    from pathlib import Path

    script = (
        "import time\n"
        "from jik.app.compute.pool import pool_in_thread\n"
        "from jik.app.compute.settings import Settings\n"
        "from jik.app.dashboard import OffloadLane, compute, default_state\n"
        "with pool_in_thread(Settings(workers=1)) as pool:\n"
        "    compute(default_state('manipulator2'), offload=OffloadLane(pool))\n"
        "    print(*(w.process.pid for w in pool._workers), flush=True)\n"
        "    time.sleep(60)\n"
    )
    path = tmp_path / "server.py"
    path.write_text(script)
    root = Path(__file__).resolve().parents[2]
    proc = subprocess.Popen(
        [sys.executable, str(path)],
        stdout=subprocess.PIPE,
        text=True,
        cwd=root,
        env={**os.environ, "PYTHONPATH": str(root)},
    )
    try:
        child = int(proc.stdout.readline().split()[0])
        os.kill(child, 0)  # alive
        proc.send_signal(signal.SIGKILL)
        proc.wait(10)
        deadline = time.monotonic() + 10
        while time.monotonic() < deadline:
            try:
                os.kill(child, 0)
            except ProcessLookupError:
                break
            try:  # reap it if it became our zombie
                os.waitpid(child, os.WNOHANG)
            except ChildProcessError:
                pass
            time.sleep(0.05)
        else:
            os.kill(child, signal.SIGKILL)
            pytest.fail("the compute worker outlived its killed server")
    finally:
        proc.kill()


def test_an_idle_dashboard_solves_the_other_manipulator_ahead():
    """A robot switch starts from that robot's defaults: solved while the dashboard is idle,
    the switch reuses both runs, the same as computed on the switch."""
    dashboard = Dashboard(updated_state(default_state("manipulator2"), {"cycles": 1}))
    other = default_state("manipulator1")
    assert dashboard.wait(1, 60)
    deadline = time.monotonic() + 60
    while not all(cache_key(other, a) in dashboard._cache for a in ALGORITHMS):
        assert time.monotonic() < deadline, "manipulator1 was not solved ahead"
        time.sleep(0.05)
    generation, _ = dashboard.update({"robot": "manipulator1"})
    assert dashboard.wait(generation, 60)
    result = dashboard.result
    dashboard.stop()
    assert result is not None and result.cached == {a: True for a in ALGORITHMS}
    fresh = compute(other)
    for a in ALGORITHMS:
        np.testing.assert_array_equal(result.runs[a].x, fresh.runs[a].x)


def test_the_figures_solved_ahead_are_those_of_the_switch():
    """An ``ahead`` event carries the other robot's panels as the switch will send them (the
    page draws them off screen and shows them on the switch when the digests agree); it is
    not sent again for a change of the same robot, and again after a switch back."""
    dashboard = Dashboard(updated_state(default_state("manipulator2"), {"cycles": 1}))
    events: list = []
    dashboard.subscribe(events.append)

    def announced(robot: str, since: int) -> list[dict]:
        return [
            json.loads(e.data)
            for e in events[since:]
            if e.kind == "ahead" and json.loads(e.data)["robot"] == robot
        ]

    def settle(generation: int, robot: str, since: int) -> dict:
        assert dashboard.wait(generation, 60)
        deadline = time.monotonic() + 60
        while not announced(robot, since):
            assert time.monotonic() < deadline, f"{robot} was not announced"
            time.sleep(0.05)
        return announced(robot, since)[-1]

    try:
        ahead = settle(1, "manipulator1", 0)
        assert set(ahead["digests"]) >= {"task", "joints", "drift", "augmenting"}
        n = len(events)
        generation, _ = dashboard.update({"gamma": 2.0})  # (the same robot: not announced again)
        assert dashboard.wait(generation, 60)
        time.sleep(0.5)
        assert not announced("manipulator1", n)
        generation, _ = dashboard.update({"robot": "manipulator1"})
        assert dashboard.wait(generation, 60)
        result = next(json.loads(e.data) for e in reversed(events) if e.kind == "result")
        assert result["state"]["robot"] == "manipulator1"
        for key, digest in ahead["digests"].items():
            assert result["digests"][key] == digest, key
            assert result["figures"][key] == ahead["figures"][key], key
        n = len(events)
        back = settle(generation, "manipulator2", n)  # (the other one now)
        assert back["figures"]["task"]["data"]
        generation, _ = dashboard.update({"robot": "manipulator2"})
        again = settle(generation, "manipulator1", len(events))  # (shown: announced again)
        assert again["digests"] == ahead["digests"]
    finally:
        dashboard.stop()


def test_solving_ahead_stops_for_a_change():
    dashboard = Dashboard(updated_state(default_state("manipulator2"), {"cycles": 1}))
    dashboard._generation = 2  # (not started) a change came after generation 1
    dashboard._prefetch(1)
    assert not dashboard._cache
    dashboard._prefetch(2)  # idle at the newest generation
    other = default_state("manipulator1")
    assert {cache_key(other, a) for a in ALGORITHMS} == set(dashboard._cache)


@pytest.mark.parametrize("mode", ["continuous", "discrete"])
def test_another_number_of_cycles_reuses_the_cycles_already_solved(mode):
    """More cycles go on from the end of a cached run, fewer are its first cycles: the same
    numbers as a run from the start (a leg depends only on its start and its target)."""
    state = updated_state(default_state("manipulator2"), {"mode": mode, "gamma": 0.5})
    cache: dict = {}
    compute(updated_state(state, {"cycles": 3}), cache=cache)
    legs = []
    grown = compute(
        updated_state(state, {"cycles": 5}),
        cache=cache,
        progress=lambda f: legs.append(f),
    )
    shrunk = compute(updated_state(state, {"cycles": 2}), cache=cache)
    assert shrunk.cached == {a: True for a in ALGORITHMS}
    L = len(grown.targets)  # 3 of 5 cycles known: the progress starts after them
    assert legs[0] == pytest.approx((2 * 3 * L + 1) / (2 * 5 * L))
    for result, cycles in ((grown, 5), (shrunk, 2)):
        fresh = compute(updated_state(state, {"cycles": cycles}))
        for a in ALGORITHMS:
            got, want = result.runs[a], fresh.runs[a]
            for name in ("theta", "x", "y", "error", "leg", "leg_end", "drift"):
                np.testing.assert_array_equal(getattr(got, name), getattr(want, name), name)
            if want.h is not None:
                np.testing.assert_array_equal(got.h, want.h)
            assert (got.success, got.message) == (want.success, want.message)
            assert got.settings is not None and want.settings is not None
            assert got.settings.difference(want.settings) is None  # (the engine checked it)


def test_a_pose_target_beyond_a_half_turn_is_refused_at_the_target():
    """A Panda target whose rotation vector is longer than pi is refused as the state changes
    (field target, the engine's reason), not run until the time limit."""
    pytest.importorskip("yourdfpy")
    state = updated_state(default_state("panda"), {"task": "target"})
    target = list(state.target[:3]) + [3.0, 0.0, 1.0]
    with pytest.raises(InvalidInputError) as err:
        updated_state(state, {"target": target})
    assert err.value.field == "target"
    assert "rotation coordinates (rx, ry, rz) have length 3.16228 > pi" in str(err.value)


def test_a_single_target_s_messages_name_no_cycle_or_leg():
    """A target task runs one leg: its failure and its damped sentence say no 'cycle 1, leg 1'
    (a closed path's say which leg)."""
    patch = {"task": "target", "target": [9.0, 9.0], "max_iterations": 10}
    result = compute(updated_state(default_state("manipulator2"), patch | {"algorithms": DLS}))
    said = [result.runs[a].message for a in DLS] + [f["text"] for f in verdict(result)]
    assert all("did not converge within 10" in m for m in said[:2])
    assert not [s for s in said if "leg" in s.replace("per leg", "")]
    assert "task error at its end 9.29" in said[-1]


def test_other_configuration_space_axes_redraw_their_panel():
    """A change of the configuration-space axes alone keeps the runs (and, in continuous mode,
    the panels that do not depend on gamma) but draws the configuration space anew on the
    axes chosen: it was reused, drawn on the axes before."""
    chain = {"name": "planar_chain", "joints": "RRRR", "lengths": [1.0, 0.8, 0.6, 0.4]}
    state = updated_state(default_state(), {"robot": "planar_chain", "robot_definition": chain})
    dashboard, titles, done = Dashboard(state), {}, threading.Event()

    def listener(event):
        if event.kind == "result":
            titles[event.generation] = json.loads(event.data)["figures"]["cspace"]["layout"]
        if event.kind == "result" and event.generation == 2:
            done.set()

    dashboard.subscribe(listener)
    try:
        assert dashboard.wait(1, timeout=60)
        dashboard.update({"cspace_axes": "013"})
        assert done.wait(60)
    finally:
        dashboard.stop()
    assert titles[2]["title"]["text"].startswith("Configuration space (x1, x2, x4)")
    assert titles[2]["scene2"]["zaxis"]["title"]["text"] == "x4"


def test_an_export_of_a_vector_of_maps_has_a_column_per_map():
    """A planar 4R chain (p - r = 2, two formula maps): the CSV has the columns h_1 and h_2, a
    number in each cell of the extended run's rows and empty ones in the pseudoinverse's, and
    the units (the CSV's line, the JSON's keys) name those columns."""
    chain = {"name": "planar_chain", "joints": "RRRR", "lengths": [1.0, 1.0, 1.0, 1.0]}
    state = updated_state(default_state(), {"robot": "planar_chain", "robot_definition": chain})
    result = compute(updated_state(state, {"cycles": 1}))
    lines = export_csv(result).splitlines()
    header, *rows = [r.split(",") for r in lines if not r.startswith("#")]
    assert header[-3:] == ["error", "h_1", "h_2"]
    assert {len(r) for r in rows} == {len(header)}
    extended = np.array([r[-2:] for r in rows if r[0] == "extended"], dtype=float)
    np.testing.assert_allclose(extended, result.runs["extended"].h, atol=1e-12)
    assert {tuple(r[-2:]) for r in rows if r[0] == "pseudoinverse"} == {("", "")}
    units = next(r for r in lines if r.startswith("# units: "))
    assert units.endswith(
        "h_1 [the unit of the map's formula]; h_2 [the unit of the map's formula]"
    )
    assert list(export_json(result)["units"])[-3:] == ["error", "h_1", "h_2"]
