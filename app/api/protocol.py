"""The HTTP protocol ``jik serve`` runs under uvicorn: uvicorn's httptools protocol, with a
deadline for reading and a cap on the size of a request's headers (why uvicorn's own options do
neither, and the figures: ``docs/benchmarks.md``, "Slow and oversized requests").

uvicorn times out an idle keep-alive connection but not one that is sending a request: a client
that opens a connection and sends nothing, or half of its headers, or part of a declared body,
keeps a socket and a task for ever (a "slowloris"). Here every request must arrive whole,
headers and body, within ``read_seconds`` of its first byte (or of the connection, for the first
request), however slowly the bytes trickle in:

- headers not complete by then: the connection is answered ``408 Request Timeout`` and closed;
- headers complete, body not: the connection is closed (the application, still waiting for the
  body, sees the client disconnect; no response can be sent through it any more).

Headers longer than :data:`MAX_HEADER_BYTES` are answered ``431 Request Header Fields Too Large``
at once and the connection is closed. WebSocket upgrades and responses that take long to compute
are not affected: the deadline stops when the request has been read.

A client that pipelines requests and goes away: every request it left unanswered sees the
disconnect (uvicorn tells only the newest one, and the older one being answered wrote to a closed
transport, logging a traceback).
"""

from __future__ import annotations

import asyncio

from uvicorn.protocols.http.httptools_impl import HttpToolsProtocol, RequestResponseCycle

#: Largest request line and headers [bytes]; 431 beyond, as soon as they cross it.
MAX_HEADER_BYTES = 64 * 1024

_TIMEOUT_RESPONSE = (
    b"HTTP/1.1 408 Request Timeout\r\n"
    b"content-type: text/plain; charset=utf-8\r\n"
    b"content-length: 46\r\n"
    b"connection: close\r\n"
    b"\r\n"
    b"request not received in time; send it at once\n"
)
_TOO_LARGE_BODY = b"request headers larger than %d bytes\n" % MAX_HEADER_BYTES
_TOO_LARGE_RESPONSE = (
    b"HTTP/1.1 431 Request Header Fields Too Large\r\n"
    b"content-type: text/plain; charset=utf-8\r\n"
    b"content-length: %d\r\n"
    b"connection: close\r\n"
    b"\r\n%s" % (len(_TOO_LARGE_BODY), _TOO_LARGE_BODY)
)


class ReadDeadlineProtocol(HttpToolsProtocol):
    """uvicorn's httptools protocol with a deadline on reading each request (see the module)."""

    #: Seconds from a request's first byte (or the connection) to its last
    #: (``JIK_READ_SECONDS``, which :func:`with_read_deadline` sets).
    read_seconds: float

    def connection_made(self, transport: asyncio.Transport) -> None:  # type: ignore[override]
        self._read_timer: asyncio.TimerHandle | None = None
        self._header_bytes = 0  # of the request being read, up to its blank line
        self._cycles: list[RequestResponseCycle] = []  # requests read and not yet answered
        super().connection_made(transport)
        self._start_reading()

    def connection_lost(self, exc: Exception | None) -> None:
        self._stop_reading()
        # Every unanswered request is told, not only the newest as uvicorn does (see the module).
        for cycle in self._cycles:
            if not cycle.response_complete:
                cycle.disconnected = True
                cycle.message_event.set()
        self._cycles.clear()
        super().connection_lost(exc)

    def data_received(self, data: bytes) -> None:
        if not self._headers_read:
            end = data.find(b"\r\n\r\n")
            self._header_bytes += len(data) if end < 0 else end
            if self._header_bytes > MAX_HEADER_BYTES:
                self._stop_reading()
                self._refuse(_TOO_LARGE_RESPONSE)
                return
        super().data_received(data)

    def on_message_begin(self) -> None:
        super().on_message_begin()
        self._start_reading()  # the next request on a kept-alive connection has its own deadline

    def on_headers_complete(self) -> None:
        self._headers_read = True
        super().on_headers_complete()
        if self.cycle is not None and self.cycle not in self._cycles:
            self._cycles = [c for c in self._cycles if not c.response_complete] + [self.cycle]

    def on_message_complete(self) -> None:
        self._stop_reading()
        self._headers_read = False  # the next bytes are the next request's
        self._header_bytes = 0
        super().on_message_complete()

    def handle_websocket_upgrade(self) -> None:
        self._stop_reading()
        super().handle_websocket_upgrade()

    def _start_reading(self) -> None:
        self._stop_reading()
        self._headers_read = False
        self._read_timer = self.loop.call_later(self.read_seconds, self._read_too_slow)

    def _stop_reading(self) -> None:
        if self._read_timer is not None:
            self._read_timer.cancel()
            self._read_timer = None

    def _read_too_slow(self) -> None:
        self._read_timer = None
        if self.transport.is_closing():
            return
        self._refuse(_TIMEOUT_RESPONSE if not self._headers_read else b"")

    def _refuse(self, response: bytes) -> None:
        """Close the connection, answering ``response`` first unless a response to an earlier
        request on it is still being sent (its bytes would be mixed with it)."""
        previous_response_pending = self.cycle is not None and not self.cycle.response_complete
        if response and not previous_response_pending:
            self.transport.write(response)
        self.transport.close()


def with_read_deadline(seconds: float) -> type[ReadDeadlineProtocol]:
    """The protocol class for uvicorn's ``http=`` option, with ``seconds`` (positive, as
    :class:`~jik.app.compute.settings.Settings` checks it) to read a request."""
    return type("ReadDeadlineProtocol", (ReadDeadlineProtocol,), {"read_seconds": float(seconds)})
