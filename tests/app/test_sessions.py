"""Dashboard sessions over HTTP: one per tab, isolated, bounded, expiring."""

from __future__ import annotations

import asyncio
import json
import re
import time

import pytest
from fastapi.testclient import TestClient
from starlette.websockets import WebSocketDisconnect

from jik.app.api.factory import create_app
from jik.app.compute.settings import Settings
from jik.app.dashboard.algorithms import COLORS
from jik.app.dashboard.plotting import PANELS
from jik.app.dashboard.sessions import SessionNotFound, SessionsFull, SessionStore
from jik.engine.registry import ALGORITHMS
from tests.helpers import run_async

JSON = {"content-type": "application/json"}


def _open(client, state=None) -> dict:
    r = client.post("/api/sessions", json={"state": state or {}})
    assert r.status_code == 201, r.text
    return r.json()


def _computed(app, session_id: str) -> None:
    dashboard = app.state.sessions.get(session_id).dashboard
    assert dashboard.wait(timeout=60)


def test_page_static_files_and_config():
    """The page, plotly.js from the plotly package, the icon and the dashboard's config."""
    client = TestClient(create_app())
    page = client.get("/")
    assert page.status_code == 200 and 'id="panels"' in page.text
    # Nothing from the network: no resource from another origin (a link the reader may follow,
    # the paper's journal, is not fetched).
    resources = re.sub(r"<a [^>]*>", "", page.text).replace("http-equiv", "")
    assert "http" not in resources
    js = client.get("/static/vendor/plotly.min.js")
    assert js.status_code == 200 and js.headers["content-type"].startswith("text/javascript")
    for module in ("main", "api", "controls", "panels", "dom"):
        js = client.get(f"/static/{module}.js")
        assert js.status_code == 200 and js.headers["content-type"].startswith("text/javascript")
    assert '<link rel="icon" href="/static/favicon.svg"' in page.text
    icon = client.get("/static/favicon.svg")
    assert icon.status_code == 200 and icon.headers["content-type"].startswith("image/svg+xml")
    assert client.get("/static/..%2Fpyproject.toml").status_code == 404
    assert client.get("/static/__init__.py").status_code == 404
    config = client.get("/api/dashboard/config").json()
    # (one colour per algorithm of the catalogue; the paper's two keep theirs)
    assert config["colors"] == COLORS and set(COLORS) == set(ALGORITHMS)
    assert (COLORS["pseudoinverse"], COLORS["extended"]) == ("#d62728", "#1f77b4")
    assert [p["id"] for p in config["panels"]] == list(PANELS)
    # The viser client for the sessions' scenes, from the viser package.
    scene = client.get("/scene/")
    assert scene.status_code == 200 and "<script" in scene.text


def test_the_errata_page_is_the_errata_file_as_html():
    """GET /errata: docs/paper-errata.md as a page (headings, tables, the commands), linked from
    the page's About; no script, nothing from another origin."""
    client = TestClient(create_app())
    errata = client.get("/errata")
    assert errata.status_code == 200 and errata.headers["content-type"].startswith("text/html")
    html = errata.text
    assert "<title>jik: Paper errata</title>" in html and "<h1>Paper errata</h1>" in html
    assert "<h2>Table 1 and the cubic (38) (Manipulator 2)</h2>" in html
    assert "<td>(0.0637, 0.6487, 1.2119)</td>" in html  # (a table of the file, as a table)
    assert "<code>jik reproduce table1</code>" in html
    assert "<script" not in html and "http" not in re.sub(r"<a [^>]*>", "", html)
    assert 'href="/errata"' in client.get("/").text


def test_each_session_has_its_own_state(app, client):
    """A change in one session never reaches another; a new one starts from the defaults."""
    one, two = _open(client), _open(client)
    assert one["id"] != two["id"] and one["state"] == two["state"]
    defaults = one["state"]
    r = client.post(
        f"/api/sessions/{one['id']}/state", json={"robot": "manipulator1", "gamma": 2.0}
    )
    assert r.status_code == 200 and r.json()["state"]["robot"] == "manipulator1"
    assert client.get(f"/api/sessions/{two['id']}").json()["state"] == defaults
    assert client.get(f"/api/sessions/{one['id']}").json()["state"]["gamma"] == 2.0
    assert _open(client)["state"] == defaults


def test_a_link_state_opens_a_session_with_that_state(app, client):
    """The state a page keeps in its URL gives a new session the same state and numbers."""
    first = _open(client)
    changed = client.post(
        f"/api/sessions/{first['id']}/state", json={"x0": [0.2, 0.1, 1.4], "cycles": 2}
    ).json()["state"]
    again = _open(client, changed)
    assert again["state"] == changed
    _computed(app, first["id"])
    _computed(app, again["id"])
    a = client.get(f"/api/sessions/{first['id']}").json()["summary"]
    b = client.get(f"/api/sessions/{again['id']}").json()["summary"]
    for run in (*a.values(), *b.values()):
        del run["seconds"]  # (the time each took)
    assert a == b and a["extended"]["success"]


#: A value nested 480 lists deep (1 KB of JSON).
DEEP = json.loads("[" * 480 + "1" + "]" * 480)


@pytest.mark.parametrize(
    ("state", "field"),
    [
        ({"gamma": -1}, "gamma"),
        ({"robot": "nope"}, "robot"),
        ({"cycles": 0}, "cycles"),
        ({"x0": [1, 2]}, "x0"),
        ({"robot_parameters": {"l": -1}}, "robot_parameters.l"),
        (  # (a robot definition nested 480 deep jammed the compute pool: 500, then 503s)
            {"robot": "formula", "robot_definition": {"name": "formula", "title": DEEP}},
            "robot_definition",
        ),
    ],
)
def test_a_bad_link_state_is_refused_with_its_field(client, state, field):
    """At ``state.<field>``, the message led by it once, whichever check refused it."""
    r = client.post("/api/sessions", json={"state": state})
    assert r.status_code == 422, r.text
    detail = r.json()["detail"][0]
    assert detail["loc"] == ["body", "state", *field.split(".")]
    assert detail["msg"].startswith(f"state.{field}: ")
    assert not detail["msg"].startswith(f"state.{field}: {field}")


def test_bad_changes_name_their_field_and_leave_the_state(client):
    session = _open(client)
    url = f"/api/sessions/{session['id']}/state"
    bad = client.post(url, json={"gamma": -1})
    assert bad.status_code == 422
    assert bad.json()["detail"][0] == {
        "loc": ["body", "gamma"],
        "msg": "gamma: Input should be greater than or equal to 0.000001",
        "type": "value_error",
    }
    not_an_object = client.post(url, content=b"[1]", headers=JSON)
    assert not_an_object.status_code == 422
    assert not_an_object.json()["detail"][0]["loc"] == ["body"]  # (not ["body", "body"])
    # A refusal quotes what the user wrote, its first 60 characters.
    long = client.post(url, json={"path": "1," * 5000}).json()["detail"][0]["msg"]
    assert f"'{'1,' * 28}1...'," in long and len(long) < 200
    assert client.get(f"/api/sessions/{session['id']}").json()["state"] == session["state"]


def test_export_is_per_session(app, client):
    one, two = _open(client), _open(client)
    client.post(f"/api/sessions/{one['id']}/state", json={"task": "target", "x0": [0.2, 0.1, 1.4]})
    _computed(app, one["id"])
    csv = client.get(f"/api/sessions/{one['id']}/export.csv")
    assert csv.status_code == 200 and csv.text.startswith("# jik export of generation")
    assert "\nalgorithm,cycle,leg,theta,x_1" in csv.text
    body = client.get(f"/api/sessions/{one['id']}/export.json").json()
    assert body["state"]["x0"] == [0.2, 0.1, 1.4]
    assert len(body["runs"]["pseudoinverse"]["x"][0]) == 3
    other = client.get(f"/api/sessions/{two['id']}/export.json").json()
    assert other["state"]["x0"] == two["state"]["x0"]


def test_unknown_and_deleted_sessions_are_404(client):
    assert client.get("/api/sessions/nope").status_code == 404
    assert client.post("/api/sessions/nope/state", json={"gamma": 1}).status_code == 404
    assert client.get("/api/sessions/nope/events").status_code == 404
    session = _open(client)
    assert client.delete(f"/api/sessions/{session['id']}").status_code == 204
    gone = client.get(f"/api/sessions/{session['id']}")
    assert gone.status_code == 404 and "reload the page" in gone.json()["detail"]


def test_a_full_store_evicts_the_idlest_unused_session_or_refuses():
    store = SessionStore(Settings(max_sessions=2))
    try:
        a = store.create()
        b = store.create()
        b.touch()
        c = store.create()  # a was idle the longest: it makes room
        with pytest.raises(SessionNotFound):
            store.get(a.id)
        assert len(store) == 2
        b.users = c.users = 1  # both followed by a tab
        with pytest.raises(SessionsFull, match=r"2 dashboard sessions in use, its limit \(JIK_MAX"):
            store.create()
    finally:
        store.close()


def test_a_full_store_answers_503(app, client):
    app.state.sessions.close()
    app.state.sessions = store = SessionStore(Settings(max_sessions=1))
    session = _open(client)
    store.get(session["id"]).users = 1
    r = client.post("/api/sessions", json={"state": {}})
    assert r.status_code == 503 and "in use" in r.json()["detail"]
    assert r.headers["retry-after"] == "5"  # (a tab closed or hidden frees a slot at once)


def test_idle_sessions_expire_by_themselves():
    store = SessionStore(Settings(session_idle_seconds=1.0))
    try:
        kept, idle = store.create(), store.create()
        kept.users = 1
        deadline = time.monotonic() + 10
        while len(store) > 1:  # the reaper runs every quarter of the idle limit
            assert time.monotonic() < deadline, "the idle session did not expire"
            time.sleep(0.05)
        assert store.get(kept.id) is kept
        with pytest.raises(SessionNotFound):
            store.get(idle.id)
        assert idle.dashboard._stopped  # (its worker thread ended)
    finally:
        store.close()


def test_a_refused_change_is_an_event_with_the_state_in_force(app, client):
    """The page and the scene both follow a session's events: a refusal from either is shown
    by both, with the values in force."""
    from jik.engine.exceptions import InvalidInputError

    session = _open(client)
    dashboard = app.state.sessions.get(session["id"]).dashboard
    events = []
    dashboard.subscribe(lambda e: events.append(e))
    with pytest.raises(InvalidInputError):
        dashboard.update({"gamma": -2}, source="scene")
    (refused,) = [json.loads(e.data) for e in events if e.kind == "refused"]
    assert refused["source"] == "scene" and "gamma" in refused["message"]
    assert refused["field"] == "gamma"
    assert refused["values"]["gamma"] == session["state"]["gamma"]
    assert refused["state"]["gamma"] == session["state"]["gamma"]


def test_the_scene_socket_refuses_other_origins_and_unknown_sessions(client):
    session = _open(client)
    url = f"/api/sessions/{session['id']}/scene"
    with pytest.raises(WebSocketDisconnect) as foreign:
        with client.websocket_connect(url, headers={"origin": "http://evil.example"}) as ws:
            ws.receive_text()
    assert foreign.value.code == 4403
    with pytest.raises(WebSocketDisconnect) as unknown:
        with client.websocket_connect("/api/sessions/nope/scene") as ws:
            ws.receive_text()
    assert unknown.value.code == 4404


def test_a_listener_that_never_reads_holds_one_event_of_each_kind(app, client):
    """The event stream of a page that stops reading buffers the newest event of each kind, not
    one per change (about 0.45 MB per change, never released)."""
    from jik.app.dashboard.messages import LatestEvents

    session = _open(client)
    dashboard = app.state.sessions.get(session["id"]).dashboard

    async def changes() -> tuple[int, list]:
        buffer = LatestEvents(asyncio.get_running_loop())
        unsubscribe = dashboard.subscribe(buffer.put)
        for k in range(40):
            generation, _ = dashboard.update({"gamma": 0.5 + 0.01 * k})
            await asyncio.to_thread(dashboard.wait, generation, 60)
        await asyncio.sleep(0.05)  # (the loop takes the last puts)
        unsubscribe()
        held = len(buffer)
        return held, [await buffer.get() for _ in range(held)]

    held, events = run_async(changes())
    kinds = [e.kind for e in events]
    assert held <= 7 and len(set(kinds)) == len(kinds), kinds
    result = next(e for e in events if e.kind == "result")
    assert result.generation == dashboard.generation  # the newest


def test_an_export_after_a_failure_is_409_never_the_previous_result(app, client, monkeypatch):
    """The export said nothing of a newer generation that failed and returned
    the previous result as if it were the current state's."""
    import jik.app.dashboard.session as session
    from jik.engine.exceptions import JikError

    real = session.compute

    def failing(state, *args, **kwargs):
        if state.gamma == 2.5:
            raise JikError("the start configuration is singular (injected by the test)")
        return real(state, *args, **kwargs)

    monkeypatch.setattr(session, "compute", failing)
    sid = client.post("/api/sessions", json={}).json()["id"]
    assert client.get(f"/api/sessions/{sid}/export.json").status_code == 200
    assert client.post(f"/api/sessions/{sid}/state", json={"gamma": 2.5}).status_code == 200
    for export in ("export.json", "export.csv"):
        r = client.get(f"/api/sessions/{sid}/{export}")
        assert r.status_code == 409, r.text
        assert "failed: the start configuration is singular" in r.json()["detail"]
    assert client.post(f"/api/sessions/{sid}/state", json={"gamma": 1.5}).status_code == 200
    r = client.get(f"/api/sessions/{sid}/export.json")
    assert r.status_code == 200
    client.delete(f"/api/sessions/{sid}")


def test_an_export_not_computed_yet_is_503_with_retry_after(app, client, monkeypatch):
    """The 503 of an export asked before its result said "retry" in words only: a client
    waiting as the document says (Retry-After) had no header to read."""
    import threading

    import jik.app.api.routes.sessions as routes
    import jik.app.dashboard.session as session

    release, real = threading.Event(), session.compute

    def held(state, *args, **kwargs):
        release.wait(30)
        return real(state, *args, **kwargs)

    monkeypatch.setattr(session, "compute", held)
    monkeypatch.setattr(routes, "EXPORT_WAIT", 0.0)
    sid = client.post("/api/sessions", json={}).json()["id"]
    r = client.get(f"/api/sessions/{sid}/export.csv")
    release.set()
    assert r.status_code == 503, r.text
    assert r.headers["retry-after"] == "1" and "computed yet" in r.json()["detail"]
    client.delete(f"/api/sessions/{sid}")


def test_an_export_of_a_named_generation_is_that_one_while_a_newer_computes(
    app, client, monkeypatch
):
    """The page's export link names the generation on screen: while a newer state computes,
    its file is the one it names, at once (not, after a wait, the newer one), and once that is
    replaced the link's generation is refused, 409, naming the one on screen."""
    import threading

    import jik.app.dashboard.session as session

    real, release = session.compute, threading.Event()

    def slow(state, *args, **kwargs):
        if state.gamma == 1.5:
            release.wait(60)
        return real(state, *args, **kwargs)

    monkeypatch.setattr(session, "compute", slow)
    sid = client.post("/api/sessions", json={}).json()["id"]
    try:
        first = client.get(f"/api/sessions/{sid}/export.json").json()["generation"]
        assert client.post(f"/api/sessions/{sid}/state", json={"gamma": 1.5}).status_code == 200
        named = {"generation": first}
        body = client.get(f"/api/sessions/{sid}/export.json", params=named).json()
        assert body["generation"] == first and body["state"]["gamma"] == 1.0
        csv = client.get(f"/api/sessions/{sid}/export.csv", params=named)
        assert csv.text.startswith(f"# jik export of generation {first}")
        release.set()
        newer = client.get(f"/api/sessions/{sid}/export.json").json()  # (the current state's)
        assert newer["generation"] > first and newer["state"]["gamma"] == 1.5
        r = client.get(f"/api/sessions/{sid}/export.json", params=named)
        assert r.status_code == 409, r.text
        assert r.json()["detail"] == (
            f"generation {first} is not the result on screen (generation "
            f"{newer['generation']}); export again"
        )
    finally:
        release.set()
        client.delete(f"/api/sessions/{sid}")


def _events_scope(session_id: str) -> dict:
    """The ASGI scope of ``GET /api/sessions/{session_id}/events``, as uvicorn gives it."""
    path = f"/api/sessions/{session_id}/events"
    return {
        "type": "http",
        "asgi": {"version": "3.0"},
        "http_version": "1.1",
        "method": "GET",
        "scheme": "http",
        "path": path,
        "raw_path": path.encode(),
        "root_path": "",
        "query_string": b"",
        "headers": [(b"host", b"127.0.0.1")],
        "client": ("127.0.0.1", 50000),
        "server": ("127.0.0.1", 8000),
    }


async def _connected() -> dict:
    """An ASGI ``receive`` of a client that stays connected and sends nothing."""
    await asyncio.Event().wait()
    return {}


def _latest_result(dashboard):
    events: list = []
    dashboard.subscribe(events.append)()  # (the latest events, replayed)
    return next(e for e in events if e.kind == "result")


def test_a_stream_whose_client_does_not_read_holds_a_piece_of_an_event_then_ends(
    app, client, monkeypatch
):
    """uvicorn keeps what a response sends until the client takes it, and pauses the response
    (its next send waits) once it holds HIGH_WATER_LIMIT bytes: a stream whose client did not
    read held a whole result (40 such streams on a 67 MB result: 2.5 GB) and stayed open. It
    holds one piece of an event more, and ends after SEND_TIMEOUT, its session unused again."""
    from uvicorn.protocols.http.flow_control import HIGH_WATER_LIMIT

    from jik.app.api.routes import sessions as routes
    from jik.app.dashboard.messages import PIECE

    monkeypatch.setattr(routes, "SEND_TIMEOUT", 0.2)
    session = _open(client)
    _computed(app, session["id"])
    stored = app.state.sessions.get(session["id"])
    assert len(_latest_result(stored.dashboard).data) > 3 * PIECE

    async def unread() -> tuple[list[bytes], bool]:
        sent: list[bytes] = []

        async def send(message) -> None:  # (uvicorn's, to a client that reads nothing)
            if sum(map(len, sent)) > HIGH_WATER_LIMIT:
                await asyncio.Event().wait()
            sent.append(message.get("body", b""))

        task = asyncio.ensure_future(app(_events_scope(session["id"]), _connected, send))
        done, _ = await asyncio.wait({task}, timeout=10)
        task.cancel()
        return sent, bool(done)

    sent, ended = run_async(unread())
    assert sum(map(len, sent)) < HIGH_WATER_LIMIT + PIECE + 1024, sum(map(len, sent))
    assert ended and stored.users == 0


def test_a_stream_sends_large_events_whole_and_a_comment_when_idle(app, client, monkeypatch):
    """An event sent in pieces reads as one; an idle stream sends a comment every HEARTBEAT
    seconds (proxies keep the connection)."""
    from jik.app.api.routes import sessions as routes

    monkeypatch.setattr(routes, "HEARTBEAT", 0.05)
    session = _open(client)
    _computed(app, session["id"])
    result = _latest_result(app.state.sessions.get(session["id"]).dashboard)

    async def read() -> bytes:
        sent: list[bytes] = []
        pinged = asyncio.Event()

        async def send(message) -> None:
            sent.append(message.get("body", b""))
            if sent[-1].startswith(b": ping"):
                pinged.set()

        task = asyncio.ensure_future(app(_events_scope(session["id"]), _connected, send))
        await asyncio.wait_for(pinged.wait(), 10)
        task.cancel()
        return b"".join(sent)

    blocks = re.split(r"\r?\n\r?\n", run_async(read()).decode())
    fields = [dict(line.split(": ", 1) for line in b.splitlines()) for b in blocks if b]
    (sent,) = [f for f in fields if f.get("event") == "result"]
    assert sent["data"] == result.data and sent["id"] == str(result.generation)
    assert fields[-1] == {"": "ping"}
