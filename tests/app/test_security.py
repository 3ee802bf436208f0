"""Who may talk to the server (jik.app.api.security): hosts, origins, JSON bodies, headers."""

from __future__ import annotations

import contextlib
import struct
import threading
import time

import httpx
import msgspec
import pytest
import uvicorn
import viser
import websockets
import websockets.asyncio.client
import websockets.typing
import zstandard
from fastapi.testclient import TestClient
from starlette.websockets import WebSocketDisconnect

from jik.app.api.factory import create_app
from tests.helpers import run_async

FOREIGN = "http://evil.example"


def test_an_unknown_host_is_refused_on_http_and_websocket(app):
    """A DNS-rebinding page reaches the server under its own name: refused before any route."""
    rebound = TestClient(app, base_url="http://attacker.example:8000")
    r = rebound.get("/health")
    assert r.status_code == 400 and "attacker.example" in r.json()["detail"]
    assert "JIK_ALLOWED_HOSTS" in r.json()["detail"]
    with pytest.raises(WebSocketDisconnect) as closed:
        with rebound.websocket_connect("ws://attacker.example:8000/api/sessions/x/scene") as ws:
            ws.receive_text()
    assert closed.value.code == 4400
    for name in ("localhost:8000", "127.0.0.1", "[::1]:8000"):
        assert TestClient(app, base_url=f"http://{name}").get("/health").status_code == 200
    client = TestClient(app, base_url="http://127.0.0.1")
    for malformed in (
        "127.0.0.1:8741@evil",
        "[::1]evil",
        "localhost:",
        "127.0.0.1:abc",
        "localhost:99999",
    ):
        assert client.get("/health", headers={"host": malformed}).status_code == 400, malformed


def test_allowed_hosts_come_from_the_environment(monkeypatch):
    monkeypatch.setenv("JIK_ALLOWED_HOSTS", "jik.lab.example, other.example")
    app = create_app()
    assert TestClient(app, base_url="http://jik.lab.example").get("/health").status_code == 200
    assert TestClient(app, base_url="http://nope.example").get("/health").status_code == 400
    monkeypatch.setenv("JIK_ALLOWED_HOSTS", "*")
    assert TestClient(create_app(), base_url="http://any.example").get("/health").status_code == 200


def test_an_allowed_host_given_with_its_port_or_empty_is_taken_as_its_name():
    """`jik serve --allowed-host lab.example:8000` answers to lab.example on any port (it
    refused every request to lab.example:8000, naming 'lab.example:8000' among the hosts it
    answers to); `--allowed-host ""` lets no request without a Host header through."""
    app = create_app(allowed_hosts=("lab.example:8000", " ", "", " other.example "))
    for base in ("http://lab.example:8000", "http://lab.example", "http://other.example"):
        assert TestClient(app, base_url=base).get("/health").status_code == 200, base
    client = TestClient(app, base_url="http://127.0.0.1")
    for host in ("", " "):
        r = client.get("/health", headers={"host": host})
        assert r.status_code == 400 and "'lab.example'" in r.json()["detail"]
        assert "lab.example:8000" not in r.json()["detail"]


def test_a_change_from_another_origin_is_refused(app, client):
    r = client.post("/api/sessions", json={"state": {}}, headers={"origin": FOREIGN})
    assert r.status_code == 403 and FOREIGN in r.json()["detail"]
    assert len(app.state.sessions) == 0
    ours = client.post("/api/sessions", json={"state": {}}, headers={"origin": "http://testserver"})
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
        with client.websocket_connect(
            f"/api/sessions/{session}/scene", headers={"origin": FOREIGN}
        ) as ws:
            ws.receive_text()
    assert closed.value.code == 4403


@contextlib.contextmanager
def _serving(app):
    """``app`` served by uvicorn on a free loopback port (its port), as ``jik serve`` does."""
    server = uvicorn.Server(
        uvicorn.Config(app, host="127.0.0.1", port=0, log_level="warning", lifespan="off")
    )
    thread = threading.Thread(target=server.run, daemon=True)
    thread.start()
    deadline = time.monotonic() + 30
    while not server.started:
        assert time.monotonic() < deadline and thread.is_alive(), "uvicorn did not start"
        time.sleep(0.02)
    try:
        yield server.servers[0].sockets[0].getsockname()[1]
    finally:
        server.should_exit = True
        thread.join(10)


async def _close_code(url: str, **headers: str) -> int:
    """The close code a websocket client gets at ``url`` (an HTTP refusal fails the test)."""
    async with websockets.asyncio.client.connect(url, additional_headers=headers) as ws:
        with pytest.raises(websockets.exceptions.ConnectionClosed) as closed:
            await ws.recv()
    assert closed.value.rcvd is not None
    return closed.value.rcvd.code


def test_a_real_server_closes_refused_scene_sockets_with_the_documented_codes(app, client):
    """Under uvicorn (not only the test client) a refused scene socket is accepted and closed
    with 4403 (another origin), 4400 (another host) or 4404 (no such session), as
    docs/security.md says: a browser's script sees those codes, never an HTTP refusal's 1006."""
    session = client.post("/api/sessions", json={"state": {}}).json()["id"]
    with _serving(app) as port:
        url = f"ws://127.0.0.1:{port}/api/sessions/{session}/scene"
        assert run_async(_close_code(url, Origin=FOREIGN)) == 4403
        assert run_async(_close_code(url, Host="attacker.example")) == 4400
        unknown = f"ws://127.0.0.1:{port}/api/sessions/nope/scene"
        assert run_async(_close_code(unknown)) == 4404


def _viser_messages(frame: bytes) -> list[dict]:
    """The messages of one frame viser's server sends (two sizes, zstd-compressed msgpack)."""
    inner, compressed = struct.unpack_from("<QQ", frame)
    packed = zstandard.ZstdDecompressor().decompress(frame[16 : 16 + compressed], inner)
    return msgspec.msgpack.decode(packed)["messages"]


def test_a_scene_server_takes_only_the_relay(tmp_path):
    """A session's viser server listens on a loopback port of its own: a page of another site
    (its Origin, a rebound Host), a local program without the relay's key and a plain request
    for viser's page are all refused at the handshake, and the session's state is unchanged;
    the relay (/api/sessions/{id}/scene) still reaches the scene."""
    from jik.app.compute.settings import Settings
    from jik.app.dashboard.sessions import SessionStore
    from jik.app.scene import DashboardScene

    app = create_app()
    app.state.sessions = SessionStore(Settings(max_sessions=2), scene_factory=DashboardScene)
    try:
        client = TestClient(app)
        created = client.post("/api/sessions", json={"state": {}}).json()
        session = app.state.sessions.get(created["id"])
        raw = f"ws://127.0.0.1:{session.scene.server.get_port()}"
        viser_protocol = [websockets.typing.Subprotocol(f"viser-v{viser.__version__}")]
        gamma = {"type": "GuiUpdateMessage", "uuid": "x", "updates": {"value": 1.9}}

        async def attack(**headers: str) -> int:
            try:
                async with websockets.asyncio.client.connect(
                    raw, additional_headers=headers, subprotocols=viser_protocol
                ) as ws:
                    await ws.send(msgspec.msgpack.encode(gamma))
                    return 101
            except websockets.exceptions.InvalidStatus as refused:
                return refused.response.status_code

        assert run_async(attack(Origin=FOREIGN, Host="attacker.example")) == 403
        assert (
            run_async(attack(Origin=f"http://127.0.0.1:{session.scene.server.get_port()}")) == 403
        )
        assert run_async(attack()) == 403  # (a local program without the relay's key)
        assert run_async(attack(Authorization="Bearer guessed")) == 403
        page = httpx.get(f"http://127.0.0.1:{session.scene.server.get_port()}/", timeout=10)
        assert page.status_code == 403
        assert session.dashboard.state.gamma == created["state"]["gamma"]
        # The relay: viser's first messages, its theme without the share button among them.
        with client.websocket_connect(
            f"/api/sessions/{created['id']}/scene", subprotocols=viser_protocol
        ) as ws:
            themes = []
            while not themes:
                themes = [
                    m
                    for m in _viser_messages(ws.receive_bytes())
                    if m["type"] == "ThemeConfigurationMessage"
                ]
        assert themes[-1]["show_share_button"] is False
        assert session.scene.server.request_share_url() is None
    finally:
        app.state.sessions.close()


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
    ok = client.post(
        "/api/sessions",
        content=b'{"state": {}}',
        headers={"content-type": "application/json; charset=utf-8"},
    )
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


@pytest.mark.parametrize(
    ("headers", "refused"),
    [
        ([("Host", "127.0.0.1:5"), ("Authorization", "KEY")], None),
        ([("Host", "[::1]:5"), ("Authorization", "KEY")], None),
        ([("Host", "127.0.0.1:5")], "relay only"),
        (
            [("Host", "127.0.0.1:5"), ("Authorization", "KEY"), ("Authorization", "KEY")],
            "relay only",
        ),
        ([("Host", "127.0.0.1:5"), ("Authorization", "KEYx")], "relay only"),
        ([("Host", "localhost.attacker.example"), ("Authorization", "KEY")], "loopback"),
        ([("Host", "127.0.0.1:5"), ("Host", "evil"), ("Authorization", "KEY")], "loopback"),
        ([("Host", "127.0.0.1:5"), ("Authorization", "KEY"), ("Origin", "null")], "browser"),
    ],
)
def test_a_scene_handshake_needs_the_key_a_loopback_host_and_no_origin(headers, refused):
    from websockets.datastructures import Headers

    from jik.app.scene.server import SCENE_KEY, handshake_refusal

    key = f"Bearer {SCENE_KEY}"
    reason = handshake_refusal(Headers([(k, v.replace("KEY", key)) for k, v in headers]))
    assert (reason is None) if refused is None else (refused in (reason or "")), reason


def test_a_scene_server_that_would_serve_unguarded_is_not_started(monkeypatch):
    """Should viser stop taking the handshake guard, a scene server fails closed: it is
    stopped and an error says why, instead of serving anyone on its port."""
    import jik.app.scene.server as scene_server

    monkeypatch.setattr(scene_server, "_guarded", lambda process_request: process_request)
    with pytest.raises(scene_server.UnguardedSceneServer, match="answered 200"):
        scene_server.SceneServer()
