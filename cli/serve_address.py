"""Where ``jik serve`` listens: the checks of ``--host`` and ``--port`` made before anything
starts (each failure one line that names the option), and the dashboard's address, printed once
the server answers.

Only the standard library: the command's parser uses these before the web parts are imported.
"""

from __future__ import annotations

import argparse
import errno
import http.client
import socket
import threading


def port_number(text: str) -> int:
    """``--port``: a TCP port, 1 to 65535 (argparse's type)."""
    try:
        port = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not a port number") from None
    if not 1 <= port <= 65535:
        raise argparse.ArgumentTypeError(f"{port} is not a port (1 to 65535)")
    return port


def _family(host: str) -> socket.AddressFamily:
    """The address family the server binds ``host`` with (an IPv6 address has a colon)."""
    return socket.AF_INET6 if ":" in host else socket.AF_INET


def listen_problem(host: str, port: int) -> str:
    """Why the server could not listen on ``host:port``, or "" if it can.

    A host name that does not resolve, or an address that is not this machine's, is named with
    ``--host``; a port in use or not allowed, with ``--port``. (The server binds again as it
    starts, and reports a port taken in between the same way.)
    """
    try:
        socket.getaddrinfo(host, port, _family(host), socket.SOCK_STREAM)
    except (socket.gaierror, UnicodeError) as error:
        why = getattr(error, "strerror", None) or str(error)
        return f"--host {host}: not an address or a host name that resolves ({why})"
    with socket.socket(_family(host), socket.SOCK_STREAM) as sock:
        sock.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
        try:
            sock.bind((host, port))
        except OSError as error:
            if error.errno in (errno.EADDRINUSE, errno.EACCES):
                return (
                    f"port {port} on {host} is in use or not allowed ({error.strerror}); "
                    "choose another with --port PORT"
                )
            return (
                f"--host {host}: cannot listen there ({error.strerror}); give an address of "
                "this machine (127.0.0.1, the default, or 0.0.0.0 for every interface)"
            )
    return ""


#: Wildcard hosts (every interface) -> the loopback address that reaches them.
_WILDCARDS = {"0.0.0.0": "127.0.0.1", "": "127.0.0.1", "::": "::1"}


def dashboard_url(host: str, port: int) -> str:
    """The address to open in a browser: a wildcard host is reached on the loopback."""
    shown = _WILDCARDS.get(host, host)
    return f"http://[{shown}]:{port}/" if ":" in shown else f"http://{shown}:{port}/"


class Announcer(threading.Thread):
    """Prints the dashboard's address once the server on ``host:port`` answers HTTP.

    It asks ``GET /health`` every 0.1 s (a server in this process, started by the main
    thread, which uvicorn's signal handling needs: nothing else says when it serves) until an
    answer comes or :meth:`stop` is called.
    """

    def __init__(self, host: str, port: int) -> None:
        super().__init__(name="jik-serve-address", daemon=True)
        self.url = dashboard_url(host, port)
        self._target = _WILDCARDS.get(host, host)
        self._port = port
        self._stopped = threading.Event()

    def _answers(self) -> bool:
        connection = http.client.HTTPConnection(self._target, self._port, timeout=5)
        try:
            connection.request("GET", "/health")
            connection.getresponse().read()
        except OSError:
            return False
        finally:
            connection.close()
        return True  # (any answer: the server is serving)

    def run(self) -> None:
        while not self._stopped.is_set():
            if self._answers():
                if not self._stopped.is_set():
                    print(self.message(), flush=True)
                return
            self._stopped.wait(0.1)

    def message(self) -> str:
        return f"jik serve: the dashboard is at {self.url} (API docs: {self.url}docs)"

    def stop(self) -> None:
        self._stopped.set()
