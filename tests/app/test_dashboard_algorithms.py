"""The dashboard's choice of algorithms: one to five of the engine's catalogue side by side, their
parameters as controls with the engine's ranges, one colour each in every panel, their cache
keys, the verdict's sentences about them, and the session API taking the choice."""

from __future__ import annotations

import json

import numpy as np
import pytest

from jik.app.compute.schemas.wording import field_text
from jik.app.dashboard.algorithms import COLORS, DEFAULT_ALGORITHMS, STYLES, cache_key, runs_key
from jik.app.dashboard.atlas import atlas_request
from jik.app.dashboard.controls import control_values, controls
from jik.app.dashboard.figures import figure_specs
from jik.app.dashboard.model import default_state, updated_state
from jik.app.dashboard.results import compute
from jik.app.dashboard.robots import state_inverse, state_kinematics
from jik.app.dashboard.verdict import verdict
from jik.engine.exceptions import InvalidInputError
from jik.engine.registry import ALGORITHMS

THREE = ["pseudoinverse", "extended", "posture"]
REST = "algorithm_parameters.rest"


def test_the_default_view_runs_the_paper_two():
    state = default_state()
    assert state.algorithms == DEFAULT_ALGORITHMS and state.algorithm_parameters == {}
    assert [c.key for c in controls(state) if c.key.startswith("algorithm_parameters")] == []


def test_choosing_algorithms_fills_their_parameters_from_the_engine():
    state = updated_state(default_state(), {"algorithms": ["posture", "damped", "pseudoinverse"]})
    assert state.algorithms == ("pseudoinverse", "damped", "posture")  # (the catalogue's order)
    assert state.algorithm_parameters == {"damping": 0.1, "damping_threshold": 0.0, "gain": 1.0}
    sliders = {c.key: c for c in controls(state) if c.key.startswith("algorithm_parameters.")}
    for p in (*ALGORITHMS["damped"].parameters, *ALGORITHMS["posture"].parameters):
        c = sliders[f"algorithm_parameters.{p.name}"]
        assert (c.minimum, c.maximum) == (p.minimum, p.maximum)
    changed = updated_state(state, {"algorithm_parameters.gain": 2.5})
    assert changed.algorithm_parameters["gain"] == 2.5
    # (a parameter of an algorithm no longer chosen is dropped)
    assert updated_state(changed, {"algorithms": ["posture"]}).algorithm_parameters == {"gain": 2.5}


@pytest.mark.parametrize(
    ("patch", "field"),
    [
        ({"algorithms": []}, "algorithms"),
        ({"algorithms": ["nope"]}, "algorithms.0"),
        ({"algorithms": ["posture", "posture"]}, "algorithms"),
        (
            {"algorithms": ["posture"], "algorithm_parameters": {"gain": -1.0}},
            "algorithm_parameters.gain",
        ),
        (
            {"algorithms": ["damped"], "algorithm_parameters.damping": 11.0},
            "algorithm_parameters.damping",
        ),
        ({"algorithm_parameters": {"lambda": 1.0}}, "algorithm_parameters.lambda"),
        # (a parameter of an algorithm not chosen: checked, though it would then be dropped)
        ({"algorithm_parameters": {"damping": -1.0}}, "algorithm_parameters.damping"),
        ({"algorithm_parameters": {"rest": [1e308] * 3}}, "algorithm_parameters.rest.0"),
    ],
)
def test_a_bad_choice_is_refused_naming_its_field(patch, field):
    with pytest.raises(InvalidInputError) as refused:
        updated_state(default_state(), patch)
    assert refused.value.field == field


def test_an_algorithm_the_robot_cannot_run_is_refused_naming_the_choice(monkeypatch):
    """The chosen inverses are built when the state is validated: the engine's refusal (the
    weighted inverse of a robot with neither joint limits nor a box) names ``algorithms``."""
    from jik.app.dashboard import model

    def refuse(state, algorithm, kin=None):
        raise InvalidInputError("planar_chain has no joint limits: give limits", "limits")

    monkeypatch.setattr(model, "state_inverse", refuse)
    with pytest.raises(InvalidInputError) as refused:
        updated_state(default_state(), {"algorithms": ["weighted"]})
    assert refused.value.field == "algorithms" and "no joint limits" in str(refused.value)
    assert updated_state(default_state(), {"cycles": 2}).cycles == 2  # (the paper's two: not built)


def test_cache_keys_hold_each_algorithms_own_parameters():
    state = updated_state(default_state(), {"algorithms": ["pseudoinverse", "damped", "posture"]})
    more = updated_state(state, {"algorithm_parameters.gain": 3.0})
    assert cache_key(more, "posture") != cache_key(state, "posture")
    assert cache_key(more, "pseudoinverse") == cache_key(state, "pseudoinverse")
    assert cache_key(more, "damped") == cache_key(state, "damped")
    assert len(set(runs_key(state))) == 3


@pytest.fixture(scope="module")
def three():
    state = updated_state(default_state(), {"algorithms": THREE, "cycles": 10})
    return compute(state)


def test_three_algorithms_one_colour_each_in_every_panel(three):
    assert list(three.runs) == THREE
    specs = figure_specs(three)
    drift = [t for t in specs["drift"]["data"] if t.get("mode") == "lines+markers"]
    assert [t["line"]["color"] for t in drift] == [COLORS[a] for a in THREE]
    assert [t["line"]["dash"] for t in drift] == [STYLES[a].dash for a in THREE]
    task = [t for t in specs["task"]["data"] if t.get("name") in {STYLES[a].label for a in THREE}]
    assert len(task) == 3
    assert len({STYLES[a].color for a in STYLES}) == len(STYLES)


def test_verdict_says_posture_drifts_less_but_is_not_repeatable(three):
    """Table 1's loop, gain 1, ten cycles: the sentence gives both comparisons, in numbers."""
    d = {a: float(r.drift[-1]) for a, r in three.runs.items()}
    assert d["posture"] < d["pseudoinverse"] and d["extended"] < 1e-12 < d["posture"]
    posture = [s["text"] for s in verdict(three) if s["algorithm"] == "posture"]
    said = " ".join(posture)
    assert f"less than the pseudoinverse's {d['pseudoinverse']:.3g}" in said
    assert f"does not reach the extended Jacobian's {d['extended']:.3g}" in said


def test_verdict_reports_damped_tracking_error_and_weighted_limits():
    state = updated_state(default_state(), {"algorithms": ["damped", "weighted"], "cycles": 2})
    result = compute(state)
    texts = {s["algorithm"]: s["text"] for s in verdict(result) if s["role"] != "finding"}
    ends = result.runs["damped"].error[
        np.r_[
            np.flatnonzero(np.diff(result.runs["damped"].leg)), len(result.runs["damped"].leg) - 1
        ]
    ]
    assert f"task error at the end of its legs up to {ends.max():.3g}" in texts["damped"]
    cycle, leg = divmod(int(np.argmax(ends)), len(result.targets))  # (as the export counts)
    assert f"(cycle {cycle + 1}, leg {leg + 1}; tolerance" in texts["damped"]
    assert "stayed within its limits" in texts["weighted"]
    assert "no joint limits: its configuration box x_range" in texts["weighted"]


def test_the_atlas_compares_the_chosen_algorithms(three):
    request = atlas_request(three.state, 8)
    assert request.algorithms == THREE
    assert request.algorithm_parameters is not None
    assert request.algorithm_parameters.gain == 1.0
    # no rest: the atlas's posture inverse pulls each run toward its own start, not toward x0
    assert request.algorithm_parameters.rest is None


def test_an_atlas_without_the_extended_inverse_is_planned_without_a_map():
    """The map is the extended inverse's: an atlas of the others alone sends none (the server
    refuses one there), and the server plans it."""
    from jik.app.compute.atlas_plan import AtlasLimits, planned

    state = updated_state(default_state(), {"algorithms": ["pseudoinverse", "damped"]})
    request = atlas_request(state, 4, cycles=1)
    assert request.augmentation is None and request.algorithms == ["pseudoinverse", "damped"]
    planned(request, AtlasLimits())
    assert atlas_request(updated_state(state, {"algorithms": THREE}), 4).augmentation is not None


def test_the_session_api_takes_the_choice(client):
    """POST /api/sessions/{id}/state chooses three algorithms; a bad choice is a 422 naming its
    field, and the state stays."""
    session = client.post("/api/sessions", json={"state": {}}).json()
    url = f"/api/sessions/{session['id']}/state"
    r = client.post(url, json={"algorithms": THREE, "algorithm_parameters.gain": 2.0})
    assert r.status_code == 200, r.text
    assert r.json()["state"]["algorithms"] == THREE
    assert r.json()["state"]["algorithm_parameters"] == {"gain": 2.0}
    bad = client.post(url, json={"algorithm_parameters.gain": -2.0})
    assert bad.status_code == 422 and "algorithm_parameters.gain" in bad.text
    none = client.post(url, json={"algorithms": []})
    assert none.status_code == 422
    assert [d["msg"] for d in none.json()["detail"]] == ["algorithms: give at least 1 entry, got 0"]
    assert client.get(f"/api/sessions/{session['id']}").json()["state"]["algorithms"] == THREE


def test_the_scene_draws_a_robot_per_chosen_algorithm(three):
    """A copy of the robot and a trace per algorithm, in its colour; the key names the three;
    the paper's two alone come back to the default set."""
    from jik.app.dashboard import Dashboard
    from jik.app.scene import DashboardScene
    from jik.app.scene.fixtures import rgb

    dashboard = Dashboard(default_state())
    scene = DashboardScene(dashboard)
    try:
        assert dashboard.wait(1, timeout=60)
        scene._draw(three)
        assert list(scene.nodes.mechanisms) == THREE
        root = "/robot/manipulator2-path-pseudoinverse-extended-posture"
        for a in THREE:
            trace = scene.nodes.fixtures[f"{root}/trace/{a}/task"]
            assert tuple(np.asarray(trace.colors).reshape(-1, 3)[0]) == rgb(COLORS[a])
        assert all(STYLES[a].label in scene.legend.content for a in THREE)
        scene._draw(compute(default_state(), 200))
        assert list(scene.nodes.mechanisms) == list(DEFAULT_ALGORITHMS)
        assert STYLES["posture"].label not in scene.legend.content
        # (the scene's panel builds the rest's sliders from the same description as the page)
        scene.controls.show(three.state)
        rest = {k: h for k, h in scene.controls.inputs.items() if k.startswith(REST)}
        assert [h.label for h in rest.values()] == ["rest: x1", "rest: x2", "rest: x3"]
        assert [h.value for h in rest.values()] == list(three.state.x0)
    finally:
        scene.stop()
        dashboard.stop()


CHAIN = {"name": "planar_chain", "joints": "RRR", "lengths": [1.0, 1.0, 1.0], "x0": [0.3, 0.3, 0.3]}


def _damped_beside_pseudoinverse(x0, target):
    state = updated_state(default_state(), {"robot": "planar_chain", "robot_definition": CHAIN})
    state = updated_state(
        state,
        {"task": "target", "target": target, "x0": x0, "algorithms": ["pseudoinverse", "damped"]},
    )
    result = compute(state)
    return result, {(s["algorithm"], s["role"]): s["text"] for s in verdict(result)}


def test_damped_goes_through_a_singular_start_where_the_pseudoinverse_stops():
    """The 3R arm stretched (J of rank 1): the pseudoinverse's run stops, damped least squares
    converges, and the verdict says so beside its task error."""
    result, said = _damped_beside_pseudoinverse([0.0, 0.0, 0.0], [2.0, 1.0])
    assert not result.runs["pseudoinverse"].success and result.runs["damped"].success
    assert "J J^T is singular" in said[("pseudoinverse", "failure")]
    assert "it went through where the pseudoinverse stopped" in said[("damped", "why")]


def test_a_run_stopped_at_a_singular_start_names_the_field_x0():
    """The stretched 3R arm's first leg starts singular for the pseudoinverse: its run and its
    summary name x0 (the engine's field) and the keys of its controls, which the page marks;
    damped least squares goes through and names none."""
    from jik.app.dashboard.messages import summary

    result, _ = _damped_beside_pseudoinverse([0.0, 0.0, 0.0], [2.0, 1.0])
    said = summary(result)
    assert said["pseudoinverse"]["field"] == "x0" and said["damped"]["field"] is None
    assert said["pseudoinverse"]["controls"] == ["x0.0", "x0.1", "x0.2"]
    assert said["damped"]["controls"] == []
    assert "J J^T is singular" in said["pseudoinverse"]["message"]


def test_damped_reports_its_task_error_at_the_reach_boundary():
    """A target beyond reach: the pseudoinverse stalls at 1.22, damped least squares stretches
    the arm to the singular configuration and is left with 0.5; both numbers are said."""
    result, said = _damped_beside_pseudoinverse([0.3, 0.3, 0.3], [3.5, 0.0])
    assert result.runs["damped"].error[-1] == pytest.approx(0.5, abs=1e-6)
    why = said[("damped", "why")]
    assert "task error at its end 0.5 (tolerance" in why
    assert "where the pseudoinverse stalled at task error 1.22, it got to 0.5" in why


def test_the_atlas_figure_has_a_heatmap_per_algorithm_on_one_colour_scale(three):
    """Three algorithms' drift over the same starts: three heatmaps side by side, one shared
    colour axis spanning all, each titled in its algorithm's colour (plotly validates it)."""
    import plotly.graph_objects as go

    from jik.app.compute.schemas import RobotUsed, UnitsInfo
    from jik.app.dashboard.atlas import atlas_figure
    from jik.engine import robot_from_dict

    request = atlas_request(three.state, 4, cycles=2)
    units = UnitsInfo(**robot_from_dict({"name": "manipulator2"}).units.summary())
    robot = RobotUsed(name="manipulator2", title="Manipulator 2", parameters={}, units=units)
    decades = {"pseudoinverse": -1.0, "extended": -15.0, "posture": -3.0}
    result = {
        "algorithms": THREE,
        "parameter": [-0.2, 0.0, 0.1, 0.3],
        "paths": [request.path],
        "drift": {a: np.full((1, 4, 2), 10.0**d).tolist() for a, d in decades.items()},
    }
    spec = atlas_figure(result, request, robot)
    assert "Manipulator 2, γ = " in spec["layout"]["title"]["text"]
    maps = [t for t in spec["data"] if t["type"] == "heatmap"]
    assert [t["coloraxis"] for t in maps] == ["coloraxis"] * 3
    assert [t["xaxis"] for t in maps] == ["x", "x2", "x3"]
    axis = spec["layout"]["coloraxis"]
    assert axis["cmin"] <= -14 and axis["cmax"] >= -1
    titles = [a["font"]["color"] for a in spec["layout"]["annotations"] if "font" in a]
    assert [COLORS[a] for a in THREE] == titles[:3]
    posture = [a["text"] for a in spec["layout"]["annotations"] if "posture" in a["text"]]
    assert len(posture) == 1 and posture[0].endswith("<br>x_rest = each run's start")
    go.Figure(spec)  # (validated)


def test_table1_gives_each_chosen_algorithm_its_column_group(three):
    """On Table 1's experiment with the posture inverse chosen: the paper's layout for J^P#
    and J^E# (jik's and the printed columns), then the posture inverse's columns of jik in
    its colour, its leg ends to four decimals, and a note that the paper prints none."""
    from jik.app.dashboard.table import FILLS, SHORT, table1_spec

    spec = table1_spec(three)
    table = spec["data"][0]
    header, cols = table["header"]["values"], table["cells"]["values"]
    fills = table["header"]["fill"]["color"]
    paper = [
        f"{SHORT[a]} x{k} ({w})"
        for a in ("pseudoinverse", "extended")
        for w in ("jik", "printed")
        for k in (1, 2, 3)
    ]
    assert header[1:13] == paper
    assert header[13:] == ["posture x1 (jik)", "posture x2 (jik)", "posture x3 (jik)"]
    assert fills[13:] == [FILLS["posture"]] * 3 and len(set(fills[1:13]) & set(fills[13:])) == 0
    ends = three.runs["posture"].leg_end
    for k in range(3):
        assert float(cols[13 + k][1]) == pytest.approx(ends[0, k], abs=1e-4)
        assert float(cols[13 + k][len(ends)]) == pytest.approx(ends[-1, k], abs=1e-4)
    assert any(
        "posture" in n and "prints the pseudoinverse" in n for n in spec["layout"]["meta"]["notes"]
    )


def test_the_tables_task_points_show_round_off_as_zero():
    """A leg's target labelled in the table as the path's box shows it: a coordinate of
    round-off (an arm's rz of -9.18e-18) as 0, never "-0"."""
    from jik.app.dashboard.table import _point

    assert _point([0.3, -9.18e-18, -4.06e-33, 1.5, -0.0]) == "(0.3, 0, 0, 1.5, 0)"
    assert _point([1e-13, 2e-13]) == "(0, 0)" and _point([0.001234, 5.0]) == "(0.00123, 5)"


# -- the posture inverse's rest x_rest -------------------------------------------------------------


def _posture(robot: str = "manipulator2", **patch):
    return updated_state(default_state(robot), {"algorithms": THREE, **patch})


def test_the_rest_shows_only_with_the_posture_inverse_over_x0_s_ranges():
    """One slider per joint variable, over the same range as x0's sliders (Manipulator 2 has
    no joint limits), at the default in force (x0 here: it has no home), and a button
    'rest = x0'; none without posture."""
    assert not [c for c in controls(default_state()) if c.key.startswith(REST)]
    state = _posture()
    spec = controls(state)
    sliders = [c for c in spec if c.key.startswith(f"{REST}.")]
    x0 = {c.key.removeprefix("x0."): c for c in spec if c.key.startswith("x0.")}
    assert [c.key for c in sliders] == [f"{REST}.{i}" for i in range(3)]
    for c in sliders:
        twin = x0[c.key.rpartition(".")[2]]
        assert (c.minimum, c.maximum, c.step, c.kind) == (
            twin.minimum,
            twin.maximum,
            twin.step,
            "slider",
        )
    assert [(c.label, c.value) for c in spec if c.kind == "preset"] == [("rest = x0", "x0")]
    values = control_values(state)
    assert [values[c.key] for c in sliders] == list(state.x0)
    assert "rest" not in state.algorithm_parameters  # (the default: it follows x0)
    moved = updated_state(state, {"x0.0": 0.25})
    assert control_values(moved)[f"{REST}.0"] == 0.25


def test_setting_the_rest_changes_the_posture_run_and_only_it():
    """A rest coordinate moved: the posture inverse's run changes, the others are the same bit
    for bit (solved again without a cache), and the posture run is the engine's with that
    rest; the verdict names the rest."""
    state = _posture(cycles=2)
    before = compute(state)
    moved = updated_state(state, {f"{REST}.1": 0.5})
    assert moved.algorithm_parameters == {"gain": 1.0, "rest": (0.0, 0.5, state.x0[2])}
    assert cache_key(moved, "posture") != cache_key(state, "posture")
    assert [cache_key(moved, a) for a in THREE[:2]] == [cache_key(state, a) for a in THREE[:2]]
    after = compute(moved)
    for a in ("pseudoinverse", "extended"):
        for field in ("theta", "x", "y", "error", "drift"):
            assert np.array_equal(getattr(after.runs[a], field), getattr(before.runs[a], field))
    shift = np.abs(after.runs["posture"].x[-1] - before.runs["posture"].x[-1]).max()
    assert shift > 0.1
    np.testing.assert_array_equal(state_inverse(moved, "posture").rest, [0.0, 0.5, state.x0[2]])
    said = " ".join(s["text"] for s in verdict(after) if s["algorithm"] == "posture")
    assert f"x_rest = (0, 0.5, {state.x0[2]:.4g}) (set)" in said
    said = " ".join(s["text"] for s in verdict(before) if s["algorithm"] == "posture")
    assert f"x_rest = x0 (0, 0, {state.x0[2]:.4g})" in said


def test_rest_x0_is_the_default_and_a_rest_set_stays_set():
    """'rest = x0' on a robot without home is the default, which follows x0 (null too); a rest
    set stays when x0 moves, even once x0 has moved onto it (it was dropped as the default then,
    and followed x0 from there)."""
    state = _posture()
    moved = updated_state(state, {f"{REST}.1": 0.5})
    assert updated_state(moved, {REST: "x0"}) == state
    assert updated_state(moved, {"algorithm_parameters": {"rest": None}}) == state
    assert updated_state(moved, {"x0.2": 1.0}).algorithm_parameters["rest"][2] == state.x0[2]
    onto = updated_state(moved, {"x0.1": 0.5})
    assert onto.algorithm_parameters["rest"] == tuple(onto.x0)
    assert updated_state(onto, {"x0.1": 0.2}).algorithm_parameters["rest"][1] == 0.5


def test_a_rest_equal_to_the_home_is_the_default():
    """On an arm with a home (the default rest), a rest set to it is the default: the state
    holds no copy; 'rest = x0' there sets the rest to the start's values."""
    pytest.importorskip("yourdfpy")
    state = _posture("panda")
    home = list(state_kinematics(state).home)
    assert "rest" not in updated_state(state, {REST: home}).algorithm_parameters
    x0 = updated_state(state, {"x0.0": 0.5})
    assert updated_state(x0, {REST: "x0"}).algorithm_parameters["rest"] == tuple(x0.x0)


@pytest.mark.parametrize(
    ("patch", "field", "words"),
    [
        ({REST: [0.0, 0.0]}, REST, "give 3 entries, one per joint variable (x1, x2, x3), got 2"),
        ({"algorithm_parameters": {"rest": [0.0, 0.0, 0.5, 1.0]}}, REST, "got 4"),
        ({REST: [0.0, 0.0, float("nan")]}, f"{REST}.2", "Input should be a finite number"),
        ({f"{REST}.0": float("inf")}, f"{REST}.0", "Input should be a finite number"),
        ({f"{REST}.2": 7.0}, f"{REST}.2", "rest x3 must be in [-3.14159, 6.28319]"),
        ({REST: [0.0, -3.5, 0.0]}, f"{REST}.1", "(the range of the rest's sliders), got -3.5"),
        ({f"{REST}.3": 0.0}, f"{REST}.3", "rest has 3 coordinates"),
        ({"algorithm_parameters": {"rest": ["a"]}}, REST, "Input should be a valid number"),
    ],
)
def test_a_bad_rest_is_refused_naming_its_field(patch, field, words):
    from jik.app.dashboard.patch import parse_patch

    state = _posture()
    with pytest.raises(InvalidInputError) as refused:
        updated_state(state, parse_patch(patch) if "." in next(iter(patch)) else patch)
    assert refused.value.field == field
    # (the message writes the field as every message does: algorithm_parameters.rest[2])
    assert str(refused.value).startswith(f"{field_text(field)}: ") and words in str(refused.value)


def test_the_session_api_refuses_a_bad_rest_naming_it(client):
    """A session's change with a rest outside the box: 422 naming the coordinate, the state
    stays."""
    session = client.post("/api/sessions", json={"state": {"algorithms": THREE}}).json()
    url = f"/api/sessions/{session['id']}/state"
    bad = client.post(url, json={f"{REST}.2": 9.0})
    assert bad.status_code == 422
    assert [d["msg"] for d in bad.json()["detail"]] == [
        f"{REST}[2]: rest x3 must be in [-3.14159, 6.28319] (the range of the rest's sliders), "
        "got 9"
    ]
    junk = client.post(url, json={"algorithm_parameters": {"rest": {}}})  # (not a number list)
    assert [d["msg"] for d in junk.json()["detail"]] == [f"{REST}: Input should be a valid number"]
    ok = client.post(url, json={f"{REST}.2": 1.0})
    assert ok.status_code == 200 and ok.json()["state"]["algorithm_parameters"]["rest"][2] == 1.0


def test_the_rest_is_dropped_with_the_posture_inverse_and_with_the_robot():
    moved = updated_state(_posture(), {f"{REST}.1": 0.5})
    assert updated_state(moved, {"algorithms": ["pseudoinverse"]}).algorithm_parameters == {}
    other = updated_state(moved, {"robot": "manipulator1"})
    assert other.algorithm_parameters == {"gain": 1.0} and other.algorithms == moved.algorithms


def test_the_api_and_the_dashboard_take_the_same_default_rest():
    """One rule, the engine's default_rest: the robot's home, else the run's start x0."""
    from jik.app.compute.requests import solve_batch_json
    from jik.app.compute.schemas import SolveRequest
    from jik.app.dashboard.algorithms import posture_rest
    from jik.engine.algorithm_registry import default_rest

    state = updated_state(_posture(), {"x0.0": 0.25})
    kin = state_kinematics(state)
    assert posture_rest(state, kin) == default_rest(kin, state.x0) == (list(state.x0), "x0")
    body = {"robot": {"name": "manipulator2"}, "algorithm": "posture", "x0": list(state.x0)}
    (api,) = solve_batch_json([SolveRequest.model_validate({**body, "target": [1.0, 1.5]})])
    assert json.loads(api)["algorithm_parameters"]["rest"] == list(state.x0)
    np.testing.assert_array_equal(state_inverse(state, "posture").rest, state.x0)


def test_export_carries_the_rest_used():
    from jik.app.dashboard.export import export_csv, export_json

    result = compute(updated_state(_posture(cycles=1), {f"{REST}.1": 0.5}))
    run = export_json(result)["runs"]["posture"]
    assert run["rest"] == [0.0, 0.5, result.state.x0[2]] and run["rest_from"] == "set"
    assert "rest" not in export_json(result)["runs"]["pseudoinverse"]
    line = f"# posture rest x_rest (set): 0.0, 0.5, {result.state.x0[2]!r}"
    assert line in export_csv(result).splitlines()


@pytest.fixture(scope="module")
def panda():
    pytest.importorskip("yourdfpy")
    return updated_state(default_state("panda"), {"algorithms": ["pseudoinverse", "posture"]})


def test_an_arm_s_rest_is_within_its_joint_limits_and_defaults_to_its_home(panda):
    """The Panda: the rest sliders span its joint limits, start at its home; 'rest = home'
    sets the default back; a coordinate beyond a limit is refused naming the limits."""
    from jik.engine.arms import ARMS
    from jik.engine.registry import make_inverse
    from jik.engine.robot_spec import robot_from_dict

    kin = robot_from_dict({"name": "panda", "task": "pose"}).kinematics
    assert list(make_inverse(kin, "posture", x0=[0.1] * 7).rest) == list(ARMS["panda"].home)
    spec = controls(panda)
    sliders = [c for c in spec if c.key.startswith(f"{REST}.")]
    assert [(c.minimum, c.maximum) for c in sliders] == [tuple(b) for b in kin.limits]
    values = control_values(panda, spec)
    assert [values[c.key] for c in sliders] == list(ARMS["panda"].home)
    home = next(c for c in spec if c.id == "ctl-preset-rest-home")
    assert home.value == list(ARMS["panda"].home) and home.label == "rest = home"
    moved = updated_state(panda, {f"{REST}.0": 0.5})
    assert updated_state(moved, {REST: home.value}) == panda
    shown = {c.key: values[c.key] for c in sliders}
    assert updated_state(moved, shown) == panda  # (what the sliders show, sent back)
    with pytest.raises(InvalidInputError) as refused:
        updated_state(panda, {f"{REST}.3": 0.0})
    assert refused.value.field == f"{REST}.3"
    assert "must be in [-3.0718, -0.0698] (the joint limits of the" in str(refused.value)


def test_a_rest_outside_a_chain_s_joint_limits_is_refused_in_the_engine_s_words():
    """A planar chain with limits: a rest outside the limits is refused at its coordinate with
    the words the engine (and so the REST API) uses; the default rest at a start outside the
    limits (the start) is not."""
    from jik.engine.robot_spec import robot_from_dict

    chain = {**CHAIN, "limits": [[-1, 1], [None, 1.2], [-3, 3]]}
    state = updated_state(default_state(), {"robot": "planar_chain", "robot_definition": chain})
    state = updated_state(state, {"algorithms": ["pseudoinverse", "posture"]})
    with pytest.raises(InvalidInputError) as engine:
        robot_from_dict(chain).inverse("posture", algorithm_parameters={"rest": [0, 2, 0]})
    with pytest.raises(InvalidInputError) as refused:
        updated_state(state, {f"{REST}.1": 2.0})
    assert refused.value.field == f"{REST}.1" and engine.value.field == "rest.1"
    assert str(refused.value) == f"{REST}[1]: {engine.value}"
    assert "at most 1.2 (the joint limits of the planar_chain), got 2" in str(refused.value)
    outside = updated_state(state, {"x0": [1.5, 0.2, 0.3]})
    assert list(state_inverse(outside, "posture").rest) == [1.5, 0.2, 0.3]


def test_each_algorithms_label_is_its_long_name_and_short_its_symbol():
    """The controls and the key show ``label`` (the long name), the table's headers and the
    task-space plot's key ``short``: the short name is part of the long one, never the reverse
    (DLS's label was "DLS" and its short "damped least squares J^DLS")."""
    for a, style in STYLES.items():
        assert style.short.split(" (")[0] in style.label, a
        assert len(style.short) < len(style.label), a
    assert STYLES["damped"].label == "damped least squares J^DLS"
    assert STYLES["weighted"].short == "J^W#"


@pytest.mark.parametrize("limits", [[[-1.0, 1.0]] * 7, 3.0])
def test_the_weighted_inverse_s_limits_are_the_robot_s_on_the_dashboard(client, limits):
    """The REST API's weighted inverse takes ``limits``; the dashboard's keeps to the robot's,
    and says so at the field (not "Input should be a valid number")."""
    pytest.importorskip("yourdfpy")
    state = {"robot": "panda", "algorithms": ["pseudoinverse", "weighted"]}
    session = client.post("/api/sessions", json={"state": state}).json()
    bad = client.post(
        f"/api/sessions/{session['id']}/state", json={"algorithm_parameters": {"limits": limits}}
    )
    assert bad.status_code == 422
    assert [d["msg"] for d in bad.json()["detail"]] == [
        "algorithm_parameters.limits: the dashboard's weighted inverse keeps to the robot's own "
        "joint limits; give them in the robot's definition (limits, or a URDF's joints)"
    ]


def test_a_discrete_target_run_says_what_the_engine_and_the_rest_api_say():
    """A single target in discrete mode: each algorithm's run in the dashboard ends where the
    engine's solve (the REST API's /solve) ends, and with the same message, tolerance and all
    ("converged: task error 7.1e-11 < 1e-10 after 34 iterations"), as in continuous mode."""
    from jik.engine.solver import solve

    state = updated_state(default_state(), {"robot": "planar_chain", "robot_definition": CHAIN})
    change = {"task": "target", "target": [1.5, 1.0], "mode": "discrete", "gamma": 0.5}
    state = updated_state(state, {**change, "algorithms": ["pseudoinverse", "damped", "posture"]})
    result = compute(state)
    for name, run in result.runs.items():
        res = solve(state_inverse(state, name), state.x0, state.target, gamma=0.5, mode="discrete")
        assert res.success and res.message.startswith("converged: task error ")
        np.testing.assert_array_equal(run.x[-1], res.x)
        assert run.message == res.message
