"""The API's error responses: every error a request can end in is mapped to its response here,
for the FastAPI handlers (:func:`add_error_handlers`) and the /solve fast path
(:func:`error_response`).

Errors have one shape. Bad input (pydantic validation, or the engine refusing it,
:class:`RequestError`) is HTTP 422 in FastAPI's list format, ``{"detail": [{"loc": ["body",
<field>...], "msg": "<field>: <problem>", "type": ...}]}``, the message always starting with
the field as :func:`~jik.app.compute.schemas.wording.field_text` writes it
(``algorithm_parameters.rest[3]``; ``loc`` as FastAPI's, ``[..., "rest", 3]``); so is a
computation stopped at the time limit (the field that sizes the work, e.g. ``cycles``). A
request that finds no free compute slot within the time limit is 503 ``{"detail": "server busy:
..."}`` with Retry-After; a failure inside a worker, and anything unexpected, is 500
``{"detail": "internal error: ..."}``, never an HTML page or a dropped connection. An atlas job
that is not there is 404, too many atlas jobs 429 with Retry-After. The dashboard sessions'
errors come here too: a refused value (the field it names) is 422, a session that is not there
404, a full session store 503 with Retry-After, an export with no result of the current state
409 (its computation failed) or 503 (not yet, with Retry-After). A body over the size limit is
413 ``{"detail": "request body of ... bytes is larger ..."}`` (:mod:`jik.app.api.security`).
The messages of validation errors are written by :mod:`jik.app.api.validation`.
"""

from __future__ import annotations

import json
import logging
import sys
from collections.abc import Callable
from typing import Any

from fastapi import FastAPI, Request
from fastapi.exceptions import RequestValidationError
from fastapi.responses import JSONResponse
from starlette.exceptions import HTTPException as StarletteHTTPException

from ...engine.exceptions import InvalidInputError
from ..compute.atlas_jobs import AtlasJobNotFound, AtlasJobsFull
from ..compute.exceptions import ComputeError, RequestError, ServiceUnavailable
from ..compute.schemas import ErrorResponse
from ..compute.schemas.wording import field_loc, field_text, without_field
from ..dashboard.sessions import ExportUnavailable, SessionNotFound, SessionsFull
from .security import BODIES, CHANGES, routed
from .validation import validation_detail

log = logging.getLogger("jik.api")


def _detail(status: int, detail: object, retry_after: str | None = None) -> JSONResponse:
    """``{"detail": detail}`` with ``status`` (and Retry-After, in seconds, when given)."""
    headers = None if retry_after is None else {"Retry-After": retry_after}
    return JSONResponse(status_code=status, content={"detail": detail}, headers=headers)


def _refused(loc: list[str | int], msg: str, kind: str = "value_error") -> JSONResponse:
    """422 in FastAPI's list format, one error at ``loc``."""
    return _detail(422, [{"loc": loc, "msg": msg, "type": kind}])


def field_error_response(exc: RequestError | InvalidInputError) -> JSONResponse:
    """422 for a value the request's checks, the dashboard's model or the engine refused, at
    the field it names, the message led by that field whoever wrote it (the engine's own
    mention of it, in any notation, dropped: :func:`without_field`)."""
    field = exc.field or ""
    said = f"{field_text(field)}: {without_field(str(exc), field)}" if field else str(exc)
    return _refused(field_loc(field), said)


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
    elif isinstance(cause, ValueError) and not isinstance(cause, json.JSONDecodeError):
        # (json's one other error: Python's bound on converting a long integer)
        why = f"it holds an integer of more than {sys.get_int_max_str_digits()} digits"
    else:
        why = "it is not valid JSON"
    return _refused(["body"], f"body: the body cannot be read as JSON: {why}", "json_invalid")


def http_error_response(exc: StarletteHTTPException) -> JSONResponse:
    """The framework's HTTP errors (404, 405 with its Allow header, ...) as it answers them,
    but its unparsed-body 400 as :func:`unparsed_body_response`."""
    if exc.status_code == 400 and exc.detail == _UNPARSED:
        return unparsed_body_response(exc)
    return JSONResponse({"detail": exc.detail}, exc.status_code, headers=exc.headers)


def compute_error_response(exc: ComputeError) -> JSONResponse:
    log.error("computation failed: %s", exc)
    return _detail(500, f"internal error: {exc}")


def unexpected_error_response(exc: Exception) -> JSONResponse:
    """500 for an error nothing expected; logged with its traceback (called while handling it)."""
    log.exception("unexpected error")
    return _detail(500, f"internal error: {type(exc).__name__}: {exc}")


#: Every expected error and its response; anything else is :func:`unexpected_error_response`.
_RESPONSES: dict[type[Exception], Callable[[Any], JSONResponse]] = {
    RequestValidationError: lambda exc: _detail(422, validation_detail(exc.errors())),
    RequestError: field_error_response,
    ServiceUnavailable: lambda exc: _detail(503, str(exc), retry_after="1"),
    ComputeError: compute_error_response,
    StarletteHTTPException: http_error_response,
    InvalidInputError: field_error_response,
    SessionNotFound: lambda exc: _detail(
        404,
        f"no dashboard session {exc.args[0]!r} (it expired or never existed); "
        "reload the page to start a new one",
    ),
    # (a tab closed or hidden lets go of its session, which a new one may then take at once)
    SessionsFull: lambda exc: _detail(503, str(exc), retry_after="5"),
    ExportUnavailable: lambda exc: _detail(
        exc.status, str(exc), "1" if exc.status == 503 else None
    ),
    AtlasJobNotFound: lambda exc: _detail(404, f"no atlas job {exc.args[0]!r}: {exc.args[1]}"),
    AtlasJobsFull: lambda exc: _detail(429, str(exc), retry_after="10"),
}


def error_response(exc: Exception) -> JSONResponse | None:
    """The response for an expected error, None for anything unexpected."""
    for kind, respond in _RESPONSES.items():
        if isinstance(exc, kind):
            return respond(exc)
    return None


def _allowed_methods(request: Request) -> str:
    """Every method some route takes at the request's path (routes are one per method, and the
    framework's 405 names only the first one's)."""
    methods = ("DELETE", "GET", "HEAD", "OPTIONS", "PATCH", "POST", "PUT")
    return ", ".join(m for m in methods if routed({**request.scope, "method": m}))


def _handler(respond: Callable[[Any], JSONResponse]):
    # A coroutine: Starlette would run a plain function in a thread, where the traceback that
    # unexpected_error_response logs is not the current exception.
    async def handle(request: Request, exc: Exception) -> JSONResponse:
        response = respond(exc)
        if response.status_code == 405:
            response.headers["Allow"] = _allowed_methods(request)
        return response

    return handle


def _error(description: str, schema: str = "ErrorResponse") -> dict:
    ref = {"$ref": f"#/components/schemas/{schema}"}
    return {"description": description, "content": {"application/json": {"schema": ref}}}


#: The errors that checks before the routes answer (:mod:`jik.app.api.security`, the
#: session store), as the OpenAPI document lists them for each operation they apply to.
_ANY_OPERATION = {"400": _error("a host name the server does not answer to")}
_CHANGE = {"403": _error("a change asked from another origin")}
_WITH_BODY = {
    "413": _error("a body over 1 MiB"),
    "415": _error("a body that is not JSON (application/json)", "HTTPValidationError"),
}
_IN_SESSION = {"404": _error("no such session (it expired or never existed)")}
_NEW_SESSION = {"503": _error("every session is in use (JIK_MAX_SESSIONS)")}
_RETRY_AFTER = {"description": "seconds to wait before asking again", "schema": {"type": "integer"}}


def document_errors(app: FastAPI) -> None:
    """Make the app's OpenAPI document list the errors above with the operations' own, each
    error with its JSON body, a 429 or 503 with its Retry-After."""
    make = app.openapi

    def openapi() -> dict[str, Any]:
        if app.openapi_schema is None:
            schema = make()
            schema.setdefault("components", {}).setdefault("schemas", {}).setdefault(
                "ErrorResponse", ErrorResponse.model_json_schema()
            )
            for path, operations in schema.get("paths", {}).items():
                for method, operation in operations.items():
                    responses = operation.setdefault("responses", {})
                    extra = dict(_ANY_OPERATION)
                    if method.upper() in CHANGES:
                        extra |= _CHANGE
                    if method.upper() in BODIES:
                        extra |= _WITH_BODY
                    if "{session_id}" in path:
                        extra |= _IN_SESSION
                    if path == "/api/sessions":
                        extra |= _NEW_SESSION
                    for status, response in extra.items():
                        responses.setdefault(status, response)
                    for status, response in responses.items():  # (every error is JSON)
                        if status[0] in "45":
                            response.setdefault("content", _error("")["content"])
                        if status in ("429", "503"):
                            response.setdefault("headers", {"Retry-After": _RETRY_AFTER})
            app.openapi_schema = schema
        return app.openapi_schema

    app.openapi = openapi  # type: ignore[method-assign]


def add_error_handlers(app: FastAPI) -> None:
    """Make the mapping above the app's exception handlers (500 for anything else)."""
    for kind, respond in _RESPONSES.items():
        app.add_exception_handler(kind, _handler(respond))
    app.add_exception_handler(Exception, _handler(unexpected_error_response))
    document_errors(app)
