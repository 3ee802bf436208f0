"""One description of the dashboard's controls (jik.app.dashboard.controls): from the registry,
shown the same in the page and the scene, turned into state changes in one place
(jik.app.dashboard.control_changes)."""

from __future__ import annotations

import json

import pytest

from jik.app.dashboard import default_state, updated_state
from jik.app.dashboard.control_changes import (
    DISCRETE_GAMMA_ON_SWITCH,
    expand,
    parse_path_text,
    path_text,
)
from jik.app.dashboard.controls import GAMMA_RANGE, control_values, controls
from jik.engine.arms import ARMS
from jik.engine.exceptions import InvalidInputError
from jik.engine.registry import ROBOTS, robot_spec


def _states():
    for robot in ROBOTS:
        state = default_state(robot)
        yield state
        if robot_spec(robot).default_path:
            other = "target" if state.task == "path" else "path"
            yield updated_state(state, {"task": other})
        yield updated_state(state, {"mode": "discrete"})


@pytest.mark.parametrize("state", list(_states()), ids=lambda s: f"{s.robot}-{s.task}-{s.mode}")
def test_every_control_shows_its_value_and_setting_it_changes_nothing(state):
    """Each control's shown value, sent back as a change, is the state in force: the page and
    the scene can always send what they show."""
    values = control_values(state)
    for c in controls(state):
        if c.kind == "preset":
            continue
        assert updated_state(state, {c.key: values[c.key]}) == state, c.key


@pytest.mark.parametrize("robot", sorted(ROBOTS))
def test_ranges_and_labels_come_from_the_registry(robot):
    state = default_state(robot)
    spec = robot_spec(robot)
    by_key = {c.key: c for c in controls(state) if c.kind != "preset"}
    for p in spec.parameters:
        c = by_key[f"robot_parameters.{p.name}"]
        assert (c.minimum, c.maximum) == (p.minimum, p.maximum)
        assert c.help.startswith(p.description)  # (then the paper's symbol explained)
    for i, name in enumerate(spec.variable_names):
        assert by_key[f"x0.{i}"].label == f"x0: {name}"
        # (its help names the variables as the labels do: the unicycle's lambda10, not λ10)
        assert "λ1" not in by_key[f"x0.{i}"].help and "λ2" not in by_key[f"x0.{i}"].help
    assert [v for v, _ in by_key["robot"].options] == [*ROBOTS, *ARMS]  # (then the arms)
    assert [v for v, _ in by_key["augmentation"].options] == [a.name for a in spec.augmentations]
    aug = spec.augmentation(state.augmentation)
    assert {k for k in by_key if k.startswith("augmentation_parameters.")} == {
        f"augmentation_parameters.{p.name}" for p in aug.parameters
    }


def test_gamma_range_follows_the_mode_and_a_switch_to_discrete_clamps_it():
    state = updated_state(default_state("manipulator2"), {"gamma": 5.0})
    (gamma,) = [c for c in controls(state) if c.key == "gamma"]
    assert (gamma.minimum, gamma.maximum) == GAMMA_RANGE["continuous"]
    discrete = updated_state(state, {"mode": "discrete"})
    assert discrete.gamma == DISCRETE_GAMMA_ON_SWITCH
    (gamma,) = [c for c in controls(discrete) if c.key == "gamma"]
    assert (gamma.minimum, gamma.maximum) == GAMMA_RANGE["discrete"]
    small = updated_state(updated_state(state, {"gamma": 0.3}), {"mode": "discrete"})
    assert small.gamma == 0.3  # (within the range: kept)


def test_control_keys_expand_into_state_fields():
    state = default_state("manipulator2")
    assert expand(state, {"x0.1": 0.5}) == {"x0": [state.x0[0], 0.5, state.x0[2]]}
    assert expand(state, {"robot_parameters.l": 1.2}) == {"robot_parameters": {"l": 1.2}}
    assert expand(state, {"path": "1, 1; 1, 2"}) == {"path": [[1.0, 1.0], [1.0, 2.0]]}
    assert parse_path_text(path_text(state.path)) == [list(p) for p in state.path]


def test_a_path_is_written_a_point_per_line_and_read_back_from_lines():
    """The path's text has a line per point (the page's box shows as many lines as points); a
    new line separates points as ';' does, so a point added on a line of its own, without a
    ';', is a point."""
    state = default_state("manipulator2")
    assert path_text(state.path) == "1, 1;\n1, 2;\n0, 2;\n0, 1"
    assert parse_path_text("1, 1\n1, 2;\n0, 2\n\n") == [[1.0, 1.0], [1.0, 2.0], [0.0, 2.0]]
    with pytest.raises(InvalidInputError) as bad:
        parse_path_text("1, 1\n1", size=2)
    assert str(bad.value).startswith("path: point 2 of 2, '1', has 1 coordinate; each point")


def test_a_computed_path_is_shown_as_a_user_types_it_and_stays_exact():
    """A catalogue arm's path is computed (its pose coordinates 1.29e-17 where 0 is meant):
    its box shows 4 decimals, 0 for those, and the shown text sent back keeps the exact
    path; an edited point is what is typed, the others stay exact."""
    state = default_state("panda")
    text = control_values(state)["path"]
    assert "e-" not in text and text.startswith("0.3034, 0.0459, 0.5903, 0, 0, -0.15;\n")
    assert updated_state(state, {"path": text}).path == state.path
    # (the same text on one line, as typed into a one-line box: no change either)
    assert updated_state(state, {"path": " ".join(text.split())}).path == state.path
    edited = updated_state(state, {"path": text.replace("-0.15", "-0.1")})
    assert edited.path[0] == (0.3034, 0.0459, 0.5903, 0.0, 0.0, -0.1)
    # (the points not edited, and those of a point added, stay exact, not rounded as shown)
    assert edited.path[1:] == state.path[1:]
    longer = updated_state(state, {"path": text + ";\n0.31, 0, 0.59, 0, 0, 0.1"})
    assert longer.path == (*state.path, (0.31, 0.0, 0.59, 0.0, 0.0, 0.1))
    with pytest.raises(InvalidInputError) as bad:
        expand(state, {"x0.7": 1.0})
    assert bad.value.field == "x0.7"
    with pytest.raises(InvalidInputError) as text:
        updated_state(state, {"path": "1, 1; one, 2"})
    # (the way to write it names a pose point's 6 coordinates, as the box's placeholder does)
    assert text.value.field == "path" and "(write 'y1, ..., y6; y1, ..., y6; ...')" in str(
        text.value
    )
    (box,) = [c for c in controls(state) if c.key == "path"]
    assert box.format == "y1, ..., y6; y1, ..., y6; ..." and box.format in box.help
    (planar,) = [c for c in controls(default_state("manipulator2")) if c.key == "path"]
    assert planar.format == "y1, y2; y1, y2; ..."


def test_a_vector_typed_as_text_is_its_numbers_and_the_shown_text_keeps_it_exact():
    """A pose target (6 numbers) is a text box in the 3D scene, which sends its text: the
    dashboard reads the numbers (it refused any text before: 'Input should be a valid tuple');
    the text shown sent back keeps the target in force exact; a wrong text is refused naming
    the target."""
    state = updated_state(default_state("panda"), {"task": "target"})
    shown = path_text([state.target])
    assert shown == "0.3034, 0.0459, 0.5903, 0, 0, 0"
    assert updated_state(state, {"target": shown}).target == state.target
    edited = updated_state(state, {"target": "0.3, 0.05, 0.6, 0, 0, 0.1"})
    assert edited.target == (0.3, 0.05, 0.6, 0.0, 0.0, 0.1)
    for text, says in (("0.3, x", "is not numbers"), ("0.3, 0.1", "write 6 finite numbers")):
        with pytest.raises(InvalidInputError) as bad:
            updated_state(state, {"target": text})
        assert bad.value.field == "target" and says in str(bad.value)


@pytest.mark.parametrize(
    ("patch", "field"),
    [
        ({"gamma": -1}, "gamma"),
        ({"robot_parameters.l": -3}, "robot_parameters.l"),
        ({"robot_parameters": {"l": "abc"}}, "robot_parameters.l"),
        ({"robot_parameters": 5}, "robot_parameters"),
        ({"x0": [1, 2]}, "x0"),
        ({"augmentation": "nope"}, "augmentation"),
        ({"cycles": 99}, "cycles"),
        ({"mode": "discrete", "gamma": 3}, "gamma"),
        ({"robot": 7}, "robot"),
        ({"nonsense": 1}, "nonsense"),
        ({"x0": [1e300, 0.0, 1.0]}, "x0.0"),  # (the API's coordinate bound)
        ({"tolerance": 0}, "tolerance"),
        ({"gamma": True}, "gamma"),  # (a boolean is no number: it was taken as 1)
        ({"cycles": True}, "cycles"),
        ({"robot_parameters.l": False}, "robot_parameters.l"),
    ],
)
def test_refusals_carry_their_field(patch, field):
    """An error names its field as data (never parsed from its message)."""
    with pytest.raises(InvalidInputError) as refused:
        updated_state(default_state("manipulator2"), patch)
    assert refused.value.field == field


def test_a_text_path_too_long_is_refused_for_its_length():
    """A path given as text past its bound is refused for that, not as "a valid tuple" (the
    other member of its type)."""
    from jik.app.dashboard.patch import parse_patch

    with pytest.raises(InvalidInputError) as refused:
        parse_patch({"path": "1, 1; " * 3000})
    assert refused.value.field == "path"
    assert str(refused.value) == "path: String should have at most 10000 characters"


@pytest.mark.parametrize(
    ("field", "keys"),
    [
        ("x0", ["x0.0", "x0.1", "x0.2"]),  # (a vector: each of its coordinates' sliders)
        ("x0.1", ["x0.1"]),
        ("robot_parameters.l", ["robot_parameters.l"]),
        ("path.2.1", ["path"]),  # (a coordinate of a point of the path: the path's box)
        ("gamma", ["gamma"]),
        ("nonsense", []),
    ],
)
def test_a_refusal_names_the_controls_it_is_about(field, keys):
    """The keys the page marks for a refused field, as the scene marks its inputs (one rule,
    ``about``); a refused change's event carries them."""
    from jik.app.dashboard import Dashboard
    from jik.app.dashboard.controls import controls_about

    state = default_state("manipulator2")
    assert controls_about(controls(state), field) == keys
    dashboard, seen = Dashboard(state), []
    dashboard.subscribe(seen.append)
    try:
        with pytest.raises(InvalidInputError):
            dashboard.update({"x0": [1, 2]})
    finally:
        dashboard.stop()
    (refused,) = [json.loads(e.data) for e in seen if e.kind == "refused"]
    assert refused["field"] == "x0" and refused["about"] == ["x0.0", "x0.1", "x0.2"]


def test_the_scene_and_the_page_show_the_same_controls():
    """The scene's GUI has one input per control of the specification, with its label, and
    selects show the same option labels as the page."""
    from jik.app.dashboard import Dashboard
    from jik.app.scene import DashboardScene

    dashboard = Dashboard(default_state("unicycle"))
    scene = DashboardScene(dashboard)
    try:
        scene.controls.show(dashboard.state)
        spec = {c.key: c for c in controls(dashboard.state) if c.kind != "preset"}
        assert set(scene.controls.inputs) == set(spec)
        for key, handle in scene.controls.inputs.items():
            assert handle.label == spec[key].label, key
        robot = scene.controls.inputs["robot"]
        assert list(robot.options) == [label for _, label in spec["robot"].options]
    finally:
        scene.stop()
        dashboard.stop()


@pytest.mark.parametrize(
    ("rest", "dashboard", "field"),
    [
        ({"gamma": -1}, {"gamma": -1}, "gamma"),
        ({"tolerance": 2.0}, {"tolerance": 2.0}, "tolerance"),
        ({"x0": [1e300, 0.0, 1.0]}, {"x0": [1e300, 0.0, 1.0]}, "x0"),
        ({"robot": {"name": "manipulator2", "l": 99}}, {"robot_parameters.l": 99}, "l"),
    ],
)
def test_a_dashboard_change_is_refused_as_a_rest_request_is(rest, dashboard, field):
    """The same pydantic field types and per-robot models check both: the same problem."""
    from jik.app.compute.schemas import SolveRequest

    body = {
        "robot": {"name": "manipulator2"},
        "algorithm": "pseudoinverse",
        "x0": [0.0, 0.0, 1.0],
        "target": [1.0, 1.0],
        **rest,
    }
    with pytest.raises(Exception) as api:
        SolveRequest.model_validate(body)
    with pytest.raises(InvalidInputError) as ours:
        updated_state(default_state("manipulator2"), dashboard)
    problem = api.value.errors()[0]["msg"]
    assert str(ours.value).endswith(problem) and field in ours.value.field


def test_control_keys_beside_a_change_of_robot_are_the_new_robots():
    """{"robot": "unicycle", "x0.0": 0}: the unicycle's x0 with its first component 0 (the key
    was expanded against the old robot's three-component x0 and refused; schemathesis, via a
    session's link state)."""
    state = updated_state(default_state("manipulator2"), {"x0.0": 0.0, "robot": "unicycle"})
    assert state.robot == "unicycle"
    assert state.x0 == (0.0, *default_state("unicycle").x0[1:])


def test_the_algorithms_parameters_are_labelled_with_the_verdicts_symbols():
    """The sliders of damped least squares and the posture inverse read as the verdict writes
    them (λ, σ_min, gain k), not as the registry's keys ("damping_threshold")."""
    state = updated_state(default_state(), {"algorithms": ["pseudoinverse", "damped", "posture"]})
    labels = {c.key: c.label for c in controls(state) if c.key.startswith("algorithm_parameters.")}
    assert labels["algorithm_parameters.damping"] == "λ (damping)"
    assert labels["algorithm_parameters.damping_threshold"] == "damping threshold (σ_min)"
    assert labels["algorithm_parameters.gain"] == "k (null-space gain)"


def test_the_tolerance_is_a_control_of_the_page_and_the_scene():
    """The tolerance, which decides where every leg stops, is a select of powers of ten (the
    state's own value too when it is another); chosen in the scene, it changes the state and
    the runs: a discrete leg at 1e-4 stops sooner, with a larger error, than at 1e-12."""
    from jik.app.dashboard import Dashboard, compute
    from jik.app.scene import DashboardScene

    state = default_state("manipulator2")
    (tol,) = [c for c in controls(state) if c.key == "tolerance"]
    assert [v for v, _ in tol.options] == [float(f"1e-{k}") for k in range(4, 15)]
    assert control_values(state)["tolerance"] == 1e-10
    odd = updated_state(state, {"tolerance": 3e-9})
    (tol,) = [c for c in controls(odd) if c.key == "tolerance"]
    assert (3e-9, "3e-09") in tol.options and (1e-10, "1e-10") in tol.options
    dashboard = Dashboard(state)
    scene = DashboardScene(dashboard)
    try:
        scene.controls.show(dashboard.state)
        box = scene.controls.inputs["tolerance"]
        assert box.value == "1e-10" and "1e-12" in box.options
        box.value = "1e-4"  # (viser's thread, for a user)
        assert dashboard.state.tolerance == 1e-4
    finally:
        scene.stop()
        dashboard.stop()
    discrete = {"task": "target", "mode": "discrete", "gamma": 0.5}  # (error halves a step)
    coarse = compute(updated_state(state, {"tolerance": 1e-4, **discrete}))
    fine = compute(updated_state(state, {"tolerance": 1e-12, **discrete}))
    for a in coarse.runs:
        assert 1e-12 <= coarse.runs[a].error[-1] < 1e-4 and fine.runs[a].error[-1] < 1e-12
        assert len(coarse.runs[a].error) < len(fine.runs[a].error)


@pytest.mark.parametrize("task", ["target", "path"])
def test_a_run_over_the_time_limit_is_refused_at_a_control_the_task_shows(task):
    """A dashboard run the compute pool stops at its time limit is refused at the field its
    task names (:func:`jik.app.compute.worker.work_of`): a control on screen for a single
    target as for a closed path (cycles is not one for a target), and its advice names it."""
    from jik.app.compute.worker import work_of
    from jik.app.dashboard.offload import run_offloaded

    field, less = work_of(run_offloaded)
    state = updated_state(default_state("manipulator2"), {"task": task})
    (control,) = [c for c in controls(state) if c.key == field]
    assert control.label.startswith("max ") and "“max … per leg”" in less


def test_any_three_joints_of_an_arm_can_be_the_configuration_space_axes():
    """A 7-joint chain offers every three of its joints, in order (35 choices, hexadecimal
    digits as the state writes them: up to 16 joints); the panel draws the three chosen, and a
    choice out of order or past p is refused naming the control."""
    from jik.app.dashboard.cspace import cspace_spec
    from jik.app.dashboard.results import compute

    chain = {"name": "planar_chain", "joints": "R" * 7, "lengths": [0.3] * 7}
    state = updated_state(default_state(), {"robot": "planar_chain", "robot_definition": chain})
    (axes,) = [c for c in controls(state) if c.key == "cspace_axes"]
    assert len(axes.options) == 35 and axes.options[-1] == ("456", "x5, x6, x7")
    chosen = updated_state(state, {"cspace_axes": "046"})
    title = cspace_spec(compute(chosen, 2))["layout"]["title"]["text"]
    assert title.startswith("Configuration space (x1, x5, x7)")
    for bad in ("064", "047", "0a1"):
        with pytest.raises(InvalidInputError) as refused:
            updated_state(state, {"cspace_axes": bad})
        assert refused.value.field == "cspace_axes"
