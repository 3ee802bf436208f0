"""The API's error responses: every error a request can end in is mapped to its response here,
for the FastAPI handlers (:func:`add_error_handlers`) and the /solve fast path
(:func:`error_response`).

Errors have one shape. Bad input (pydantic validation, or the engine refusing it,
:class:`RequestError`) is HTTP 422 in FastAPI's list format, ``{"detail": [{"loc": ["body",
<field>...], "msg": "<field>: <problem>", "type": ...}]}``, the message always starting with the
field; so is a computation stopped at the time limit (the field that sizes the work, e.g.
``cycles``). A request that finds no free compute slot within the time limit is 503
``{"detail": "server busy: ..."}`` with Retry-After; a failure inside a worker, and anything
unexpected, is 500 ``{"detail": "internal error: ..."}``, never an HTML page or a dropped
connection. An atlas job that is not there is 404, too many atlas jobs 429 with Retry-After.
The dashboard sessions' errors come here too: a refused value (the field it names)
is 422, a session that is not there 404, a full session store 503 with Retry-After. A body
over the size limit is 413 ``{"detail": "request body of ... bytes is larger ..."}``
(:class:`BodyLimit`).
"""

from __future__ import annotations

import logging
from collections.abc import Callable
from typing import Any

from fastapi import FastAPI, HTTPException, Request
from fastapi.exceptions import RequestValidationError
from fastapi.responses import JSONResponse
from starlette.exceptions import HTTPException as StarletteHTTPException
from starlette.types import ASGIApp, Message, Receive, Scope, Send

from jik.app.compute.atlas_jobs import AtlasJobNotFound, AtlasJobsFull
from jik.app.compute.exceptions import ComputeError, RequestError, ServiceUnavailable
from jik.app.compute.schemas import AUGMENTATION_MODELS, ROBOT_MODELS
from jik.app.dashboard.sessions import SessionNotFound, SessionsFull
from jik.engine.exceptions import InvalidInputError

log = logging.getLogger("jik.api")
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
        elif e.get("type") == "json_invalid":  # (loc: the body and the character's position)
            ctx = e.get("ctx") or {}
            where = f" at character {loc[1]}" if len(loc) > 1 else ""
            detail.append({"loc": ["body"], "type": "json_invalid", "msg":
                           f"body: not valid JSON{where}: {ctx.get('error', msg)}"})  # fmt: skip
            continue
        elif e.get("type") == "union_tag_invalid":
            ctx = e.get("ctx") or {}
            msg = f"unknown name {ctx.get('tag')!r}; choose one of {ctx.get('expected_tags')}"
        detail.append({"loc": loc, "msg": f"{_field(loc)}: {msg}", "type": str(e.get("type"))})
    return detail


def validation_error_response(exc: RequestValidationError) -> JSONResponse:
    return JSONResponse(status_code=422, content={"detail": _validation_detail(exc.errors())})


def request_error_response(exc: RequestError) -> JSONResponse:
    loc = ["body", *exc.field.replace("[", ".").replace("]", "").split(".")]
    return JSONResponse(
        status_code=422, content={"detail": [{"loc": loc, "msg": str(exc), "type": "value_error"}]}
    )


#: What FastAPI says of a body it could not parse (a JSON nested too deep, bytes that are not
#: UTF-8), as a 400 of its own: answered as the client's bad input it is, 422 on ``body``.
_UNPARSED = "There was an error parsing the body"


def unparsed_body_response(exc: Exception) -> JSONResponse:
    """422 for a body that is not readable JSON (the reason from the parser's error)."""
    cause = exc.__cause__ if isinstance(exc, StarletteHTTPException) else exc
    if isinstance(cause, RecursionError):
        why = "its arrays or objects are nested too deep"
    elif isinstance(cause, UnicodeDecodeError):
        why = "it is not UTF-8 text"
    else:
        why = "it is not valid JSON"
    return JSONResponse(status_code=422, content={"detail": [{
        "loc": ["body"], "msg": f"body: the body cannot be read as JSON: {why}",
        "type": "json_invalid"}]})  # fmt: skip


def http_error_response(exc: StarletteHTTPException) -> JSONResponse:
    """The framework's HTTP errors (404, 405 with its Allow header, ...) as it answers them,
    but its unparsed-body 400 as :func:`unparsed_body_response`."""
    if exc.status_code == 400 and exc.detail == _UNPARSED:
        return unparsed_body_response(exc)
    return JSONResponse(status_code=exc.status_code, content={"detail": exc.detail},
                        headers=getattr(exc, "headers", None))  # fmt: skip


def invalid_input_response(exc: InvalidInputError) -> JSONResponse:
    """422 for a value the dashboard's model or the engine refused, at the field it names."""
    loc = ["body", *exc.field.split(".")] if exc.field else ["body"]
    return JSONResponse(status_code=422, content={"detail": [
        {"loc": loc, "msg": str(exc), "type": "value_error"}]})  # fmt: skip


def session_not_found_response(exc: SessionNotFound) -> JSONResponse:
    return JSONResponse(status_code=404, content={"detail": (
        f"no dashboard session {exc.args[0]!r} (it expired or never existed); "
        "reload the page to start a new one")})  # fmt: skip


def sessions_full_response(exc: SessionsFull) -> JSONResponse:
    return JSONResponse(status_code=503, content={"detail": str(exc)},
                        headers={"Retry-After": "30"})  # fmt: skip


def atlas_job_not_found_response(exc: AtlasJobNotFound) -> JSONResponse:
    return JSONResponse(status_code=404, content={"detail": (
        f"no atlas job {exc.args[0]!r} (it was cancelled, or ended and expired)")})  # fmt: skip


def atlas_jobs_full_response(exc: AtlasJobsFull) -> JSONResponse:
    return JSONResponse(status_code=429, content={"detail": str(exc)},
                        headers={"Retry-After": "10"})  # fmt: skip


def busy_response(exc: ServiceUnavailable) -> JSONResponse:
    return JSONResponse(status_code=503, content={"detail": str(exc)}, headers={"Retry-After": "1"})


def compute_error_response(exc: ComputeError) -> JSONResponse:
    log.error("computation failed: %s", exc)
    return JSONResponse(status_code=500, content={"detail": f"internal error: {exc}"})


def unexpected_error_response(exc: Exception) -> JSONResponse:
    """500 for an error nothing expected; logged with its traceback (called while handling it)."""
    log.exception("unexpected error")
    return JSONResponse(
        status_code=500, content={"detail": f"internal error: {type(exc).__name__}: {exc}"}
    )


#: Every expected error and its response; anything else is :func:`unexpected_error_response`.
_RESPONSES: dict[type[Exception], Callable[[Any], JSONResponse]] = {
    RequestValidationError: validation_error_response,
    RequestError: request_error_response,
    ServiceUnavailable: busy_response,
    ComputeError: compute_error_response,
    StarletteHTTPException: http_error_response,
    InvalidInputError: invalid_input_response,
    SessionNotFound: session_not_found_response,
    SessionsFull: sessions_full_response,
    AtlasJobNotFound: atlas_job_not_found_response,
    AtlasJobsFull: atlas_jobs_full_response,
}


def error_response(exc: Exception) -> JSONResponse | None:
    """The response for an expected error, None for anything unexpected."""
    for kind, respond in _RESPONSES.items():
        if isinstance(exc, kind):
            return respond(exc)
    return None


def _handler(respond: Callable[[Any], JSONResponse]):
    # A coroutine: Starlette would run a plain function in a thread, where the traceback that
    # unexpected_error_response logs is not the current exception.
    async def handle(request: Request, exc: Exception) -> JSONResponse:
        return respond(exc)

    return handle


def add_error_handlers(app: FastAPI) -> None:
    """Make the mapping above the app's exception handlers (500 for anything else)."""
    for kind, respond in _RESPONSES.items():
        app.add_exception_handler(kind, _handler(respond))
    app.add_exception_handler(Exception, _handler(unexpected_error_response))


def _too_large(detail: str) -> JSONResponse:
    return JSONResponse(status_code=413, content={"detail": detail})


class _TooLarge(HTTPException):
    """Raised while reading an over-long body; an HTTPException so that FastAPI's routes pass it
    on (to their 413 handler) instead of reporting a body they could not parse."""


class BodyLimit:
    """ASGI middleware: a request body over ``limit`` bytes gets a JSON 413.

    A Content-Length over the limit is answered before the body is read; a body sent without a
    length is counted as it is read and cut off at the limit.
    """

    def __init__(self, app: ASGIApp, limit: int) -> None:
        self.app = app
        self.limit = limit

    def _message(self, size: str) -> str:
        return (
            f"request body of {size} bytes is larger than the limit of {self.limit} bytes; "
            "send a smaller request"
        )

    async def __call__(self, scope: Scope, receive: Receive, send: Send) -> None:
        if scope["type"] != "http":
            await self.app(scope, receive, send)
            return
        for name, value in scope.get("headers", ()):
            if name == b"content-length" and value.isdigit() and int(value) > self.limit:
                await _too_large(self._message(str(int(value))))(scope, receive, send)
                return
        seen = 0
        started = False

        async def counted() -> Message:
            nonlocal seen
            message = await receive()
            seen += len(message.get("body", b""))
            if seen > self.limit:
                raise _TooLarge(413, self._message(f"more than {self.limit}"))
            return message

        async def watched(message: Message) -> None:
            nonlocal started
            started = started or message["type"] == "http.response.start"
            await send(message)

        try:
            await self.app(scope, counted, watched)
        except _TooLarge as exc:  # from the /solve fast path, which has no handlers
            if started:
                raise
            await _too_large(exc.detail)(scope, receive, send)
