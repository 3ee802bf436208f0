"""Dashboard sessions over HTTP: one per browser tab (:mod:`jik.app.dashboard.sessions`).

The page creates its session from the state in its URL (``POST /api/sessions``), changes it
(``POST /api/sessions/{id}/state``), follows it (``GET /api/sessions/{id}/events``, server-sent
events), cancels a result's E1/E2 and computes them again
(``POST /api/sessions/{id}/functionals/cancel``, ``POST /api/sessions/{id}/functionals``) and
shows its 3D scene, whose websocket goes through
``/api/sessions/{id}/scene`` to the session's own viser server on a loopback port. The id is a
random token: only the tab that created the session knows it.
"""

from __future__ import annotations

import asyncio
import contextlib
import math
from typing import Annotated

import websockets
from fastapi import APIRouter, Request, WebSocket
from fastapi.responses import JSONResponse, PlainTextResponse
from pydantic import BaseModel, ConfigDict, Field
from sse_starlette import EventSourceResponse, ServerSentEvent
from sse_starlette.sse import SendTimeoutError
from starlette.types import Receive, Scope, Send

from ....engine.exceptions import InvalidInputError
from ...compute.schemas import INTEGRAL
from ...compute.schemas.wording import refused, without_field
from ...dashboard import export_file
from ...dashboard.controls import controls_message
from ...dashboard.messages import LatestEvents, sse_pieces
from ...dashboard.patch import StatePatch, parse_patch, patch_of
from ...dashboard.robots import vet_definition
from ...dashboard.sessions import SessionNotFound
from ..dependencies import Pool, Store
from ..errors import unparsed_body_response
from ..security import close_websocket

router = APIRouter(tags=["dashboard sessions"])
#: Seconds between keep-alive comments on an idle event stream.
HEARTBEAT = 15.0
#: Seconds a client has to take a piece of an event (or a keep-alive comment) before its stream
#: is closed; the page's EventSource then reconnects and gets the latest events again.
SEND_TIMEOUT = 30.0
#: The events the page follows.
PAGE_EVENTS = ("state", "progress", "result", "functionals", "error", "ahead", "refused")
#: Seconds an export waits for the session's first result.
EXPORT_WAIT = 60.0


class SessionCreate(BaseModel):
    """``POST /api/sessions``: a new dashboard session (one per browser tab)."""

    model_config = ConfigDict(
        extra="forbid", json_schema_extra={"examples": [{"state": {"robot": "manipulator1"}}]}
    )

    state: StatePatch = Field(  # type: ignore[valid-type]
        default_factory=StatePatch,
        description="the dashboard fields that differ from the defaults (a link's state); "
        "validated like a change (POST /api/sessions/{id}/state)",
    )
    low_end: bool = Field(
        default=False,
        strict=True,
        description="draw the 3D scene without shadows or environment map: the low-end mode, "
        "which the page asks for only when its browser renders WebGL without a GPU",
    )


#: What a client does next with a new session (OpenAPI links: the id it answers is the path's).
_SESSION_LINKS = {
    name: {"operationId": name, "parameters": {"session_id": "$response.body#/id"}}
    for name in (
        "get_session",
        "post_state",
        "session_events",
        "cancel_functionals",
        "compute_functionals",
        "export_json",
        "export_csv",
        "delete_session",
    )
}


@router.post("/api/sessions", status_code=201, responses={201: {"links": _SESSION_LINKS}})
async def create_session(body: SessionCreate, store: Store, pool: Pool) -> JSONResponse:
    """A new session whose state is the defaults changed by ``state`` (a link's state)."""
    try:
        patch = patch_of(body.state)
        await vet_definition(pool, patch)
        session = await asyncio.to_thread(store.create, patch, body.low_end)
    except InvalidInputError as exc:  # (the link's state is the body's "state")
        raise refused(f"state.{exc.field or ''}", without_field(str(exc), exc.field)) from None
    dashboard = session.dashboard
    created = {
        "id": session.id,
        "generation": dashboard.generation,
        "state": dashboard.state.as_dict(),
        "scene": session.scene is not None,
        **controls_message(dashboard.state),
    }
    return JSONResponse(status_code=201, content=created)


@router.get("/api/sessions/{session_id}", operation_id="get_session")
async def get_session(session_id: str, store: Store) -> JSONResponse:
    """The session's state, its generation and the summary of its last result."""
    return JSONResponse(store.get(session_id).dashboard.snapshot())


@router.delete("/api/sessions/{session_id}", status_code=204, operation_id="delete_session")
async def delete_session(session_id: str, store: Store):
    """End the session now (a closing tab; otherwise it expires when idle)."""
    await asyncio.to_thread(store.delete, session_id)
    return PlainTextResponse(status_code=204, content="")


@router.post(
    "/api/sessions/{session_id}/state",
    operation_id="post_state",
    openapi_extra={
        "requestBody": {
            "required": True,
            "content": {
                "application/json": {"schema": {"$ref": "#/components/schemas/StatePatch"}}
            },
        }
    },
)
async def post_state(session_id: str, request: Request, store: Store, pool: Pool) -> JSONResponse:
    """Change some controls: ``{"gamma": 2}``, ``{"x0": [...]}``, ``{"robot": "manipulator1"}``.

    The body is a :data:`StatePatch`; the answer is the new generation and state. A change
    refused, by the patch's types or by the engine, is a 422 naming the field, and a ``refused``
    event for the session's page and scene, which show it beside the field.
    """
    session = store.get(session_id)
    try:
        body = await request.json()
    except (ValueError, RecursionError) as exc:
        return unparsed_body_response(exc)
    try:
        patch = parse_patch(body)
        await vet_definition(pool, patch)  # (a robot's formulas: built off the event loop)
    except InvalidInputError as exc:
        session.dashboard.refuse(exc)
    generation, state = await asyncio.to_thread(session.dashboard.update, patch, "page")
    return JSONResponse({"generation": generation, "state": state.as_dict()})


class SecondPhaseRequest(BaseModel):
    """Which result's second phase (h on a grid when it is expensive, E1, E2 and their
    sensitivity) a request is about: the generation on screen, never a newer one by accident."""

    model_config = ConfigDict(extra="forbid", json_schema_extra={"examples": [{"generation": 1}]})

    generation: Annotated[int, Field(strict=True, ge=1), INTEGRAL] = Field(
        description="the generation of the result shown"
    )


#: A session that is not there (expired, deleted, never created).
_NOT_FOUND: dict[int | str, dict] = {404: {"description": "no such session"}}
#: A second phase that is not in the state a request needs.
_SECOND_PHASE_CONFLICT: dict[int | str, dict] = {
    409: {
        "description": "that generation's second phase is not running (cancel) or was not "
        "cancelled (compute), or a newer generation is current"
    },
}


@router.post(
    "/api/sessions/{session_id}/functionals/cancel",
    status_code=202,
    operation_id="cancel_functionals",
    responses={**_SECOND_PHASE_CONFLICT, **_NOT_FOUND},
)
async def cancel_functionals(
    session_id: str, body: SecondPhaseRequest, store: Store
) -> JSONResponse:
    """Stop computing E1, E2, their sensitivity (and h on a grid) of the result on screen: it
    stays, and a ``functionals`` event with ``cancelled`` says what was not computed."""
    dashboard = store.get(session_id).dashboard
    return _second_phase_answer(
        dashboard.cancel_second_phase(body.generation),
        dashboard,
        body.generation,
        f"nothing to cancel: E1, E2 of generation {body.generation} are not being computed",
    )


@router.post(
    "/api/sessions/{session_id}/functionals",
    status_code=202,
    operation_id="compute_functionals",
    responses={**_SECOND_PHASE_CONFLICT, **_NOT_FOUND},
)
async def compute_functionals(
    session_id: str, body: SecondPhaseRequest, store: Store
) -> JSONResponse:
    """Compute again the cancelled E1, E2, their sensitivity (and h on a grid) of the result on
    screen: ``progress`` events, then a ``functionals`` event."""
    dashboard = store.get(session_id).dashboard
    return _second_phase_answer(
        dashboard.compute_second_phase(body.generation),
        dashboard,
        body.generation,
        f"E1, E2 of generation {body.generation} were not cancelled, or it is not the result shown",
    )


def _second_phase_answer(done: bool, dashboard, generation: int, refusal: str) -> JSONResponse:
    """202 with the generation when the second phase did as asked; else 409 saying why."""
    if not done:
        return JSONResponse(
            status_code=409,
            content={"detail": f"{refusal} (the session is at generation {dashboard.generation})"},
        )
    return JSONResponse(status_code=202, content={"generation": generation})


class CSVResponse(PlainTextResponse):
    media_type = "text/csv"


#: An export with no result of the current state (:class:`ExportUnavailable`).
_NO_EXPORT: dict[int | str, dict] = {
    409: {
        "description": "the current state's computation failed, or the generation asked is "
        "no longer on screen: nothing current to export"
    },
    503: {"description": "the current state's result is not computed yet"},
}


@router.get(
    "/api/sessions/{session_id}/events",
    operation_id="session_events",
    response_class=EventSourceResponse,
    responses={
        200: {"description": "the session's events", "content": {"text/event-stream": {}}},
        **_NOT_FOUND,
    },
)
async def events(session_id: str, store: Store):
    """Server-sent events of one session: ``state``, ``progress``, ``result``, ``functionals``,
    ``error``, ``ahead``, ``refused``.

    Each event's data is JSON; a ``result`` carries every panel as a plotly figure, an
    ``ahead`` the panels of another robot's default state, solved ahead for a switch. An event's
    id is the state's generation; a client that connects again gets the latest event of each
    kind again (``Last-Event-ID`` is not read).
    """
    session = store.get(session_id)
    dashboard = session.dashboard
    queue = LatestEvents(asyncio.get_running_loop())  # (bounded: one event of each kind)
    unsubscribe = dashboard.subscribe(queue.put)
    session.users += 1

    async def stream():
        try:
            yield ServerSentEvent(retry=1000)  # (the page reconnects after 1 s)
            while True:
                try:
                    event = await asyncio.wait_for(queue.get(), HEARTBEAT)
                except TimeoutError:  # (a comment, so that proxies keep the connection)
                    yield ServerSentEvent(comment="ping")
                    continue
                if event.kind == "closed":  # (the session ended: the page opens a new one)
                    return
                if event.kind in PAGE_EVENTS:
                    for piece in sse_pieces(event):
                        yield piece
        finally:
            unsubscribe()
            session.users -= 1
            session.touch()

    # uvicorn keeps what it is sent until the client takes it: an event goes in pieces, each
    # sent once uvicorn's buffer has room, and a stream whose client takes nothing for
    # SEND_TIMEOUT seconds ends, as when the client leaves or the server stops. sse-starlette's
    # pings, which could land between two pieces, are off (ping=0 spins before its 3.4.9).
    return _EventStream(stream(), ping=math.inf, sep="\n", send_timeout=SEND_TIMEOUT)


class _EventStream(EventSourceResponse):
    """sse-starlette's response, ended without a traceback when a send times out (a client that
    does not read): uvicorn then closes the connection, logging that the response was cut."""

    async def __call__(self, scope: Scope, receive: Receive, send: Send) -> None:
        try:
            await super().__call__(scope, receive, send)
        except* SendTimeoutError:  # (in an exception group from older sse-starlette)
            pass


@router.get(
    "/api/sessions/{session_id}/export.json",
    operation_id="export_json",
    responses={**_NO_EXPORT, **_NOT_FOUND},
)
async def export_result_json(
    session_id: str, store: Store, generation: int | None = None
) -> JSONResponse:
    """The session's result as JSON: every point of each run; units keyed by column names.
    With ``generation`` (the page's link), that generation's result, on screen."""
    session = store.get(session_id)
    result, functionals = await asyncio.to_thread(session.exported, generation, EXPORT_WAIT)
    body, name = await asyncio.to_thread(export_file, result, "json", functionals)
    return JSONResponse(body, headers={"Content-Disposition": f'attachment; filename="{name}"'})


@router.get(
    "/api/sessions/{session_id}/export.csv",
    operation_id="export_csv",
    response_class=CSVResponse,
    responses={
        200: {"description": "one row per trajectory point"},
        **_NO_EXPORT,
        **_NOT_FOUND,
    },
)
async def export_result_csv(session_id: str, store: Store, generation: int | None = None):
    """The session's result as CSV: '#' lines (units per column, the coordinates' names), then
    a row per point of each run: algorithm, cycle, leg, theta, x_1.., y_1.., error, h. With
    ``generation``, as the JSON export."""
    session = store.get(session_id)
    result, _ = await asyncio.to_thread(session.exported, generation, EXPORT_WAIT)
    body, name = await asyncio.to_thread(export_file, result, "csv")  # (off the event loop)
    return CSVResponse(body, headers={"Content-Disposition": f'attachment; filename="{name}"'})


@router.websocket("/api/sessions/{session_id}/scene")
async def scene_socket(websocket: WebSocket, session_id: str) -> None:
    """The session's 3D scene: the viser client's websocket, relayed to the session's viser
    server, which takes no other client (:mod:`jik.app.scene.server`). A socket for no such
    session is closed with 4404, one whose scene cannot be reached with 1011 (another origin or
    host never gets here: :mod:`jik.app.api.security` closes it with 4403 or 4400)."""
    store = getattr(websocket.app.state, "sessions", None)
    try:
        session = store.get(session_id) if store is not None else None
    except SessionNotFound:
        session = None
    if session is None or session.scene is None:
        await close_websocket(
            websocket.receive, websocket.send, 4404, "no such session (it expired or was deleted)"
        )
        return
    try:
        upstream = await session.scene.connect(websocket.scope.get("subprotocols", []))
    except (OSError, websockets.exceptions.WebSocketException, TimeoutError):
        await close_websocket(
            websocket.receive, websocket.send, 1011, "the session's scene is not reachable"
        )
        return
    await websocket.accept(subprotocol=upstream.subprotocol)
    session.users += 1
    try:
        await _relay(websocket, upstream)
    finally:
        session.users -= 1
        session.touch()
        await upstream.close()


async def _relay(websocket: WebSocket, upstream) -> None:
    """Copy messages both ways until either side closes."""

    async def down() -> None:
        async for message in upstream:
            if isinstance(message, bytes):
                await websocket.send_bytes(message)
            else:
                await websocket.send_text(message)

    async def up() -> None:
        while True:
            message = await websocket.receive()
            if message["type"] == "websocket.disconnect":
                return
            data = message.get("bytes")
            await upstream.send(data if data is not None else message.get("text", ""))

    tasks = [asyncio.create_task(down()), asyncio.create_task(up())]
    try:
        await asyncio.wait(tasks, return_when=asyncio.FIRST_COMPLETED)
    finally:
        for task in tasks:
            task.cancel()
        for task in tasks:
            with contextlib.suppress(asyncio.CancelledError, Exception):
                await task
        with contextlib.suppress(Exception):
            await websocket.close()
