"""The posture inverse's rest sliders on a robot with joint limits but no ``x_range``: they span
what the dashboard accepts (the joint limits, the robot's range on a side without one), x0's
sliders the same (a start outside the limits, accepted and reported, is typed in x0's exact
boxes), and a rest slider
moved while the default rest (the start) is outside the limits brings the coordinates the user
did not touch into them, as the verdict said beforehand."""

from __future__ import annotations

import math

import pytest

from jik.app.dashboard.controls import control_values, controls
from jik.app.dashboard.model import default_state, updated_state
from jik.app.dashboard.verdict import verdict
from jik.engine.exceptions import InvalidInputError

REST = "algorithm_parameters.rest"
#: The verdict's sentence on what the posture inverse's rest did.
WHY = ("posture", "why")
PI = math.pi
#: Four revolute joints: a two-sided limit, one upper bound only, limits wider than x0's
#: sliders (-pi, pi), and a lower bound above them.
LIMITS = [[-1.0, 1.0], [None, 1.2], [-4.0, 4.0], [3.5, None]]
CHAIN = {"name": "planar_chain", "joints": "RRRR", "lengths": [1.0] * 4, "limits": LIMITS}
#: What the rest's sliders span (and the dashboard accepts) for LIMITS.
SPAN = [(-1.0, 1.0), (-PI, 1.2), (-4.0, 4.0), (3.5, 3.5 + 2 * PI)]


def _state(x0) -> object:
    chain = {**CHAIN, "x0": x0}
    state = updated_state(default_state(), {"robot": "planar_chain", "robot_definition": chain})
    return updated_state(state, {"algorithms": ["pseudoinverse", "posture"]})


def _sliders(state, key: str) -> list[tuple[float, float]]:
    return [
        (c.minimum, c.maximum)
        for c in controls(state)
        if c.key.startswith(f"{key}.") and c.kind == "slider"
    ]


def test_the_rest_and_x0_sliders_span_the_joint_limits():
    """Each end of a rest slider is accepted, a step beyond it is refused naming its
    coordinate; x0's sliders span the same ranges (the joint limits, not the robot's range
    (-pi, pi) past them), and an x0 beyond the first joint's limits, as an exact box sends it,
    is accepted (the runs report it as leaving them)."""
    state = _state([0.3, 0.3, 0.3, 3.6])
    assert _sliders(state, REST) == SPAN
    assert _sliders(state, "x0") == SPAN
    for i, (lo, hi) in enumerate(SPAN):
        for end, beyond in ((lo, lo - 0.01), (hi, hi + 0.01)):
            assert updated_state(state, {f"{REST}.{i}": end}).algorithm_parameters["rest"][i] == end
            with pytest.raises(InvalidInputError) as refused:
                updated_state(state, {f"{REST}.{i}": beyond})
            assert refused.value.field == f"{REST}.{i}"
    outside = updated_state(state, {"x0.0": 2.0})
    assert outside.x0[0] == 2.0  # (a start outside the limits, reported by the runs)


def test_a_rest_slider_moved_from_a_default_outside_the_limits_brings_the_others_in():
    """The default rest is the start, here outside the first two joints' limits: moving the
    third rest slider sets the rest with the first two at their nearest limit (what their
    sliders show), not a refusal naming a coordinate the user did not touch; the verdict says
    so before the move, and the exact boxes show the rest set after it."""
    x0 = [1.5, 2.0, 0.3, 3.6]
    state = _state(x0)
    assert "rest" not in state.algorithm_parameters
    assert [control_values(state)[f"{REST}.{i}"] for i in range(4)] == x0  # (the default)
    moved = updated_state(state, {f"{REST}.2": 0.5})
    assert moved.algorithm_parameters["rest"] == (1.0, 1.2, 0.5, 3.6)
    assert [control_values(moved)[f"{REST}.{i}"] for i in range(4)] == [1.0, 1.2, 0.5, 3.6]
    assert updated_state(moved, {f"{REST}.0": -0.5}).algorithm_parameters["rest"][1] == 1.2
    # (a rest set keeps its coordinates: only a default is brought into the limits)
    with pytest.raises(InvalidInputError) as refused:
        updated_state(state, {REST: [1.5, 1.0, 0.5, 3.6]})
    assert refused.value.field == f"{REST}.0"

    from jik.app.dashboard.results import compute

    def said(result) -> str:
        (text,) = [s["text"] for s in verdict(result) if (s["algorithm"], s["role"]) == WHY]
        return text

    result = compute(updated_state(state, {"cycles": 1}))
    assert (
        "x_rest = x0 (1.5, 2, 0.3, 3.6), the default, outside the joint limits: moving a rest "
        "slider sets the rest with x1 = 1, x2 = 1.2, the nearest values within them"
    ) in said(result)
    assert "x_rest = (1, 1.2, 0.5, 3.6) (set):" in said(
        compute(updated_state(moved, {"cycles": 1}))
    )


def test_the_scene_s_rest_sliders_span_the_limits_and_bring_the_default_in():
    """The scene builds its rest sliders from the same specification: over the joint limits,
    at the default in force (as the page's exact boxes, the start x0); one moved sets the rest
    as the page's does."""
    from jik.app.dashboard import Dashboard
    from jik.app.scene import DashboardScene

    dashboard = Dashboard(_state([1.5, 2.0, 0.3, 3.6]))
    scene = DashboardScene(dashboard)
    try:
        scene.controls.show(dashboard.state)
        rest = [scene.controls.inputs[f"{REST}.{i}"] for i in range(4)]
        assert [(h.min, h.max) for h in rest] == SPAN
        assert [h.value for h in rest] == [1.5, 2.0, 0.3, 3.6]
        rest[2].value = 0.5  # what a move of the slider gives
        assert dashboard.state.algorithm_parameters["rest"] == (1.0, 1.2, 0.5, 3.6)
    finally:
        scene.stop()
        dashboard.stop()
