"""The dashboard page: ``/``, its static files, and the live state over server-sent events.

``GET /`` serves ``static/index.html``; plotly.js comes from the installed plotly package, the
3D scene from viser on the scene port: nothing is fetched from the network. The page changes the
state with ``POST /api/dashboard/state`` and follows it on ``GET /api/dashboard/events``; it holds
the scene's animation still while the pointer is on its controls (``POST /api/dashboard/hold``).
"""

from __future__ import annotations

import asyncio
from pathlib import Path

import plotly
from fastapi import APIRouter, FastAPI, Request
from fastapi.responses import (
    FileResponse,
    JSONResponse,
    PlainTextResponse,
    Response,
    StreamingResponse,
)

from jik import static
from jik.app.dashboard import (
    COLORS,
    LABELS,
    MAX_DASHBOARD_CYCLES,
    Dashboard,
    Event,
    export_csv,
    export_json,
)
from jik.app.schemas import HoldRequest, HoldResponse
from jik.engine.exceptions import InvalidInputError

router = APIRouter(tags=["dashboard"])

STATIC_DIR = Path(static.__file__).resolve().parent
PLOTLY_JS = Path(plotly.__file__).resolve().parent / "package_data" / "plotly.min.js"
_MEDIA = {
    ".html": "text/html",
    ".js": "text/javascript",
    ".css": "text/css",
    ".svg": "image/svg+xml",
}
#: Seconds between keep-alive comments on the event stream.
HEARTBEAT = 15.0


def dashboard_for(app: FastAPI) -> Dashboard:
    """The app's one :class:`Dashboard`, created on first use."""
    dashboard = getattr(app.state, "dashboard", None)
    if dashboard is None:
        dashboard = app.state.dashboard = Dashboard()
    return dashboard


@router.get("/", include_in_schema=False)
async def index() -> FileResponse:
    return FileResponse(STATIC_DIR / "index.html", media_type="text/html")


@router.get("/static/vendor/plotly.min.js", include_in_schema=False)
async def plotly_js() -> FileResponse:
    """plotly.js of the installed plotly package (no CDN)."""
    return FileResponse(PLOTLY_JS, media_type="text/javascript")


@router.get("/static/{name}", include_in_schema=False)
async def static_file(name: str) -> Response:
    path = STATIC_DIR / name
    if path.suffix not in _MEDIA or path.parent != STATIC_DIR or not path.is_file():
        return JSONResponse(status_code=404, content={"detail": f"no static file {name!r}"})
    return FileResponse(path, media_type=_MEDIA[path.suffix])


@router.get("/api/dashboard/config")
async def config(request: Request) -> dict:
    """Where the page finds the 3D scene, and the colour of each algorithm."""
    return {
        "scene_port": getattr(request.app.state, "scene_port", None),
        "colors": COLORS,
        "labels": LABELS,
        "max_cycles": MAX_DASHBOARD_CYCLES,
    }


@router.get("/api/dashboard/state")
async def get_state(request: Request) -> dict:
    """The current state, its generation and the summary of the last computed result."""
    return dashboard_for(request.app).snapshot()


@router.post("/api/dashboard/state")
async def post_state(request: Request) -> JSONResponse:
    """Change some controls: ``{"gamma": 2}``, ``{"x0": [...]}``, ``{"robot": "manipulator1"}``.

    The body is a partial :class:`~jik.app.dashboard.DashboardState`; the answer is the new
    generation and state (422 with the engine's message for a value it refuses).
    """
    try:
        patch = await request.json()
    except ValueError:
        return _invalid("body", "the body must be a JSON object")
    if not isinstance(patch, dict):
        return _invalid("body", "the body must be a JSON object of dashboard fields")
    try:
        generation, state = dashboard_for(request.app).update(patch, source="page")
    except InvalidInputError as exc:
        return _invalid(_field_of(str(exc), patch), str(exc))
    return JSONResponse({"generation": generation, "state": state.as_dict()})


@router.post("/api/dashboard/hold", response_model=HoldResponse)
async def post_hold(body: HoldRequest, request: Request) -> HoldResponse | JSONResponse:
    """Hold the 3D scene's animation still for ``seconds`` (0 ends the hold).

    The page holds it while the pointer is on its controls, so that a change is computed and
    drawn without the scene's frames taking the CPU (see :meth:`jik.app.dashboard.Dashboard.hold`).
    """
    try:
        held = dashboard_for(request.app).hold(body.holder, body.seconds)
    except InvalidInputError as exc:  # (too many holders)
        return _invalid("holder", str(exc))
    return HoldResponse(held_seconds=held)


def _field_of(message: str, patch: dict) -> str:
    for key in patch:
        if message.startswith(key) or f" {key}" in message:
            return key
    return next(iter(patch), "body")


def _invalid(field: str, message: str) -> JSONResponse:
    return JSONResponse(
        status_code=422,
        content={"detail": [{"loc": ["body", field], "msg": message, "type": "value_error"}]},
    )


#: The events the page follows.
PAGE_EVENTS = ("state", "progress", "result", "functionals", "error", "ahead")


@router.get("/api/dashboard/events")
async def events(request: Request) -> StreamingResponse:
    """Server-sent events: ``state``, ``progress``, ``result``, ``functionals``, ``error``,
    ``ahead``.

    Each event's data is JSON; a ``result`` carries every panel as a plotly figure, an
    ``ahead`` the panels of another robot's default state, solved ahead for a switch.
    """
    dashboard = dashboard_for(request.app)
    loop = asyncio.get_running_loop()
    queue: asyncio.Queue[Event] = asyncio.Queue()

    def listener(event: Event) -> None:
        loop.call_soon_threadsafe(queue.put_nowait, event)

    unsubscribe = dashboard.subscribe(listener)

    async def stream():
        try:
            yield "retry: 1000\n\n"
            while True:
                try:
                    event = await asyncio.wait_for(queue.get(), HEARTBEAT)
                except TimeoutError:
                    if await request.is_disconnected():
                        return
                    yield ": keep-alive\n\n"
                    continue
                # A newer result makes queued progress of older generations pointless.
                if event.kind == "progress" and event.generation < dashboard.generation:
                    continue
                if event.kind not in PAGE_EVENTS:
                    continue
                yield f"event: {event.kind}\nid: {event.generation}\ndata: {event.data}\n\n"
        finally:
            unsubscribe()

    return StreamingResponse(
        stream(),
        media_type="text/event-stream",
        headers={"Cache-Control": "no-cache", "X-Accel-Buffering": "no"},
    )


async def _finished(request: Request):
    """The live dashboard, after waiting (up to 60 s) for its first result."""
    dashboard = dashboard_for(request.app)
    if dashboard.result is None:
        await asyncio.to_thread(dashboard.wait, None, 60.0)
    return dashboard


@router.get("/api/dashboard/export.json")
async def export_result_json(request: Request) -> JSONResponse:
    """The current result, every trajectory point of both algorithms, as JSON."""
    dashboard = await _finished(request)
    if dashboard.result is None:
        return JSONResponse(status_code=503, content={"detail": "no result computed yet"})
    body = export_json(dashboard.result, dashboard.functionals)
    return JSONResponse(
        body, headers={"Content-Disposition": 'attachment; filename="jik-result.json"'}
    )


@router.get("/api/dashboard/export.csv")
async def export_result_csv(request: Request) -> PlainTextResponse:
    """The current result as CSV: one row per trajectory point and algorithm."""
    dashboard = await _finished(request)
    if dashboard.result is None:
        return PlainTextResponse("no result computed yet\n", status_code=503)
    return PlainTextResponse(
        export_csv(dashboard.result),
        media_type="text/csv",
        headers={"Content-Disposition": 'attachment; filename="jik-result.csv"'},
    )


__all__ = ["dashboard_for", "router"]
