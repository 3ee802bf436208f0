"""Every request body the OpenAPI document publishes has an example (what Swagger UI's "Try it
out" starts from), and the server accepts every example the document gives: the per-robot
models' (``examples`` of each schema) and the routes' (``examples`` of the media type)."""

from __future__ import annotations

import json

import pytest

from jik.app.api.factory import create_app
from jik.engine.registry import ROBOTS

DOCUMENT = create_app().openapi()
SCHEMAS = DOCUMENT["components"]["schemas"]


def _bodies() -> list[tuple[str, dict]]:
    """(path, the media type of its request body) of every operation that takes one."""
    out = []
    for path, operations in DOCUMENT["paths"].items():
        for operation in operations.values():
            body = operation.get("requestBody")
            if body is not None:
                out.append((path, body["content"]["application/json"]))
    return out


def _models(media: dict) -> list[str]:
    """The request models a body's schema names (the members of a per-robot union)."""
    schema = media["schema"]
    refs = schema.get("oneOf", [schema])
    return [ref["$ref"].rsplit("/", 1)[1] for ref in refs]


REQUEST_MODELS = sorted({(path, model) for path, media in _bodies() for model in _models(media)})


def _examples() -> list:
    """Every example of the document, once, with the path it is for."""
    seen: dict[tuple[str, str], object] = {}
    for path, media in _bodies():
        given = [(model, e) for model in _models(media) for e in SCHEMAS[model].get("examples", [])]
        given += [(name, e["value"]) for name, e in media.get("examples", {}).items()]
        for label, example in given:
            seen.setdefault((path, json.dumps(example, sort_keys=True)), (label, example))
    return [
        pytest.param(path, example, id=f"{path}:{label}")
        for (path, _), (label, example) in seen.items()
    ]


EXAMPLES = _examples()
REST = [p for p in EXAMPLES if "{session_id}" not in p.values[0] and p.values[0] != "/api/sessions"]
SESSION = [p for p in EXAMPLES if p not in REST]


@pytest.mark.parametrize(("path", "model"), REQUEST_MODELS)
def test_every_request_model_has_an_example(path, model):
    assert SCHEMAS[model].get("examples"), f"{model} of {path} has no example"


def test_each_route_lists_every_robots_example_and_each_model_its_own_robots():
    for path, media in _bodies():
        if "oneOf" not in media["schema"]:
            continue
        examples = media["examples"]
        for model in _models(media):
            robot_ref = SCHEMAS[model]["properties"]["robot"]["$ref"].rsplit("/", 1)[1]
            name = SCHEMAS[robot_ref]["properties"]["name"]["const"]
            (example,) = SCHEMAS[model]["examples"]
            assert example["robot"]["name"] == name, (path, model)
            assert json.dumps(examples[name]["value"], sort_keys=True) == json.dumps(
                example, sort_keys=True
            ), (path, model)


def test_the_examples_are_the_registrys_defaults():
    """Manipulator 2's: Table 1's start and path; not numbers copied by hand."""
    spec = ROBOTS["manipulator2"]
    solve = SCHEMAS["SolveManipulator2Request"]["examples"][0]
    assert solve["x0"] == list(spec.default_x0) and solve["target"] == list(spec.default_target)
    path = SCHEMAS["RepeatabilityManipulator2Request"]["examples"][0]["path"]
    assert path == [[1.0, 1.0], [1.0, 2.0], [0.0, 2.0], [0.0, 1.0]]
    assert SCHEMAS["KinematicsManipulator2Request"]["examples"][0]["x"] == list(spec.default_x0)


@pytest.mark.parametrize(("path", "example"), REST)
def test_the_server_accepts_every_example(api, path, example):
    r = api.post(path, json=example)
    if path == "/atlas":
        assert r.status_code == 202, r.text
        assert api.delete(f"/atlas/{r.json()['id']}").status_code == 204
    else:
        assert r.status_code == 200, r.text


def test_a_session_accepts_every_example_of_its_routes(client):
    """The sessions' examples in order: one creates a session, the others go to it (a second
    phase that is not running or was not cancelled is a 409: the body was taken)."""
    created = [e for p in SESSION if p.values[0] == "/api/sessions" for e in [p.values[1]]]
    assert created
    r = client.post("/api/sessions", json=created[0])
    assert r.status_code == 201, r.text
    session = r.json()["id"]
    try:
        for param in SESSION:
            path, example = param.values
            if path == "/api/sessions":
                continue
            r = client.post(path.replace("{session_id}", session), json=example)
            if path.endswith("/atlas"):
                assert r.status_code == 202, r.text
                assert client.delete(f"/atlas/{r.json()['id']}").status_code == 204
            elif path.endswith("/state"):
                assert r.status_code == 200, (example, r.text)
            else:
                assert r.status_code in (202, 409), (path, r.text)
    finally:
        client.delete(f"/api/sessions/{session}")
