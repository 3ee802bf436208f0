"""ASGI middleware that refuses a request body over a size limit with a JSON 413."""

from __future__ import annotations

from fastapi import HTTPException
from fastapi.responses import JSONResponse
from starlette.types import ASGIApp, Message, Receive, Scope, Send


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
