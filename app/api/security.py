"""Who may talk to the server: allowed hosts, same-origin changes, JSON bodies of a bounded size,
safe headers.

One ASGI middleware, outermost, in front of every route, the fast path and the scene's
websocket relay (docs/security.md has the threat model):

- **Host.** A request whose ``Host`` names no allowed host is refused (HTTP 400, a websocket is
  closed with 4400): a page of another site that rebinds its DNS name to 127.0.0.1 reaches the
  server under its own name and is stopped here. Allowed by default: ``localhost``,
  ``127.0.0.1`` and ``[::1]``, on any port; more with ``JIK_ALLOWED_HOSTS`` (comma-separated,
  ``*`` for any) or ``jik serve --allowed-host``.
- **Origin.** A browser sends ``Origin`` with every cross-site POST, DELETE and websocket: one
  that does not name the host the request was sent to is refused (403; a websocket closed with
  4403). Requests without ``Origin`` (curl, scripts) are not browsers' and pass.
- **Content type.** A POST or PUT body must be JSON (``application/json``), else 415: a form or
  ``text/plain`` post from another site (which browsers send without asking) is never parsed.
- **Size.** A body over :data:`MAX_BODY_BYTES` is answered 413 (JSON): a ``Content-Length``
  over it before the body is read, a body sent without one as it crosses the limit.
- **Headers.** Every response says ``X-Content-Type-Options: nosniff``, ``Referrer-Policy:
  no-referrer``, and a ``Content-Security-Policy`` with ``frame-ancestors 'self'`` (with
  ``X-Frame-Options: SAMEORIGIN``): only our own page may frame the dashboard and its scene.
  The page and the API load scripts from this server only; the scene's page (viser's client, one
  file with an inline packed script) also runs inline scripts and workers from ``blob:``.
"""

from __future__ import annotations

from collections.abc import Iterable
from urllib.parse import urlsplit

from fastapi import HTTPException
from starlette.responses import JSONResponse
from starlette.routing import Match
from starlette.types import ASGIApp, Message, Receive, Scope, Send

from ..compute.settings import host_name

#: Largest request body accepted (413 beyond): the largest valid request is a few kilobytes.
MAX_BODY_BYTES = 1 << 20
#: Host names allowed by default: the loopback names.
LOOPBACK_HOSTS = ("localhost", "127.0.0.1", "[::1]", "::1")
#: Methods that change something, whose origin must be ours.
CHANGES = frozenset({"POST", "PUT", "PATCH", "DELETE"})
#: Methods whose body must be JSON.
BODIES = frozenset({"POST", "PUT", "PATCH"})
_PAGE_POLICY = (
    "default-src 'self'; script-src 'self'; style-src 'self' 'unsafe-inline'; "
    "img-src 'self' data: blob:; connect-src 'self'; worker-src 'self' blob:; "
    "frame-src 'self'; frame-ancestors 'self'; base-uri 'none'; form-action 'none'; "
    "object-src 'none'"
)
# viser's client: one HTML file whose packed bundle is an inline script that unpacks itself
# (eval of its own code), with workers and textures from blob: URLs and its websocket to us;
# the API's documentation page (Swagger UI), whose bootstrap is an inline script.
_SCENE_POLICY = (
    "default-src 'self'; script-src 'self' 'unsafe-inline' 'unsafe-eval' blob:; "
    "style-src 'self' 'unsafe-inline'; img-src 'self' data: blob:; font-src 'self' data:; "
    "connect-src 'self' data: blob:; worker-src 'self' blob:; frame-ancestors 'self'; "
    "base-uri 'none'; form-action 'none'; object-src 'none'"
)


class SecurityMiddleware:
    """See the module's docstring. ``allowed_hosts``: host names (no port), ``*`` for any."""

    def __init__(self, app: ASGIApp, allowed_hosts: Iterable[str] = LOOPBACK_HOSTS) -> None:
        self.app = app
        # (a name given with its port, 'lab.example:8000', is the name, which Host headers are
        # compared with; an empty one names no host, as in JIK_ALLOWED_HOSTS)
        hosts = {host_name(h.strip()).lower() for h in allowed_hosts if h.strip()}
        self.any_host = "*" in hosts
        self.hosts = frozenset(hosts)

    async def __call__(self, scope: Scope, receive: Receive, send: Send) -> None:
        if scope["type"] not in ("http", "websocket"):
            await self.app(scope, receive, send)
            return
        headers = {k.decode("latin-1").lower(): v.decode("latin-1") for k, v in scope["headers"]}
        host = headers.get("host", "")
        websocket = scope["type"] == "websocket"
        refusal = self._refusal(scope, headers, host, websocket)
        if refusal is not None:
            status, message = refusal
            if websocket:
                await close_websocket(receive, send, 4000 + status, message)
            else:
                await _refused(status, message)(scope, receive, send)
            return
        if websocket:
            await self.app(scope, receive, send)
            return
        path = scope.get("path", "")
        scene_or_docs = path.startswith(("/scene/", "/static-offline-docs")) or path == "/docs"
        policy = (_SCENE_POLICY if scene_or_docs else _PAGE_POLICY).encode()
        started = False
        seen = 0

        async def secured(message: Message) -> None:
            nonlocal started
            if message["type"] == "http.response.start":
                started = True
                extra = [
                    (b"x-content-type-options", b"nosniff"),
                    (b"referrer-policy", b"no-referrer"),
                    (b"x-frame-options", b"SAMEORIGIN"),
                    (b"content-security-policy", policy),
                ]
                message["headers"] = [*message.get("headers", []), *extra]
            await send(message)

        async def counted() -> Message:
            nonlocal seen
            message = await receive()
            seen += len(message.get("body", b""))
            if seen > MAX_BODY_BYTES:
                raise _TooLarge(413, _too_large(f"more than {MAX_BODY_BYTES}"))
            return message

        length = headers.get("content-length", "")
        try:
            if length.isdigit() and int(length) > MAX_BODY_BYTES:
                raise _TooLarge(413, _too_large(str(int(length))))
            await self.app(scope, counted, secured)
        except _TooLarge as exc:  # (its length, or its body read past the limit by the fast path)
            if started:
                raise
            await JSONResponse({"detail": exc.detail}, 413)(scope, receive, secured)

    def _refusal(self, scope: Scope, headers: dict, host: str, websocket: bool):
        """(status, message) of a refused request, or None."""
        if not self.any_host and host_name(host).lower() not in self.hosts:
            return 400, (
                f"host {host!r} is not allowed: the server answers to {sorted(self.hosts)} "
                "(add names with JIK_ALLOWED_HOSTS or jik serve --allowed-host)"
            )
        method = scope.get("method", "GET")
        origin = headers.get("origin")
        if (websocket or method in CHANGES) and origin is not None:
            if origin == "null" or urlsplit(origin).netloc.lower() != host.lower():
                return 403, f"a request from another origin ({origin}) may not change anything"
        if method in BODIES and routed(scope):
            kind = headers.get("content-type", "").split(";")[0].strip().lower()
            if kind != "application/json" and not kind.endswith("+json"):
                return 415, (
                    f"content-type: the body must be JSON (application/json), got "
                    f"{kind or 'none'!r}"
                )
        return None


class _TooLarge(HTTPException):
    """Raised while reading an over-long body; an HTTPException so that FastAPI's routes pass it
    on (to their 413 handler) instead of reporting a body they could not parse."""


def _too_large(size: str) -> str:
    return (
        f"request body of {size} bytes is larger than the limit of {MAX_BODY_BYTES} bytes; "
        "send a smaller request"
    )


def routed(scope: Scope) -> bool:
    """Whether a route of the app takes this method at this path (else the router answers,
    404 or 405 with its Allow header, whatever the body)."""
    app = scope.get("app")
    routes = getattr(getattr(app, "router", None), "routes", None)
    if routes is None:
        return True
    return any(route.matches(scope)[0] == Match.FULL for route in routes)


async def close_websocket(receive: Receive, send: Send, code: int, reason: str) -> None:
    """Accept, then close with ``code`` (4400, 4403; the scene's relay: 4404, 1011): a refused
    handshake reaches a browser's script only as 1006, a close code as itself. Nothing the
    client sends is read."""
    if (await receive())["type"] != "websocket.connect":
        return
    await send({"type": "websocket.accept"})
    # (a close frame's reason is at most 123 bytes of UTF-8)
    short = reason.encode()[:123].decode(errors="ignore")
    await send({"type": "websocket.close", "code": code, "reason": short})


def _refused(status: int, message: str) -> JSONResponse:
    """The JSON answer to a refused request: a 415 in FastAPI's list format, on the header."""
    detail: object = message
    if status == 415:
        loc = ["header", "content-type"]
        detail = [{"loc": loc, "msg": message, "type": "unsupported_media_type"}]
    return JSONResponse({"detail": detail}, status, headers={"X-Content-Type-Options": "nosniff"})
