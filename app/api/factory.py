"""The FastAPI application: ``create_app()`` wires the routers, the error handlers and the pool.

Errors have one shape. Bad input (pydantic validation, or the engine refusing it) is HTTP 422 in
FastAPI's list format, ``{"detail": [{"loc": ["body", <field>...], "msg": "<field>: <problem>",
"type": ...}]}``, the message always starting with the field; so is a computation stopped at the
time limit (the field that sizes the work, e.g. ``cycles``). A request that finds no free compute
slot within the time limit is 503 ``{"detail": "server busy: ..."}`` with Retry-After; anything
unexpected is 500 ``{"detail": "internal error: ..."}``, never an HTML page or a dropped
connection. A body over 1 MiB is 413 ``{"detail": "request body of ... bytes is larger ..."}``.
"""

from __future__ import annotations

import logging
from contextlib import asynccontextmanager

from fastapi import FastAPI, Request
from fastapi.exceptions import RequestValidationError
from fastapi.responses import JSONResponse
from fastapi_offline import FastAPIOffline

from jik import __version__
from jik.app.api.errors import (
    BodyLimit,
    busy_response,
    compute_error_response,
    request_error_response,
)
from jik.app.api.fastpath import SolveFastPath
from jik.app.api.routes import dashboard, health, repeatability, robots, sessions, solve, synthesize
from jik.app.compute.exceptions import ComputeError, RequestError, ServiceUnavailable
from jik.app.compute.pool import ComputePool
from jik.app.compute.schemas import AUGMENTATION_MODELS, ROBOT_MODELS
from jik.app.compute.settings import Settings, env_flag

log = logging.getLogger("jik.api")
#: Largest request body accepted (413 beyond): the largest valid request is a few kilobytes.
MAX_BODY_BYTES = 1 << 20
_TAGS = set(ROBOT_MODELS) | set(AUGMENTATION_MODELS)


def _field(loc) -> str:
    """Field path of a pydantic location: ``("body", "robot", "manipulator2", "l")`` -> ``robot.l``.

    Indices become ``x0[2]``; the discriminator tag of a union member is dropped.
    """
    parts = [str(p) for p in loc if p != "body"]
    if len(parts) > 2 and parts[0] in ("robot", "augmentation") and parts[1] in _TAGS:
        del parts[1]
    out: list[str] = []
    for p in parts:
        if p.isdigit() and out:
            out[-1] += f"[{p}]"
        else:
            out.append(p)
    return ".".join(out) or "body"


def _validation_detail(errors) -> list[dict]:
    detail = []
    for e in errors:
        loc = list(e.get("loc", ()))
        msg = str(e.get("msg", "invalid"))
        if e.get("type") == "extra_forbidden":
            msg = "unknown field; remove it"
        elif e.get("type") == "union_tag_invalid":
            ctx = e.get("ctx") or {}
            msg = f"unknown name {ctx.get('tag')!r}; choose one of {ctx.get('expected_tags')}"
        detail.append({"loc": loc, "msg": f"{_field(loc)}: {msg}", "type": str(e.get("type"))})
    return detail


def create_app(settings: Settings | None = None, fast_solve: bool | None = None) -> FastAPI:
    """The jik REST API. ``settings`` (default: from the environment) sizes the compute pool;
    ``fast_solve`` serves well-formed /solve requests on a short path (:mod:`jik.app.api.fastpath`;
    default on, ``JIK_FAST_SOLVE=0`` turns it off)."""
    if fast_solve is None:
        fast_solve = env_flag("JIK_FAST_SOLVE")
    pool = ComputePool(settings)

    @asynccontextmanager
    async def lifespan(app: FastAPI):
        await pool.warm_up()
        yield
        pool.close()
        store = getattr(app.state, "sessions", None)
        if store is not None:
            store.close()

    # /docs and /redoc with Swagger UI's and ReDoc's files from the fastapi-offline package: the
    # API's documentation works on a machine without internet, and loads nothing from a CDN.
    app = FastAPIOffline(
        title="jik",
        version=__version__,
        summary="Repeatable Jacobian inverse kinematics: pseudoinverse vs extended Jacobian, "
        "and synthesis of augmenting maps (Tchon, Karpinska, Janiak 2009).",
        lifespan=lifespan,
    )
    app.state.pool = pool

    @app.exception_handler(RequestValidationError)
    async def _invalid(request: Request, exc: RequestValidationError) -> JSONResponse:
        return JSONResponse(status_code=422, content={"detail": _validation_detail(exc.errors())})

    @app.exception_handler(RequestError)
    async def _refused(request: Request, exc: RequestError) -> JSONResponse:
        return request_error_response(exc)

    @app.exception_handler(ServiceUnavailable)
    async def _busy(request: Request, exc: ServiceUnavailable) -> JSONResponse:
        return busy_response(exc)

    @app.exception_handler(ComputeError)
    async def _compute(request: Request, exc: ComputeError) -> JSONResponse:
        return compute_error_response(exc)

    @app.exception_handler(Exception)
    async def _unexpected(request: Request, exc: Exception) -> JSONResponse:
        log.exception("unexpected error")
        return JSONResponse(
            status_code=500, content={"detail": f"internal error: {type(exc).__name__}: {exc}"}
        )

    for module in (health, robots, solve, repeatability, synthesize):
        app.include_router(module.router)
    app.include_router(dashboard.router)
    app.include_router(sessions.router)
    if fast_solve:
        app.add_middleware(SolveFastPath, pool=pool)
    app.add_middleware(BodyLimit, limit=MAX_BODY_BYTES)  # outermost: before any body is read
    return app
