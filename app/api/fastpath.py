"""POST /solve on a short path: the same contract without the framework's per-request layers.

Under load the latency of /solve is decided by the event loop's time per request: 16 clients
send a wave of requests that is solved as one batch, and the loop handles the wave's requests
one after the other. FastAPI's routing, middleware, dependency handling and response wrapping
take about as long per request as everything else together (``jik bench load``: p50 12.5 ms
with, 9 ms without). This ASGI middleware answers a JSON ``POST /solve`` itself: it validates
the body with the same model, runs it through the same compute pool and maps errors with the
same functions (:mod:`jik.app.api.errors`). Anything else, and any body that fails validation,
goes to the FastAPI route unchanged (the body is replayed), so validation messages and the
OpenAPI description come from one place.
"""

from __future__ import annotations

import json
from typing import Any

from pydantic import TypeAdapter, ValidationError
from starlette.requests import ClientDisconnect, Request
from starlette.responses import Response
from starlette.types import ASGIApp, Message, Receive, Scope, Send

from ..compute.pool import ComputePool
from ..compute.schemas import SolveBody
from .errors import error_response

#: The route's body type, checked here as the route would.
_SOLVE_BODY: TypeAdapter[Any] = TypeAdapter(SolveBody)


def _replay(body: bytes, receive: Receive) -> Receive:
    """A ``receive`` that gives ``body`` once, then whatever the client sends next."""
    sent = False

    async def replay() -> Message:
        nonlocal sent
        if not sent:
            sent = True
            return {"type": "http.request", "body": body, "more_body": False}
        return await receive()

    return replay


class SolveFastPath:
    """ASGI middleware serving well-formed ``POST /solve`` requests directly from the pool.

    ``served`` counts the requests it answered (the rest went to the app).
    """

    def __init__(self, app: ASGIApp, pool: ComputePool) -> None:
        self.app = app
        self.pool = pool
        self.served = 0

    async def __call__(self, scope: Scope, receive: Receive, send: Send) -> None:
        # (a body that is not JSON never gets here: the security middleware, outside, answers 415)
        if scope["type"] != "http" or scope["path"] != "/solve" or scope["method"] != "POST":
            await self.app(scope, receive, send)
            return
        try:
            body = await Request(scope, receive).body()
        except ClientDisconnect:
            return
        try:
            req = _SOLVE_BODY.validate_python(json.loads(body))  # as FastAPI reads the body
        except (ValueError, RecursionError, ValidationError):  # the route says what is wrong
            await self.app(scope, _replay(body, receive), send)
            return
        self.served += 1
        response: Any
        try:
            response = Response(await self.pool.solve(req), media_type="application/json")
        except Exception as exc:
            response = error_response(exc)
            if response is None:  # unexpected: the app's 500 handler answers
                raise
        await response(scope, receive, send)
