"""What the dashboard writes about a result (app/dashboard/verdict.py), and what it says when a
generation fails: NaN never reaches JSON, the error names the result still on screen."""

from __future__ import annotations

import dataclasses
import json
import math

import numpy as np

from jik.app.dashboard import Dashboard, compute, default_state, updated_state
from jik.app.dashboard import session as session_module
from jik.app.dashboard.messages import summary, to_json
from jik.app.dashboard.verdict import verdict
from jik.engine.exceptions import JikError

POSE_B = [-5.0, 5.0, math.pi / 2]


def texts(result) -> str:
    return " ".join(s["text"] for s in verdict(result))


def test_nan_and_inf_become_null_in_json():
    """to_json is the one boundary where results become JSON: NaN and inf are null there,
    in plain floats and in arrays."""
    data = {"a": float("nan"), "b": [1.0, float("inf")], "c": np.array([0.5, np.nan])}
    assert json.loads(to_json(data)) == {"a": None, "b": [1.0, None], "c": [0.5, None]}


def test_unicycle_from_b_reports_the_engines_message():
    """Unicycle from q0 = B (discrete): h is undefined after a few iterations; the summary and
    its JSON carry the engine's message, not a JSON error."""
    state = updated_state(default_state("unicycle"), {"robot_parameters.q0": POSE_B})
    result = compute(state)
    data = json.loads(to_json(summary(result)))
    assert not data["extended"]["success"]
    assert "undefined" in data["extended"]["message"]
    assert "undefined" in texts(result) and "stopped" in texts(result)
    # Why, and that this is the paper's run B with its erratum (none of it where the run stopped
    # where it started, below).
    assert "iteration 3 took lambda10 from 0.0659 to -0.0777, across lambda10 = 0" in texts(result)
    assert "run from q0 = B (sec. 6.2, Figs. 13 (J^P#) and 14 (J^E#))" in texts(result)
    assert "docs/paper-errata.md" in texts(result)
    # The why follows the engine's status of the run ("undefined": h undefined where it stopped),
    # not its words: a run stopped where [J; dh] is singular gets none of it.
    run = result.runs["extended"]
    assert run.status == "undefined"
    singular = dataclasses.replace(run, status="singular")
    text = texts(dataclasses.replace(result, runs={**result.runs, "extended": singular}))
    assert "characteristic (28)" not in text and "docs/paper-errata.md" not in text
    # A run stopped where it started has no "why" (it said "h changed by only 0 along its
    # run,."): its h, constant, says nothing about conservation.
    still = dataclasses.replace(run, h=np.zeros_like(run.error))
    text = texts(dataclasses.replace(result, runs={**result.runs, "extended": still}))
    assert "stopped" in text and "Why: J^E#" not in text and ",." not in text


def test_verdict_says_when_the_extended_jacobian_is_not_repeatable():
    """Manipulator 2, discrete mode, gamma = 1: the extended Jacobian drifts and h changes; the
    verdict says both, with the numbers, and why (the discrete step)."""
    state = updated_state(default_state("manipulator2"), {"mode": "discrete", "gamma": 1.0})
    result = compute(state)
    text = texts(result)
    drift = result.runs["extended"].drift[-1]
    assert drift > 1e-2
    assert "extended Jacobian J^E#: not repeatable" in text
    assert f"{drift:.3g}" in text and "h was not conserved" in text
    assert "only approximately" in text and "closed joint paths" not in text


def test_verdict_names_gamma_near_two():
    state = updated_state(default_state("manipulator2"), {"mode": "discrete", "gamma": 1.89})
    assert "γ = 1.89 is near 2" in texts(compute(state))


def test_verdict_continuous_is_repeatable():
    text = texts(compute(default_state("manipulator2")))
    assert "extended Jacobian J^E#: repeatable" in text
    assert "pseudoinverse J^P#: not repeatable" in text


def test_a_failed_generation_names_the_result_on_screen(monkeypatch):
    """A generation whose computation raises: the snapshot and a new subscriber get its
    message and the generation (and state) of the result that stays on screen."""
    dash = Dashboard()
    try:
        assert dash.wait(1, timeout=120)
        real = session_module.compute

        def failing(state, *args, **kwargs):
            if state.gamma == 2.5:
                raise JikError("the start is singular")
            return real(state, *args, **kwargs)

        monkeypatch.setattr(session_module, "compute", failing)
        generation, _ = dash.update({"gamma": 2.5})
        assert dash.wait(generation, timeout=120)
        snap = dash.snapshot()
        assert snap["error"]["message"] == "the start is singular"
        assert snap["error"]["shown"]["generation"] == 1
        assert snap["computed_generation"] == 1
        seen = []
        dash.subscribe(seen.append)()
        assert [e.kind for e in seen][-1] == "error"
    finally:
        dash.stop()


def test_a_generations_error_never_goes_out_before_its_state(monkeypatch):
    """The state event of a change is sent by the thread that made it, after the worker was
    woken: on a loaded machine the worker's error came first, and the page, which had not
    heard of that generation, ignored it for good. The worker now waits for the state event:
    a listener slow on it (it waits up to 1 s for the error) sees the error only after it."""
    import threading

    dash = Dashboard()
    try:
        assert dash.wait(1, timeout=120)
        real = session_module.compute

        def failing(state, *args, **kwargs):
            if state.gamma == 2.5:
                raise JikError("the start is singular")
            return real(state, *args, **kwargs)

        monkeypatch.setattr(session_module, "compute", failing)
        seen, errored = [], threading.Event()

        def listener(event):  # (slow to take the state of generation 2)
            if event.kind == "state" and event.generation == 2:
                errored.wait(1.0)  # (an error sent meanwhile overtakes this state)
            seen.append((event.kind, event.generation))
            if event.kind == "error":
                errored.set()

        dash.subscribe(listener)
        generation, _ = dash.update({"gamma": 2.5})
        assert dash.wait(generation, timeout=120)
        mine = [e for e in seen if e[1] == 2]
        assert mine.index(("state", 2)) < mine.index(("error", 2)), seen
    finally:
        dash.stop()


ARM = {"name": "planar_chain", "joints": "RRR", "lengths": [1.0, 0.8, 0.6]}


def _arm_target(target):
    state = updated_state(
        default_state(),
        {"robot": "planar_chain", "robot_definition": ARM, "task": "target", "target": target},
    )
    return summary(compute(state))


def test_a_stalled_run_says_whether_the_target_is_out_of_reach():
    """A planar 3R arm of reach 1 + 0.8 + 0.6 = 2.4: a target at distance 5 is out of reach
    (both algorithms say so); one at 0.05 is within reach, where J^P# converges and J^E#
    (h = x3) stalls at an algorithmic singularity of [J; dh], J being regular."""
    far = _arm_target([5.0, 0.0])
    for algorithm in ("pseudoinverse", "extended"):
        assert (
            "the target is out of reach: it is 5 from the base, beyond the arm's reach 2.4"
            in (far[algorithm]["message"])
        )
        assert "near a singularity or the target is unreachable" not in far[algorithm]["message"]
    near = _arm_target([0.05, 0.0])
    assert near["pseudoinverse"]["success"]
    message = near["extended"]["message"]
    assert "the target is within reach (0.05 from the base, reach 2.4)" in message
    assert "J is regular there" in message and "algorithmic singularity" in message


def _warnings(state) -> list[str]:
    return [s["text"] for s in verdict(compute(state)) if s["role"] == "warning"]


def test_a_map_singular_in_its_design_region_is_said_where():
    """(32) with C2 = -1: g(x1) vanishes near x1 = 0.48 for any x2, x3, found by the engine's
    map_singularities on the design region; C2 = 1 is regular: no warning."""
    state = updated_state(default_state("manipulator1"), {"augmentation": "e1_optimal"})
    state = updated_state(state, {"augmentation_parameters": {"C1": 1.0, "C2": -1.0}})
    assert _warnings(state) == [
        "Warning: the augmenting map e1_optimal (C1 = 1, C2 = -1) is singular in the design "
        "region x1 ∈ [0, 1], x2 ∈ [0, 1], x3 ∈ [0.5, 1.5]: the gradient of h blows up; h jumps "
        "through infinity at x1 ∈ [0.458, 0.5], any x2, any x3 (1250 of the 25^3 grid points). E1 "
        "and E2 there are not a measure of fit, and the extended Jacobian is undefined where a "
        "run crosses it."
    ]
    regular = updated_state(state, {"augmentation_parameters": {"C1": 1.0, "C2": 1.0}})
    assert _warnings(regular) == []


def test_the_paper_cubic_loses_rank_inside_its_design_region():
    """(38) on Manipulator 2's design region: det [J; dh] changes sign between grid points
    (dh K = 0 there, where E1 diverges), which a test of the grid points alone missed."""
    warnings = _warnings(default_state("manipulator2"))
    assert len(warnings) == 1
    assert (
        "paper_cubic is singular in the design region x2 ∈ [-1, 1], x3 ∈ [0, 3.14]" in (warnings[0])
    )
    assert (
        "the extended Jacobian (10) loses rank at x2 ∈ [-1, 0.25], x3 ∈ [0, 0.916]" in (warnings[0])
    )


def test_a_leg_out_of_iterations_names_the_control_and_gamma_only_when_it_helps():
    """Discrete mode at gamma 1.9 with few iterations per leg: the leg's message names the
    control and says to take gamma nearer 1; a target out of reach says so instead."""
    state = updated_state(default_state(), {"mode": "discrete", "gamma": 1.9, "max_iterations": 10})
    message = summary(compute(state))["pseudoinverse"]["message"]
    assert "did not converge within 10 iterations" in message
    assert "raise “max iterations per leg” (a control above), take γ nearer 1" in message
    far = updated_state(
        default_state(),
        {
            "robot": "planar_chain",
            "robot_definition": ARM,
            "task": "target",
            "target": [3.0, 1.0],
            "mode": "discrete",
            "gamma": 1.0,
            "max_iterations": 10,
        },
    )
    message = summary(compute(far))["pseudoinverse"]["message"]
    assert "did not converge within 10 iterations" in message
    assert "the target is out of reach: it is 3.16 from the base" in message
    assert "γ" not in message
