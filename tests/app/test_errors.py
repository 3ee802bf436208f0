"""Bad input: HTTP 422 whose message names the field and the problem; never a 5xx."""

from __future__ import annotations

import pytest

from tests.app.conftest import TABLE1_PATH, X0_M2, messages, solve_body


def _rep(**over) -> dict:
    body = {
        "robot": {"name": "manipulator2"},
        "algorithm": "pseudoinverse",
        "x0": X0_M2,
        "path": TABLE1_PATH,
    }
    body.update(over)
    return body


@pytest.mark.parametrize(
    ("body", "expected"),
    [
        (solve_body(x0=[0.0, 0.0]), "x0: must have 3 components (p of manipulator2), got 2"),
        (solve_body(target=[1.0, 1.0, 1.0]), "target: must have 2 components (r of manipulator2)"),
        (solve_body(x0=[]), "x0: must have 3 components (p of manipulator2), got 0"),
        (solve_body(x0="abc"), "x0: Input should be a valid list"),
        (solve_body(robot={"name": "puma560"}), "robot: unknown name 'puma560'; choose one of"),
        (solve_body(robot={"l": 1.0}), "robot: give the robot, with a name among"),
        (
            solve_body(robot="manipulator2"),
            """robot: must be an object such as {"name": "manipulator2"}, not the string""",
        ),
        (
            solve_body(robot="puma560"),
            """robot: must be an object such as {"name": "manipulator1"}, not the string 'puma""",
        ),
        (solve_body(robot={"name": "manipulator2", "l": 9}), "robot.l: Input should be less than"),
        (solve_body(robot={"name": "manipulator2", "q": 1}), "robot.q: unknown field"),
        (solve_body(algorithm="transpose"), "algorithm: Input should be 'pseudoinverse', 'ext"),
        (
            solve_body(algorithm="extended", augmentation={"name": "nope"}),
            "augmentation: unknown name 'nope'",
        ),
        (
            solve_body(algorithm="extended", augmentation={"name": "e2_optimal"}),
            "augmentation: unknown name 'e2_optimal'; choose one of",
        ),
        (solve_body(gamma=0), "gamma: Input should be greater than or equal to 0.000001"),
        (solve_body(gamma=-1.5), "gamma: Input should be greater than or equal to 0.000001"),
        (solve_body(mode="discrete", gamma=2.5), "gamma: must be < 2 in discrete mode"),
        (solve_body(mode="sideways"), "mode: Input should be 'continuous' or 'discrete'"),
        (solve_body(tolerance=0), "tolerance: Input should be greater than or equal to 0.000"),
        (solve_body(max_iterations=0), "max_iterations: Input should be greater than or equal"),
        (solve_body(max_iterations=10**7), "max_iterations: Input should be less than or equal"),
        (solve_body(extra=1), "extra: unknown field; remove it"),
        (_rep(cycles=1001), "cycles: Input should be less than or equal to 1000"),
        (_rep(cycles=0), "cycles: Input should be greater than or equal to 1"),
        (_rep(path=[[0.0, 1.0]] * 101), "path: give at most 100 entries, got 101"),
        (_rep(path=[]), "path: give at least 1 entry, got 0"),
        (_rep(path=[[1.0, 1.0], [1.0, 2.0, 3.0]]), "path[1]: must have 2 components"),
    ],
)
def test_bad_input_names_the_field(api, body, expected):
    url = "/repeatability" if "path" in body else "/solve"
    r = api.post(url, json=body)
    assert r.status_code == 422, r.text
    assert any(m.startswith(expected) for m in messages(r)), messages(r)


@pytest.mark.parametrize(
    ("raw", "expected"),
    [
        ('"x0": [0, 0, NaN]', "x0[2]: Input should be a finite number"),
        ('"x0": [0, Infinity, 1]', "x0[1]: Input should be a finite number"),
        ('"x0": [0, -Infinity, 1]', "x0[1]: Input should be a finite number"),
        ('"x0": [0, 0, 1], "gamma": NaN', "gamma: Input should be a finite number"),
        ('"x0": [0, 0, 1], "robot": {"name": "manipulator2", "l": NaN}', "robot.l: Input should"),
    ],
)
def test_nan_and_inf_are_rejected(api, raw, expected):
    """JSON extensions NaN / Infinity parse in Python; they must still be refused."""
    base = '{"robot": {"name": "manipulator2"}, "algorithm": "pseudoinverse", "target": [1, 1]'
    if '"robot"' in raw:
        base = '{"algorithm": "pseudoinverse", "target": [1, 1]'
    r = api.post(
        "/solve", content=base + ", " + raw + "}", headers={"content-type": "application/json"}
    )
    assert any(m.startswith(expected) for m in messages(r)), messages(r)


def test_nan_in_path_is_rejected(api):
    raw = (
        '{"robot": {"name": "manipulator2"}, "algorithm": "extended", "x0": [0, 0, 1.5],'
        ' "path": [[1, 1], [NaN, 2]]}'
    )
    r = api.post("/repeatability", content=raw, headers={"content-type": "application/json"})
    assert messages(r) == ["path[1][0]: Input should be a finite number"]


def test_algorithmically_singular_start(api):
    """[J; dh] singular at x0 (dh K = 0 at x1 = -b/a for (36)): 422 naming x0."""
    body = {
        "robot": {"name": "manipulator1"},
        "algorithm": "extended",
        "augmentation": {"name": "e2_optimal", "a": 1.0, "b": 0.0},
        "x0": [0.0, 0.5, 1.0],
        "target": [0.8, 1.5],
    }
    (msg,) = messages(api.post("/solve", json=body))
    assert msg.startswith("x0: the extended Jacobian [J; dh] of manipulator1")
    assert "algorithmic singularity" in msg and "at x = (0, 0.5, 1)" in msg
    rep = {k: v for k, v in body.items() if k != "target"} | {"path": [[0.8, 1.5]]}
    (msg,) = messages(api.post("/repeatability", json=rep))
    assert msg.startswith("x0: ") and "algorithmic singularity" in msg


def test_augmentation_parameter_refused_by_the_registry(api):
    """C1 = 0 makes (32) vanish identically: the registry's message, under the field."""
    body = solve_body(
        robot={"name": "manipulator1"},
        x0=[0.5, 0.5, 1.0],
        algorithm="extended",
        augmentation={"name": "e1_optimal", "C1": 0.0},
    )
    (msg,) = messages(api.post("/solve", json=body))
    assert msg.startswith("augmentation: C1 must be nonzero")


@pytest.mark.parametrize("algorithm", ["pseudoinverse", "damped"])
def test_a_map_given_to_an_algorithm_without_one_is_refused(api, algorithm):
    """A map, good or bad (C1 = 0; a formula that does not parse), is the extended inverse's:
    given with another algorithm, the request is refused at ``augmentation``."""
    body = solve_body(
        robot={"name": "manipulator1"},
        x0=[0.5, 0.5, 1.0],
        algorithm=algorithm,
        augmentation={"name": "e1_optimal", "C1": 0.0},
    )
    takes = f"augmentation: the {algorithm} inverse takes none (the extended inverse does)"
    assert messages(api.post("/solve", json=body)) == [takes]
    arm = {"name": "planar_chain", "joints": "RRR", "lengths": [1.0, 0.8, 0.6]}
    rep = {
        "robot": arm,
        "augmentation": {"name": "formula", "h": "x1 +"},
        "algorithm": algorithm,
        "x0": [0.3, 1.0, 1.0],
        "path": [[1.0, 1.3], [1.0, 1.7]],
    }
    assert messages(api.post("/repeatability", json=rep)) == [takes]


def test_malformed_json(api):
    r = api.post("/solve", content="{not json", headers={"content-type": "application/json"})
    assert r.status_code == 422
    assert r.json()["detail"][0]["msg"].startswith("body: not valid JSON at character 1: ")


def test_missing_fields(api):
    """The robot first (it decides the lengths of the rest), then every other missing field."""
    assert messages(api.post("/solve", json={})) == ["robot: Field required"]
    msgs = messages(api.post("/solve", json={"robot": {"name": "manipulator2"}}))
    assert msgs == ["algorithm: Field required"]  # (x0 and target: the robot's by default)


def test_wrong_method_and_unknown_path_are_4xx(api):
    assert api.get("/solve").status_code == 405
    assert api.get("/nowhere").status_code == 404


def test_coordinates_are_bounded(api):
    """Finite but absurd coordinates are refused before they reach the engine."""
    (msg,) = messages(api.post("/solve", json=solve_body(x0=[0.0, 1e17, 1.0])))
    assert msg == "x0[1]: Input should be less than or equal to 1000"
    body = {**_rep(), "path": [[1.0, -1e175]]}
    (msg,) = messages(api.post("/repeatability", json=body))
    assert msg == "path[0][1]: Input should be greater than or equal to -1000"


@pytest.mark.parametrize("path", ["/solve", "/repeatability", "/synthesize"])
def test_oversized_body_is_413_with_a_message(api, path):
    body = '{"pad": "' + "x" * (2 << 20) + '"}'
    r = api.post(path, content=body, headers={"content-type": "application/json"})
    assert r.status_code == 413
    assert "larger than the limit of 1048576 bytes" in r.json()["detail"]


@pytest.mark.parametrize("path", ["/solve", "/repeatability", "/synthesize"])
def test_oversized_body_without_a_length_is_413(api, path):
    def chunks():  # sent chunked, without Content-Length
        for _ in range(40):
            yield b"x" * 65536

    r = api.post(path, content=chunks(), headers={"content-type": "application/json"})
    assert r.status_code == 413
    assert "more than 1048576 bytes" in r.json()["detail"]


DEEP = b"[" * 50_000 + b"]" * 50_000


@pytest.mark.parametrize("path", ["/solve", "/repeatability", "/synthesize", "/api/sessions"])
def test_a_body_nested_too_deep_is_422_not_500(api, path):
    """A JSON nested past Python's recursion limit is the client's bad input (it was a 500
    with the exception's text)."""
    r = api.post(path, content=DEEP, headers={"content-type": "application/json"})
    assert r.status_code == 422, r.text
    (error,) = r.json()["detail"]
    assert error["loc"] == ["body"] and "nested too deep" in error["msg"]
    assert "Recursion" not in r.text


def test_bad_session_changes_are_422_naming_the_field(api):
    session = api.post("/api/sessions", json={"state": {}}).json()["id"]
    url = f"/api/sessions/{session}/state"
    for body, field in [
        ({"robot_parameters": "abc"}, "robot_parameters"),
        ({"robot_parameters": 5}, "robot_parameters"),
        ({"path": 5}, "path"),
        ({"augmentation_parameters": [1, 2]}, "augmentation_parameters"),
    ]:
        r = api.post(url, json=body)
        assert r.status_code == 422, (body, r.text)
        assert r.json()["detail"][0]["loc"] == ["body", field]
    r = api.post(url, content=DEEP, headers={"content-type": "application/json"})
    assert r.status_code == 422 and "nested too deep" in r.text
    api.delete(f"/api/sessions/{session}")


@pytest.mark.parametrize(
    ("body", "says"),
    [
        (b'{"robot": ', "not valid JSON at character 10"),
        (b'{"robot": "\xff"}', "not UTF-8"),
        (b'{"cycles": ' + b"1" * 5000 + b"}", "it holds an integer of more than 4300 digits"),
    ],
)
def test_a_body_that_is_not_json_says_why(api, body, says):
    """(FastAPI answered these with an undocumented 400 'There was an error parsing the body'.)"""
    r = api.post("/repeatability", content=body, headers={"content-type": "application/json"})
    assert r.status_code == 422, r.text
    assert r.json()["detail"][0]["loc"] == ["body"] and says in r.text


@pytest.mark.parametrize(
    ("over", "field"),
    [
        ({"gamma": True}, "gamma"),
        ({"tolerance": False}, "tolerance"),
        ({"max_iterations": True}, "max_iterations"),
        ({"x0": [0.0, True, 1.5]}, "x0[1]"),
        ({"robot": {"name": "manipulator2", "l": True}}, "robot.l"),
        ({"gamma": "2"}, "gamma"),
    ],
)
def test_a_boolean_or_a_string_is_no_number(api, over, field):
    """(Booleans were taken as 0 and 1, and numeric strings as numbers.)"""
    (msg,) = messages(api.post("/solve", json=solve_body(**over)))
    assert msg.startswith(f"{field}: Input should be a valid")


def _chain_urdf(joints: int) -> str:
    links = "".join(f'<link name="l{i}"/>' for i in range(joints + 1))
    moving = "".join(
        f'<joint name="j{i}" type="revolute"><parent link="l{i}"/><child link="l{i + 1}"/>'
        f'<origin xyz="0.1 0 0"/><axis xyz="0 0 1"/>'
        f'<limit lower="-3" upper="3" effort="1" velocity="1"/></joint>'
        for i in range(joints)
    )
    return f'<robot name="long">{links}{moving}</robot>'


@pytest.mark.parametrize("path", ["/solve", "/repeatability"])
def test_a_robot_past_the_joint_cap_is_refused_by_the_cap(api, path):
    """A 400-joint URDF chain was answered "x0 must have 400 components", which no x0 can have
    (x0 takes at most 16): the answer names the cap and how to stay under it, before the
    robot is built."""
    robot = {"name": "urdf", "urdf": _chain_urdf(400), "end_link": "l400", "task": "xy"}
    body = {"robot": robot, "algorithm": "pseudoinverse", "x0": [0.1] * 16}
    body.update({"target": [1.0, 1.0]} if path == "/solve" else {"path": [[1.0, 1.0]]})
    (msg,) = messages(api.post(path, json=body))
    assert msg == (
        "robot: 400 of the 400 movable joints on the chain from 'l0' to 'l400' would be "
        "active; at most 16 can be (name at most that many in active_joints; the others stay "
        "at 0 or at their locked values)"
    )


def test_an_unknown_active_joint_is_named_with_its_value(api):
    """The engine's "active_joints[0]: 'j9' is not ..." loses its field's prefix to the
    request's, and keeps nothing of it ("robot.active_joints[0]: = 'j9'" before)."""
    robot = {"name": "urdf", "urdf": _chain_urdf(3), "end_link": "l3", "active_joints": ["j9"]}
    (msg,) = messages(api.post("/kinematics", json={"robot": robot, "x": [0.1]}))
    assert msg.startswith("robot.active_joints[0]: 'j9' is not a movable joint on the chain")


def test_a_missing_atlas_job_says_why_it_is_missing(api):
    """An id of an earlier server process is a job lost in the restart; one of this server's
    was cancelled or dropped; anything else was never an id (all were answered "it was
    cancelled, or ended and expired")."""
    from jik.app.compute.atlas_jobs import AtlasJobs

    assert api.get("/atlas/x").status_code == 404
    ours = api.app.state.atlas_jobs.run
    earlier = AtlasJobs().run
    while earlier == ours:
        earlier = AtlasJobs().run
    token = "A" * 16
    for job_id, why in [
        (
            earlier + token,
            "the server restarted since it was started, and atlas jobs live in "
            "the server's memory: start it again",
        ),
        (
            ours + token,
            "it was cancelled, or it ended and was dropped (600 s after, or sooner to make "
            "room: the server keeps 16 jobs)",
        ),
        ("nosuchjob", "no job of this server has had this id"),
    ]:
        r = api.get(f"/atlas/{job_id}")
        assert r.status_code == 404
        assert r.json() == {"detail": f"no atlas job {job_id!r}: {why}"}


@pytest.mark.parametrize("path", ["/solve", "/repeatability"])
def test_an_overflow_at_the_start_is_called_an_overflow(api, path):
    """k(x0) = exp(800) is past the floating-point range: the answer says so (it was "J J^T
    is singular", and in a session "y_d contains NaN or infinite values")."""
    robot = {"name": "formula", "variables": ["x1", "x2", "x3"], "task": ["exp(x1) + x3", "x2"]}
    body = {"robot": robot, "algorithm": "pseudoinverse", "x0": [800.0, 0.5, 0.5]}
    body.update({"target": [1.0, 1.0]} if path == "/solve" else {"path": [[1.0, 1.0]]})
    (msg,) = messages(api.post(path, json=body))
    assert msg == (
        "x0: the kinematics are not finite at the start: k(x0) = (inf, 0.5), its Jacobian not "
        "finite (the task is undefined there, or overflows); choose a start where both are "
        "finite"
    )


@pytest.mark.parametrize("path", ["/solve", "/repeatability", "/atlas", "/kinematics"])
@pytest.mark.parametrize("raw", [b"[1, 2, 3]", b"3", b'"robot"', b"true"])
def test_a_body_that_is_no_json_object_says_so(api, path, raw):
    """An array or a scalar has no robot to choose by: the body is named, not the robot."""
    r = api.post(path, content=raw, headers={"content-type": "application/json"})
    assert r.status_code == 422, r.text
    assert r.json()["detail"] == [
        {"loc": ["body"], "msg": "body: the body must be a JSON object", "type": "model_type"}
    ]


def test_a_refusal_names_its_field_once_and_as_every_message_does(api):
    """The engine's ``lengths[1] must be positive`` and ``rest must have shape`` under the
    request's field: the field is the message's prefix, not repeated after it; indices in
    brackets (``algorithm_parameters.rest[1]``), ``loc`` as FastAPI's (an index a number)."""
    chain = {"name": "planar_chain", "joints": "RRR", "lengths": [1.0, -0.8, 0.6]}
    r = api.post(
        "/solve",
        json={"robot": chain, "algorithm": "pseudoinverse", "x0": X0_M2, "target": [1, 1]},
    )
    assert messages(r) == ["robot.lengths[1]: must be positive (a link's length), got -0.8"]
    assert r.json()["detail"][0]["loc"] == ["body", "robot", "lengths", 1]
    rest = {"rest": [0.0, 1.0]}
    r = api.post("/solve", json=solve_body(algorithm="posture", algorithm_parameters=rest))
    assert messages(r) == [
        "algorithm_parameters.rest: must have shape (..., 3) (a vector of length 3), got shape (2,)"
    ]
    chain = {"name": "planar_chain", "joints": "RRR", "lengths": [1, 1, 1], "limits": [[-1, 1]] * 3}
    rest = {"rest": [0.0, 2.0, 0.0]}
    body = {"robot": chain, "algorithm": "posture", "x0": [0.1, 0.2, 0.3], "target": [1, 1]}
    r = api.post("/solve", json={**body, "algorithm_parameters": rest})
    assert messages(r)[0].startswith("algorithm_parameters.rest[1]: rest x2 must be")
    assert r.json()["detail"][0]["loc"] == ["body", "algorithm_parameters", "rest", 1]


def test_an_engine_error_is_named_by_its_field_not_its_words():
    """The request's field of an engine error is the error's field (the engine's name made the
    request's: tol -> tolerance), whatever its message starts with."""
    from jik.app.compute.requests import engine_error
    from jik.engine.exceptions import InvalidInputError

    err = engine_error(InvalidInputError("the tolerance tol must be > 0, got -1", "tol"))
    assert (err.field, str(err)) == (
        "tolerance",
        "tolerance: the tolerance tol must be > 0, got -1",
    )
    err = engine_error(InvalidInputError("y_d contains NaN or infinite values", "y_d"))
    assert str(err) == "target: contains NaN or infinite values"
    err = engine_error(InvalidInputError("x0 is fine; gamma is not", "chunk"))
    assert err.field == "request"
