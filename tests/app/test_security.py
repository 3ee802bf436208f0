"""Who may talk to the server (jik.app.api.security): hosts, origins, JSON bodies, headers."""

from __future__ import annotations

import pytest
from fastapi.testclient import TestClient
from starlette.websockets import WebSocketDisconnect

from jik.app.api.factory import create_app

FOREIGN = "http://evil.example"


def test_an_unknown_host_is_refused_on_http_and_websocket(app):
    """A DNS-rebinding page reaches the server under its own name: refused before any route."""
    rebound = TestClient(app, base_url="http://attacker.example:8000")
    r = rebound.get("/health")
    assert r.status_code == 400 and "attacker.example" in r.json()["detail"]
    assert "JIK_ALLOWED_HOSTS" in r.json()["detail"]
    with pytest.raises(WebSocketDisconnect) as closed:
        with rebound.websocket_connect("ws://attacker.example:8000/api/sessions/x/scene"):
            pass
    assert closed.value.code == 4400
    for name in ("localhost:8000", "127.0.0.1", "[::1]:8000"):
        assert TestClient(app, base_url=f"http://{name}").get("/health").status_code == 200


def test_allowed_hosts_come_from_the_environment(monkeypatch):
    monkeypatch.setenv("JIK_ALLOWED_HOSTS", "jik.lab.example, other.example")
    app = create_app()
    assert TestClient(app, base_url="http://jik.lab.example").get("/health").status_code == 200
    assert TestClient(app, base_url="http://nope.example").get("/health").status_code == 400
    monkeypatch.setenv("JIK_ALLOWED_HOSTS", "*")
    assert TestClient(create_app(), base_url="http://any.example").get("/health").status_code == 200


def test_a_change_from_another_origin_is_refused(app, client):
    r = client.post("/api/sessions", json={"state": {}}, headers={"origin": FOREIGN})
    assert r.status_code == 403 and FOREIGN in r.json()["detail"]
    assert len(app.state.sessions) == 0
    ours = client.post("/api/sessions", json={"state": {}},
                       headers={"origin": "http://testserver"})  # fmt: skip
    assert ours.status_code == 201
    session = ours.json()["id"]
    for method, path, body in [
        ("POST", f"/api/sessions/{session}/state", {"cycles": 5}),
        ("DELETE", f"/api/sessions/{session}", None),
        ("POST", "/solve", {}),
    ]:
        r = client.request(method, path, json=body, headers={"origin": FOREIGN})
        assert r.status_code == 403, (method, path)
    assert client.get(f"/api/sessions/{session}").json()["state"]["cycles"] == 3
    assert client.get("/health", headers={"origin": FOREIGN}).status_code == 200  # (a read)


def test_the_scene_socket_refuses_another_origin(client):
    session = client.post("/api/sessions", json={"state": {}}).json()["id"]
    with pytest.raises(WebSocketDisconnect) as closed:
        with client.websocket_connect(f"/api/sessions/{session}/scene",
                                      headers={"origin": FOREIGN}):  # fmt: skip
            pass
    assert closed.value.code == 4403


@pytest.mark.parametrize(
    ("content_type", "body"),
    [
        ("text/plain", b'{"state": {}}'),
        ("application/x-www-form-urlencoded", b"state=%7B%7D"),
        ("multipart/form-data; boundary=x", b"--x--"),
        (None, b'{"state": {}}'),
    ],
)
def test_a_body_that_is_not_json_is_415_and_never_parsed(app, client, content_type, body):
    headers = {} if content_type is None else {"content-type": content_type}
    for path in ("/api/sessions", "/solve", "/repeatability", "/synthesize"):
        r = client.post(path, content=body, headers=headers)
        assert r.status_code == 415, (path, r.text)
        assert r.json()["detail"][0]["loc"] == ["header", "content-type"]
    assert len(app.state.sessions) == 0
    ok = client.post("/api/sessions", content=b'{"state": {}}',
                     headers={"content-type": "application/json; charset=utf-8"})  # fmt: skip
    assert ok.status_code == 201


@pytest.mark.parametrize("path", ["/", "/health", "/docs", "/scene/", "/static/main.js"])
def test_responses_carry_the_safety_headers(client, path):
    r = client.get(path)
    assert r.status_code == 200
    assert r.headers["x-content-type-options"] == "nosniff"
    assert r.headers["referrer-policy"] == "no-referrer"
    assert r.headers["x-frame-options"] == "SAMEORIGIN"
    policy = r.headers["content-security-policy"]
    assert "frame-ancestors 'self'" in policy and "default-src 'self'" in policy
    if path in ("/", "/health", "/static/main.js"):
        assert "script-src 'self';" in policy  # (no inline script on our page)


def test_a_method_a_route_does_not_take_is_405_with_allow_not_415(client):
    """The content-type check applies to the routes that take the body; the router answers the
    rest (405 with its Allow header)."""
    r = client.put("/api/sessions", content=b"x", headers={"content-type": "text/plain"})
    assert r.status_code == 405 and r.headers["allow"] == "POST"
    r = client.post("/health", content=b"x", headers={"content-type": "text/plain"})
    assert r.status_code == 405 and r.headers["allow"] == "GET"


def test_the_openapi_document_gives_the_event_stream_and_the_csv_their_types(client):
    """(Both were documented as JSON.)"""
    paths = client.get("/openapi.json").json()["paths"]
    events = paths["/api/sessions/{session_id}/events"]["get"]["responses"]
    assert list(events["200"]["content"]) == ["text/event-stream"] and "404" in events
    csv = paths["/api/sessions/{session_id}/export.csv"]["get"]["responses"]
    assert list(csv["200"]["content"]) == ["text/csv"] and {"404", "503"} <= set(csv)
