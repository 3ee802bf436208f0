"""The scenes' viser servers: reachable only through the API's relay, quiet, with no share link.

Each session's :class:`SceneServer` listens on a loopback port of its own, which any program
of the machine, and any web page its browser opens, can dial. Only the API's relay
(``/api/sessions/{id}/scene``, behind :mod:`jik.app.api.security`'s Host and Origin checks)
may talk to it, so every opening handshake on a scene's port must

- carry this process's scene key (:data:`SCENE_KEY`, random, never leaves the process) in
  ``Authorization``, which only :meth:`SceneServer.connect` (the relay) sends;
- carry no ``Origin`` (browsers send one with every websocket; the relay sends none);
- name a loopback host in ``Host`` (a page that rebinds its DNS name names its own).

Anything else, a websocket or a plain HTTP request for viser's files, is answered 403
before viser sees it. viser 1.1 has no option for this: its server calls
``websockets.asyncio.server.serve`` with its own ``process_request``; :func:`_install_guard`
wraps that argument for viser's handlers, and every new server is probed at start (it must
refuse a request without the key), so a viser that stops calling ``serve`` that way fails
closed instead of serving unguarded.

viser prints banners (each server's address, "Server stopped") with rich's console; they go
to the ``jik.scene.viser`` logger at DEBUG instead of the server's log. Its share button (a
public tunnel to this viser instance) is hidden and its share requests are refused.
"""

from __future__ import annotations

import hmac
import http.client
import io
import logging
import secrets
import threading
from collections.abc import Sequence
from http import HTTPStatus
from typing import Any

import rich
import viser
import websockets.asyncio.client
import websockets.asyncio.server
from websockets.typing import Subprotocol

from ..compute.settings import host_name

#: The key the relay presents to the scenes' servers (one per process, see the module's text).
SCENE_KEY = secrets.token_urlsafe(32)
_AUTHORIZATION = f"Bearer {SCENE_KEY}"
_LOOPBACK = frozenset({"127.0.0.1", "localhost", "[::1]"})
_log = logging.getLogger("jik.scene.viser")
_installed = threading.Lock()


def handshake_refusal(headers: Any) -> str | None:
    """Why a handshake on a scene's port is refused (see the module's text), or None.
    ``headers``: websockets' ``Headers`` (a name may come more than once)."""
    if headers.get_all("Origin"):
        return "a scene server takes no browser's request: use /api/sessions/{id}/scene"
    hosts = headers.get_all("Host")
    host = hosts[0] if len(hosts) == 1 else ""
    if host_name(host).lower() not in _LOOPBACK:
        return "a scene server answers to loopback names only"
    keys = headers.get_all("Authorization")
    key = keys[0] if len(keys) == 1 else ""
    if not hmac.compare_digest(key.encode(), _AUTHORIZATION.encode()):
        return "a scene server takes the API's relay only"
    return None


def _guarded(process_request):
    """``process_request`` of a viser server, refusing what :func:`handshake_refusal` does."""

    def guard(connection, request):
        refusal = handshake_refusal(request.headers)
        if refusal is not None:
            return connection.respond(HTTPStatus.FORBIDDEN, refusal + "\n")
        return None if process_request is None else process_request(connection, request)

    return guard


class _GuardedServe(websockets.asyncio.server.serve):
    """websockets' ``serve``, with :func:`_guarded` around the ``process_request`` of viser's
    servers (their handler is defined in a ``viser`` module); other servers are unchanged."""

    def __init__(self, handler, *args, process_request=None, **kwargs) -> None:
        if getattr(handler, "__module__", "").partition(".")[0] == "viser":
            process_request = _guarded(process_request)
        super().__init__(handler, *args, process_request=process_request, **kwargs)


class _ViserLog(io.TextIOBase):
    """A file for rich's console whose lines go to the ``jik.scene.viser`` logger (DEBUG)."""

    def writable(self) -> bool:
        return True

    def write(self, text: str) -> int:
        for line in text.splitlines():
            if line.strip():
                _log.debug("%s", line.rstrip())
        return len(text)


def _install_guard() -> None:
    """Guard every viser server started from now on, and send viser's prints to the log."""
    with _installed:
        if websockets.asyncio.server.serve is not _GuardedServe:
            websockets.asyncio.server.serve = _GuardedServe  # type: ignore[misc]
            rich.reconfigure(file=_ViserLog(), width=100)


class UnguardedSceneServer(RuntimeError):
    """A viser server answered a request without the scene key (see :mod:`jik.app.scene.server`)."""


class SceneServer(viser.ViserServer):
    """A viser server on a loopback port that only the relay reaches (see the module's text)."""

    def __init__(self) -> None:
        _install_guard()
        super().__init__(host="127.0.0.1", port=0, label="jik scene", verbose=False)
        try:
            self._probe()
        except BaseException:
            super().stop()
            raise

    def _probe(self) -> None:
        """Fail closed: a request without the key must be refused."""
        probe = http.client.HTTPConnection("127.0.0.1", self.get_port(), timeout=10)
        try:
            probe.request("GET", "/")
            status = probe.getresponse().status
        finally:
            probe.close()
        if status != HTTPStatus.FORBIDDEN:
            raise UnguardedSceneServer(
                f"the scene server on port {self.get_port()} answered {status} to a request "
                "without the scene key; refusing to serve it (viser's server no longer takes "
                "jik's handshake guard)"
            )

    def request_share_url(self, verbose: bool = True) -> str | None:
        """Never: a share link would open this scene to anyone on the internet."""
        return None

    def connect(self, subprotocols: Sequence[str] | None) -> websockets.asyncio.client.connect:
        """The relay's connection to this server (await it): with the scene key."""
        return websockets.asyncio.client.connect(
            f"ws://127.0.0.1:{self.get_port()}",
            subprotocols=[Subprotocol(p) for p in subprotocols] if subprotocols else None,
            additional_headers={"Authorization": _AUTHORIZATION},
            max_size=None,
            compression=None,
            open_timeout=10,
        )
