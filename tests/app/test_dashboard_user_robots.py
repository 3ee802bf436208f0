"""A user's robot in the dashboard's state: its definition is state, refusals name
their field under robot_definition, and the session computes both algorithms for it."""

from __future__ import annotations

import numpy as np
import pytest

from jik.app.dashboard.functionals import functionals_key, state_inert_variables
from jik.app.dashboard.model import DashboardState, default_state, updated_state, validate
from jik.app.dashboard.patch import StatePatch, patch_of
from jik.app.dashboard.results import compute
from jik.app.dashboard.session import Dashboard
from jik.engine.exceptions import InvalidInputError

ARM = {"name": "planar_chain", "joints": "RRR", "lengths": [1.0, 0.8, 0.6]}


def _arm_state() -> DashboardState:
    return updated_state(default_state(), {"robot": "planar_chain", "robot_definition": ARM})


def test_a_definition_is_state_with_its_defaults_and_a_map():
    """The definition's defaults (x0 = 0.5 each, a closed path) and, as it gives no map, h = x3."""
    state = _arm_state()
    assert state.robot == "planar_chain" and state.robot_definition == ARM
    assert state.x0 == (0.5, 0.5, 0.5) and state.task == "path" and len(state.path) == 3
    assert state.augmentation == "formula"
    assert validate(state.as_dict()) == state  # (the page's link: the state as JSON)


@pytest.mark.parametrize(
    ("patch", "field", "text"),
    [
        (
            {"robot_definition": {**ARM, "lengths": [1.0, 0.8]}},
            "robot_definition.lengths",
            "one entry per joint (3), got 2",
        ),
        (
            {"robot_definition": {**ARM, "lengths": [1.0, "a", 0.6]}},
            "robot_definition.lengths.1",
            "must be a number",
        ),
        (
            {"robot_definition": {**ARM, "name": "formula"}},
            "robot_definition.name",
            "must be the robot's kind",
        ),
        (
            {
                "robot": "formula",
                "robot_definition": {
                    "name": "formula",
                    "variables": ["x1", "x2"],
                    "task": ["x1 + os"],
                },
            },
            "robot_definition.task.0",
            "unknown name 'os'",
        ),
        ({"robot": "urdf"}, "robot_definition", "needs its definition"),
        (
            {"robot_definition": {**ARM, "joints": "RR", "lengths": [0.4] * 2}},
            "robot_definition.joints",
            "this robot has p = 2, r = 2 (the REST API and jik solve",
        ),
        (
            {
                "robot_definition": {
                    **ARM,
                    "joints": "RRRR",
                    "lengths": [0.4] * 4,
                    "augmentations": [{"name": "formula", "h": "x4"}],
                }
            },
            "robot_definition.augmentations.0.h",
            "must be a list of 2 formulas (p - r = 2",
        ),
        (
            {
                "robot": "formula",
                "robot_definition": {
                    "name": "formula",
                    "task": ["x1 * a", "x2"],
                    "variables": ["x1", "x2", "x3"],
                    "parameters": {"a": 1e300},
                },
            },
            "robot_definition",
            "the robot's default target k(x0) has target[0] = 6.5e+299, which the dashboard "
            "refuses (Input should be less than or equal to 1000); change the definition (task, "
            "variables, parameters)",
        ),
        (
            {
                "robot": "formula",
                "robot_definition": {
                    "name": "formula",
                    "task": ["sqrt(x1 - 10)", "x2 + x3"],
                    "variables": ["x1", "x2", "x3"],
                },
            },
            "robot_definition.x0",
            "the task k(x) is undefined at x0 = (0.5, 0.5, 0.5) (k1 = nan) or at 256 points of "
            "x_range",
        ),
    ],
)
def test_refusals_name_the_definitions_field(patch, field, text):
    with pytest.raises(InvalidInputError) as err:
        updated_state(_arm_state(), {"robot": "planar_chain", **patch})
    assert err.value.field == field
    assert text in str(err.value)


def test_a_catalogue_robot_drops_the_definition():
    state = updated_state(_arm_state(), {"robot": "manipulator2"})
    assert state.robot_definition is None and state == default_state("manipulator2")
    with pytest.raises(InvalidInputError) as err:
        validate({**default_state().as_dict(), "robot_definition": ARM})
    assert err.value.field == "robot_definition"


def test_the_session_computes_both_algorithms_for_it():
    """The 3R arm on its default closed path: J^P# drifts, J^E# with h = x3 comes back."""
    dashboard = Dashboard(_arm_state())
    dashboard.start()
    try:
        assert dashboard.wait(timeout=60)
        runs = dashboard.result.runs
        assert runs["pseudoinverse"].drift[-1] > 1e-4
        assert np.max(runs["extended"].drift) < 1e-9
    finally:
        dashboard.stop()


def test_the_pages_link_opens_the_same_robot():
    """A link holds the whole state (?state=<JSON>): a new session from it has the same robot,
    definition and changes."""
    state = updated_state(_arm_state(), {"x0.1": 0.7, "cycles": 2})
    link = StatePatch.model_validate(state.as_dict())
    assert updated_state(default_state(), patch_of(link)) == state


def test_an_overflow_at_the_start_is_called_an_overflow():
    """k(x0) = exp(800) closes the path: the session says the kinematics overflow at x0 (it said
    "y_d contains NaN or infinite values")."""
    robot = {"name": "formula", "variables": ["x1", "x2", "x3"], "task": ["exp(x1) + x3", "x2"]}
    state = updated_state(_arm_state(), {"robot": "formula", "robot_definition": robot})
    state = updated_state(state, {"x0": [800.0, 0.5, 0.5]})
    with pytest.raises(InvalidInputError) as err:
        compute(state)
    assert err.value.field == "x0"
    assert "the kinematics are not finite at the start" in str(err.value)


def _formula_robot(task: list[str]) -> DashboardState:
    definition = {
        "name": "formula",
        "variables": ["x1", "x2", "x3"],
        "task": task,
        "augmentations": [{"name": "e2_synthesized", "region": {"x2": [0.4, 1], "x3": [0.4, 1]}}],
    }
    return updated_state(default_state(), {"robot": "formula", "robot_definition": definition})


def test_two_robots_of_one_kind_and_map_do_not_share_e1_e2():
    """Two formula robots with the same map and design region: J of the first ignores x1,
    the second's depends on it. Their E1/E2 (cached by what they depend on, shared by every
    session of the server) are not each other's: x1 is inert for the first only, held at x0's
    value for the second."""
    first = _formula_robot(["x2 + cos(x3)", "x1 + sin(x3)"])
    second = _formula_robot(["x2 + x1*cos(x3)", "x1 + sin(x3)"])
    assert state_inert_variables(first) == {0}
    assert state_inert_variables(second) == frozenset()
    assert functionals_key(first) != functionals_key(second)
    assert '"fixed": {"x1": 0.5}' in functionals_key(second)
