"""``jik serve``: the REST API under uvicorn (and the dashboard's viser scene).

Both ports are taken before anything says the server started: a busy port is reported with the
option that changes it, and the API's socket is handed to uvicorn already bound, so nothing can
take it in between.
"""

from __future__ import annotations

import errno
import signal
import socket

import uvicorn

from jik.app.main import create_app


class PortInUse(RuntimeError):
    """A port that ``jik serve`` needs is taken; the message names the option that changes it."""


def bind(host: str, port: int, option: str) -> socket.socket:
    """A listening TCP socket on ``host:port``; :class:`PortInUse` naming ``option`` if taken."""
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
                f"choose another with {option} PORT"
            ) from None
        raise
    sock.listen(2048)
    return sock


def _stopped(signum: int, frame: object) -> None:
    """The signal that uvicorn raises again after its graceful shutdown: nothing more to do."""


def run_server(host: str = "127.0.0.1", port: int = 8000, scene_port: int = 8080) -> None:
    """Serve the API on ``host:port`` until interrupted (SIGINT or SIGTERM).

    Parameters
    ----------
    host : str
        Address to bind; 127.0.0.1 by default (use 0.0.0.0 in a container).
    port : int
        HTTP port of the API (OpenAPI docs at /docs).
    scene_port : int
        Port of the viser 3D scene.

    Raises
    ------
    PortInUse
        If either port is taken, before anything is started.
    """
    api_socket = bind(host, port, "--port")
    try:
        bind(host, scene_port, "--scene-port").close()  # viser binds it itself, just below
    except PortInUse:
        api_socket.close()
        raise
    app = create_app()
    from jik.app.dashboard import Dashboard
    from jik.app.scene import start_scene
    from jik.app.service import env_flag

    # The dashboard runs one algorithm in a second process (JIK_DASHBOARD_OFFLOAD=0: not).
    app.state.dashboard = Dashboard(offload=env_flag("JIK_DASHBOARD_OFFLOAD"))
    app.state.scene_port = start_scene(app.state.dashboard, host, scene_port).port
    # uvicorn shuts down gracefully on SIGINT and SIGTERM, restores the handlers it found and then
    # raises the signal again. With these handlers that second signal only ends the wait, so the
    # dashboard and its worker processes are stopped below and the command exits 0, as a server
    # asked to stop should (`docker stop` sends SIGTERM).
    previous = {sig: signal.signal(sig, _stopped) for sig in (signal.SIGINT, signal.SIGTERM)}
    try:
        config = uvicorn.Config(app, host=host, port=port, log_level="info", access_log=False)
        uvicorn.Server(config).run(sockets=[api_socket])
    finally:
        for sig, handler in previous.items():
            signal.signal(sig, handler)
        app.state.dashboard.stop()
        api_socket.close()
