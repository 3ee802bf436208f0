"""One integer rule on every route: JSON Schema's "integer" (2 and 2.0), never 2.5, true or "2".

The OpenAPI document types these fields ``integer``; JSON cannot tell 2 from 2.0, and JSON Schema
counts both as integers, so every route takes both (the fuzzer's positive cases include 2.0).
"""

from __future__ import annotations

import pytest

from tests.app.conftest import solve_body

LOOP = [[0.0, 1.0], [1.0, 1.0], [1.0, 2.0], [0.0, 2.0]]
#: A key no request takes: the body is refused (422) before anything is computed, and the
#: answer lists every other error of the body too.
_STOP = {"no_such_field": 1}

_REPEATABILITY = {**solve_body(), "path": LOOP}
del _REPEATABILITY["target"]
_SYNTHESIZE = {"robot": {"name": "manipulator2"}}
_ATLAS = {"robot": {"name": "manipulator2"}, "path": LOOP, "starts": 6, "arc": [-1.0, 1.0]}

#: (path, body, integer field) of every route that takes an integer in its body.
ROUTES = [
    ("/solve", solve_body(), "max_iterations"),
    ("/repeatability", _REPEATABILITY, "cycles"),
    ("/repeatability", _REPEATABILITY, "max_iterations"),
    ("/synthesize", _SYNTHESIZE, "nodes"),
    ("/synthesize", _SYNTHESIZE, "degree"),
    ("/synthesize", _SYNTHESIZE, "grid"),
    ("/atlas", _ATLAS, "starts"),
    ("/atlas", _ATLAS, "cycles"),
    ("/atlas", _ATLAS, "seed"),
    ("/api/sessions/{id}/atlas", {}, "starts"),
    ("/api/sessions/{id}/atlas", {}, "cycles"),
]


@pytest.fixture(scope="module")
def session(api):
    session = api.post("/api/sessions", json={"state": {}}).json()["id"]
    yield session
    api.delete(f"/api/sessions/{session}")


def _fields(response) -> list[str]:
    assert response.status_code == 422, response.text
    return [".".join(str(p) for p in e["loc"][1:]) for e in response.json()["detail"]]


@pytest.mark.parametrize(("path", "body", "field"), ROUTES)
def test_a_whole_float_is_an_integer(api, session, path, body, field):
    r = api.post(path.format(id=session), json={**body, field: 3.0, **_STOP})
    assert _fields(r) == ["no_such_field"], r.text


@pytest.mark.parametrize(("path", "body", "field"), ROUTES)
@pytest.mark.parametrize("value", [2.5, True, "2"])
def test_a_fraction_a_boolean_or_a_string_is_no_integer(api, session, path, body, field, value):
    r = api.post(path.format(id=session), json={**body, field: value})
    (error,) = r.json()["detail"]
    assert r.status_code == 422 and error["loc"][1:] == [field], r.text
    assert error["msg"].startswith(f"{field}: Input should be a valid integer"), r.text


def test_the_session_state_takes_the_same_integers(api, session):
    url = f"/api/sessions/{session}/state"
    r = api.post(url, json={"cycles": 2.0, "max_iterations": 300.0})
    assert r.status_code == 200, r.text
    state = r.json()["state"]
    assert state["cycles"] == 2 and state["max_iterations"] == 300
    for field in ("cycles", "max_iterations"):
        for value in (2.5, True, "2"):
            r = api.post(url, json={field: value})
            assert r.status_code == 422 and r.json()["detail"][0]["loc"] == ["body", field]


@pytest.mark.parametrize("route", ["functionals", "functionals/cancel"])
def test_the_second_phase_takes_the_same_integers(api, session, route):
    """A generation of 2.0 is the integer 2 (a 409: not the generation shown, not a 422)."""
    url = f"/api/sessions/{session}/{route}"
    r = api.post(url, json={"generation": 1000.0})
    assert r.status_code == 409 and "generation 1000 " in r.text, r.text
    for value in (2.5, True, "2"):
        r = api.post(url, json={"generation": value})
        assert r.status_code == 422 and r.json()["detail"][0]["loc"] == ["body", "generation"]


#: A planar chain with p - r = 2, whose E2-synthesized maps take the joints of their frame.
_CHAIN = {"name": "planar_chain", "joints": "RRRR", "lengths": [1.0, 1.0, 1.0, 1.0]}


@pytest.mark.parametrize("value", [2.5, True, "2"])
def test_a_maps_frame_axes_follow_the_same_rule(api, value):
    """A map's ``frame_axes`` (in a robot's request, as in /synthesize's own) are integers by
    the one rule: a boolean or a string is refused, as 2.5 is."""
    body = solve_body(robot=_CHAIN, algorithm="extended", x0=[0.1, 0.2, 0.3, 0.4])
    body["augmentation"] = {"name": "e2_synthesized", "frame_axes": [value]}
    r = api.post("/solve", json=body)
    assert r.status_code == 422, r.text
    (error,) = r.json()["detail"]
    assert error["loc"][-2:] == ["frame_axes", 0], r.text
    assert error["msg"].startswith("augmentation.frame_axes[0]: Input should be a valid integer")
