"""The dashboard page: ``/``, its static files, the viser client's page for its 3D scene, and the
paper's errata (``/errata``, ``docs/paper-errata.md`` as HTML).

``GET /`` serves ``static/index.html``; plotly.js comes from the installed plotly package and the
scene's page (``/scene/``) from the installed viser package: nothing is fetched from the network.
Each tab's state lives in its own session (:mod:`jik.app.api.routes.sessions`).
"""

from __future__ import annotations

from functools import cache
from html import escape
from pathlib import Path

import plotly
import viser
from fastapi import APIRouter
from fastapi.responses import FileResponse, HTMLResponse, JSONResponse, Response
from markdown_it import MarkdownIt

from .... import static
from ....docs import paper_errata
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


@cache
def _errata_page() -> str:
    text = paper_errata()
    title = escape(text.partition("\n")[0].lstrip("# ").strip())
    body = MarkdownIt("commonmark", {"html": False}).enable("table").render(text)
    return (
        f'<!doctype html><html lang="en"><head><meta charset="utf-8"><title>jik: {title}</title>'
        '<meta name="viewport" content="width=device-width, initial-scale=1">'
        '<link rel="icon" href="/static/favicon.svg">'
        '<link rel="stylesheet" href="/static/style.css">'
        f'</head><body class="document"><main>{body}</main></body></html>'
    )


@router.get("/errata", response_class=HTMLResponse, tags=["dashboard"])
async def errata() -> HTMLResponse:
    """Where the printed paper and jik disagree, each with the command that shows it: the
    repository's ``docs/paper-errata.md`` as a page (``jik errata`` prints its Markdown)."""
    return HTMLResponse(_errata_page())


@router.get("/api/dashboard/config")
async def config() -> dict:
    """The colour, label and line style of each algorithm, the panels (ids, sizes and help, in
    order), and when a computation shows its progress. (Each session's controls come with its
    state.)"""
    return page_config()
