"""The compute layer's typed errors; the API's error mapping gives each its HTTP response."""

from .schemas.wording import field_text


class RequestError(ValueError):
    """A request the engine cannot serve: HTTP 422 with a message that names ``field`` (its
    path in either notation, ``x0[1]`` or ``x0.1``; the message writes it as ``x0[1]``)."""

    def __init__(self, field: str, message: str) -> None:
        self.field = field
        self.message = message
        super().__init__(f"{field_text(field)}: {message}")


class ServiceUnavailable(RuntimeError):
    """No compute slot became free within the time limit (or a worker died): HTTP 503."""


class WorkerLost(ServiceUnavailable):
    """A compute worker died or stopped responding (the server's fault, not the request's): it
    is replaced; a request whose worker died is retried once on a fresh one."""


class ComputeError(RuntimeError):
    """An unexpected failure inside a worker: HTTP 500 with its description."""
