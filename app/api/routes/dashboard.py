"""The dashboard page: ``/``, its static files, and the viser client's page for its 3D scene.

``GET /`` serves ``static/index.html``; plotly.js comes from the installed plotly package and the
scene's page (``/scene/``) from the installed viser package: nothing is fetched from the network.
Each tab's state lives in its own session (:mod:`jik.app.api.routes.sessions`).
"""

from __future__ import annotations

from pathlib import Path

import plotly
import viser
from fastapi import APIRouter
from fastapi.responses import FileResponse, JSONResponse, Response

from .... import static
from ...dashboard.help import page_config

router = APIRouter(tags=["dashboard"])

STATIC_DIR = Path(static.__file__).resolve().parent
PLOTLY_JS = Path(plotly.__file__).resolve().parent / "package_data" / "plotly.min.js"
#: The viser client (one self-contained page) of the installed viser package.
VISER_CLIENT = Path(viser.__file__).resolve().parent / "client" / "build" / "index.html"
_MEDIA = {
    ".html": "text/html",
    ".js": "text/javascript",
    ".css": "text/css",
    ".svg": "image/svg+xml",
}


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


@router.get("/scene/", include_in_schema=False)
async def scene_page() -> FileResponse:
    """The viser client's page; the dashboard frames it with ``?websocket=`` set to its
    session's scene (``/api/sessions/{id}/scene``)."""
    return FileResponse(VISER_CLIENT, media_type="text/html")


@router.get("/api/dashboard/config")
async def config() -> dict:
    """The colour, label and line style of each algorithm, the panels (ids, sizes and help, in
    order), and when a computation shows its progress. (Each session's controls come with its
    state.)"""
    return page_config()


__all__ = ["router"]
