"""The OpenAPI document says exactly what the server takes and answers: each
robot's vector lengths, maps and variables; every error a check before the routes can answer;
the methods of a path in a 405's Allow; JSON Schema's integers; a gamma the solver can use."""

from __future__ import annotations

import pytest

from jik.app.compute.schemas import USER_ROBOT_MODELS
from jik.engine.registry import ROBOTS

from .conftest import solve_body


@pytest.fixture(scope="module")
def document(api):
    return api.get("/openapi.json").json()


def _variants(document, path: str) -> dict[str, dict]:
    """The body's schema for each robot (the members of its oneOf), by robot name."""
    schemas = document["components"]["schemas"]
    body = document["paths"][path]["post"]["requestBody"]["content"]["application/json"]
    members = body["schema"]["oneOf"]
    out = {}
    for ref in members:
        schema = schemas[ref["$ref"].rsplit("/", 1)[1]]
        robot = schemas[schema["properties"]["robot"]["$ref"].rsplit("/", 1)[1]]
        out[robot["properties"]["name"]["const"]] = schema
    return out


def _given(field: dict) -> dict:
    """The schema of a field given (x0, target, path: each may be left out, the robot's)."""
    (given,) = [s for s in field["anyOf"] if s.get("type") != "null"]
    assert field.get("default", None) is None
    return given


def test_each_robot_has_its_own_vector_lengths(document):
    solve, repeatability = _variants(document, "/solve"), _variants(document, "/repeatability")
    assert set(solve) == set(repeatability) == {*ROBOTS, *USER_ROBOT_MODELS}
    for kind in USER_ROBOT_MODELS:  # (p and r follow from the definition: 1 to 16)
        x0 = _given(solve[kind]["properties"]["x0"])
        assert (x0["minItems"], x0["maxItems"]) == (1, 16), kind
    for name, spec in ROBOTS.items():
        r = len(spec.task_names)
        x0 = _given(solve[name]["properties"]["x0"])
        assert (x0["minItems"], x0["maxItems"]) == (spec.p, spec.p), name
        target = _given(solve[name]["properties"]["target"])
        assert (target["minItems"], target["maxItems"]) == (r, r), name
        point = _given(repeatability[name]["properties"]["path"])["items"]
        assert (point["minItems"], point["maxItems"]) == (r, r), name


def test_each_robot_offers_only_its_own_maps_and_variables(document):
    schemas = document["components"]["schemas"]
    for name, body in _variants(document, "/solve").items():
        options = body["properties"]["augmentation"]["anyOf"]
        refs = [o for o in options if "$ref" in o] + [
            m for o in options for m in o.get("oneOf", [])
        ]
        names = {schemas[m["$ref"].rsplit("/", 1)[1]]["properties"]["name"]["const"] for m in refs}
        expected = (
            {"formula", "e2_synthesized"}
            if name in USER_ROBOT_MODELS
            else {a.name for a in ROBOTS[name].augmentations}
        )
        assert names == expected, name
    for name, body in _variants(document, "/synthesize").items():
        if name in USER_ROBOT_MODELS:
            continue
        region = body["properties"]["region"]["anyOf"][0]
        assert region["propertyNames"]["enum"] == list(ROBOTS[name].variable_names)


def test_the_errors_checked_before_the_routes_are_documented(document):
    for path, operations in document["paths"].items():
        for method, operation in operations.items():
            codes = set(operation["responses"])
            assert "400" in codes, (method, path)  # (a host it does not answer to)
            if method == "post":
                assert {"403", "413", "415", "422"} <= codes, (method, path)
            if "{session_id}" in path:
                assert "404" in codes, (method, path)


def test_every_error_documents_its_body_and_the_headers_sent_with_it(document):
    """A client generated from the document read a session's 404, an export's 409 and 503 as
    bodiless, a 429's or 503's Retry-After and a started atlas's Location as not sent, and knew
    of no 503 from POST /api/sessions: each is documented as the server sends it."""
    for path, operations in document["paths"].items():
        for method, operation in operations.items():
            for status, response in operation["responses"].items():
                where = (method, path, status)
                if status[0] in "45":
                    assert "application/json" in response.get("content", {}), where
                if status in ("429", "503"):
                    assert response["headers"]["Retry-After"]["schema"] == {"type": "integer"}
    for path in ("/atlas", "/api/sessions/{session_id}/atlas"):
        assert "Location" in document["paths"][path]["post"]["responses"]["202"]["headers"]
    assert "503" in document["paths"]["/api/sessions"]["post"]["responses"]


def test_a_405_allows_every_method_of_the_path(client):
    assert client.options("/synthesize").headers["allow"] == "GET, POST"
    assert client.put("/api/sessions/abc").headers["allow"] == "DELETE, GET"


def test_a_wrong_length_names_the_robot_and_the_field(api):
    r = api.post("/solve", json=solve_body(x0=[0.0, 1.0]))
    assert r.status_code == 422
    assert r.json()["detail"][0] == {
        "loc": ["body", "x0"],
        "msg": "x0: must have 3 components (p of manipulator2), got 2",
        "type": "too_short",
    }


def test_an_integer_may_be_written_49_0_but_never_true_or_a_string(api):
    body = {"robot": {"name": "manipulator2"}, "grid": 5.0, "nodes": 3.0}
    assert api.post("/synthesize", json=body).status_code == 200
    for bad in (True, "5", 5.5):
        r = api.post("/synthesize", json={**body, "grid": bad})
        assert r.status_code == 422 and r.json()["detail"][0]["loc"] == ["body", "grid"], bad


def test_a_gamma_too_small_for_the_solver_is_refused_at_the_boundary(api):
    """gamma 5e-324 was accepted and ended in the solver's 'guess[0] contains NaN'."""
    body = {**solve_body(), "path": [[1.9, 0.0]], "gamma": 5e-324}
    del body["target"]
    r = api.post("/repeatability", json=body)
    assert r.status_code == 422 and r.json()["detail"][0]["loc"] == ["body", "gamma"]
    assert api.post("/repeatability", json={**body, "gamma": 1e-6}).status_code == 200


def test_the_default_box_leaves_out_the_fixed_variables(api):
    r = api.post(
        "/synthesize",
        json={"robot": {"name": "manipulator2"}, "fixed": {"x2": 0.5}, "grid": 5, "nodes": 3},
    )
    assert r.status_code == 200, r.text
    assert set(r.json()["region"]) == {"x1", "x3"} and r.json()["fixed"] == {"x2": 0.5}


def test_a_session_takes_exactly_what_its_document_says(client):
    assert client.post("/api/sessions", json={"low_end": 0}).status_code == 422
    r = client.post("/api/sessions", json={"state": {"x0.7": 1.0}})
    assert r.status_code == 422
    assert r.json()["detail"][0]["loc"] == ["body", "state", "x0", 7]
    r = client.post("/api/sessions", json={"state": {"what": 1}})
    assert r.status_code == 422 and r.json()["detail"][0]["loc"][-1] == "what"
    created = client.post("/api/sessions", json={"state": {"x0.0": 0.25}})
    assert created.status_code == 201 and created.json()["state"]["x0"][0] == 0.25
    session = created.json()["id"]
    for change, loc in (
        ({"x0.1": "abc"}, ["x0", 1]),  # (an index a number, as in FastAPI's locations)
        ({"x0.1": [1]}, ["x0", 1]),
        ({"robot_parameters.l": "a"}, ["robot_parameters", "l"]),
    ):
        r = client.post(f"/api/sessions/{session}/state", json=change)
        assert r.status_code == 422, change
        assert r.json()["detail"][0]["loc"] == ["body", *loc]
    r = client.post(f"/api/sessions/{session}/state", json={"x0": (0.0, 0.5, 1.0), "x0.0": 0.1})
    assert r.status_code == 200 and r.json()["state"]["x0"] == [0.1, 0.5, 1.0]
    client.delete(f"/api/sessions/{session}")
