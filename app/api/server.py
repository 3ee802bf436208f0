"""``jik serve``: the REST API, the dashboard and its 3D scenes under uvicorn, on one port.

The port is taken before anything says the server started: a busy port is reported with the
option that changes it, and the socket is handed to uvicorn already bound, so nothing can take it
in between. Each dashboard session's 3D scene is a viser server on a loopback port of its own,
reached only through the API's proxy (:mod:`jik.app.api.routes.sessions`).
"""

from __future__ import annotations

import errno
import logging
import signal
import socket

import uvicorn

from ..compute.settings import read_environment
from ..dashboard.sessions import SessionStore
from ..scene import DashboardScene
from .factory import create_app
from .protocol import with_read_deadline


class PortInUse(RuntimeError):
    """A port that ``jik serve`` needs is taken; the message names the option that changes it."""


def bind(host: str, port: int) -> socket.socket:
    """A listening TCP socket on ``host:port``; :class:`PortInUse` naming ``--port`` if taken."""
    family = socket.AF_INET6 if ":" in host else socket.AF_INET
    sock = socket.socket(family, socket.SOCK_STREAM)
    sock.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
    try:
        sock.bind((host, port))
    except OSError as error:
        sock.close()
        if error.errno in (errno.EADDRINUSE, errno.EACCES):
            raise PortInUse(
                f"port {port} on {host} is in use or not allowed ({error.strerror}); "
                "choose another with --port PORT"
            ) from None
        raise
    sock.listen(2048)
    return sock


class _NoSocketLines(logging.Filter):
    """Drops uvicorn's line for each websocket (``127.0.0.1:5000 - "WebSocket
    /api/sessions/{id}/scene" [accepted]``), which it writes to its error log whatever
    ``access_log`` says: its path holds the session's id, the one key to the session."""

    def filter(self, record: logging.LogRecord) -> bool:
        return not str(record.msg).startswith('%s - "WebSocket %s"')


_NO_SOCKET_LINES = _NoSocketLines()


def _stopped(signum: int, frame: object) -> None:
    """The signal that uvicorn raises again after its graceful shutdown: nothing more to do."""


def run_server(
    host: str = "127.0.0.1",
    port: int = 8000,
    allowed_hosts: tuple[str, ...] = (),
    forwarded_allow_ips: str | None = None,
) -> None:
    """Serve the API and the dashboard on ``host:port`` until interrupted (SIGINT or SIGTERM).

    Parameters
    ----------
    host : str
        Address to bind; 127.0.0.1 by default (use 0.0.0.0 in a container).
    port : int
        HTTP port of the API (OpenAPI docs at /docs), the page and its scenes.
    allowed_hosts : tuple of str
        Host names the server answers to besides the loopback names and ``JIK_ALLOWED_HOSTS``.
    forwarded_allow_ips : str or None
        Addresses of the reverse proxies whose ``X-Forwarded-For`` and ``X-Forwarded-Proto``
        are believed (comma-separated, ``*`` for any; uvicorn's ``forwarded_allow_ips``). None:
        no proxy; the client is the socket's peer, whatever the headers say (the per-client
        limits count peers).

    Raises
    ------
    PortInUse
        If the port is taken, before anything is started.
    InvalidInputError
        If a ``JIK_*`` variable is not valid (its ``field`` names it), before anything starts.
    """
    settings = read_environment()  # (once; a bad JIK_* variable is refused by its name)
    sock = bind(host, port)
    app = create_app(settings, allowed_hosts=allowed_hosts)
    # The sessions share the app's compute pool (JIK_WORKERS processes) with the API.
    app.state.sessions = SessionStore(settings, scene_factory=DashboardScene, pool=app.state.pool)
    # uvicorn shuts down gracefully on SIGINT and SIGTERM (the lifespan stops the sessions and
    # the workers), restores the handlers it found and then raises the signal again. With these
    # handlers that second signal only ends the wait, and the command exits 0, as a server asked
    # to stop should (`docker stop` sends SIGTERM).
    previous = {sig: signal.signal(sig, _stopped) for sig in (signal.SIGINT, signal.SIGTERM)}
    try:
        config = uvicorn.Config(
            app,
            host=host,
            port=port,
            log_level="info",
            access_log=False,
            # A request must arrive whole within read_seconds (slow senders are cut off).
            http=with_read_deadline(settings.read_seconds),
            # Beyond max_connections uvicorn answers 503 at once instead of queueing.
            limit_concurrency=settings.max_connections,
            # uvicorn believes X-Forwarded-For from 127.0.0.1 unless told otherwise: any local
            # client could then name itself anew with each request.
            proxy_headers=forwarded_allow_ips is not None,
            forwarded_allow_ips=forwarded_allow_ips or "",
        )
        # (after the Config, which sets up uvicorn's loggers; no access log: no request's path)
        logging.getLogger("uvicorn.error").addFilter(_NO_SOCKET_LINES)
        uvicorn.Server(config).run(sockets=[sock])
    finally:
        for sig, handler in previous.items():
            signal.signal(sig, handler)
        sock.close()
