"""The API's error responses, one mapping for the FastAPI handlers and the /solve fast path.

Bad input that the engine or the service refuses (:class:`RequestError`) is 422 in FastAPI's list
format with the field first in the message; no free compute slot is 503 with Retry-After; a
failure inside a worker is 500 with its description.
"""

from __future__ import annotations

import logging

from fastapi.responses import JSONResponse

from app.service import ComputeError, RequestError, ServiceUnavailable

log = logging.getLogger("jik.api")


def request_error_response(exc: RequestError) -> JSONResponse:
    loc = ["body", *exc.field.replace("[", ".").replace("]", "").split(".")]
    return JSONResponse(
        status_code=422, content={"detail": [{"loc": loc, "msg": str(exc), "type": "value_error"}]}
    )


def busy_response(exc: ServiceUnavailable) -> JSONResponse:
    return JSONResponse(status_code=503, content={"detail": str(exc)}, headers={"Retry-After": "1"})


def compute_error_response(exc: ComputeError) -> JSONResponse:
    log.error("computation failed: %s", exc)
    return JSONResponse(status_code=500, content={"detail": f"internal error: {exc}"})


def error_response(exc: Exception) -> JSONResponse | None:
    """The response for an error of the service, None for anything unexpected."""
    if isinstance(exc, RequestError):
        return request_error_response(exc)
    if isinstance(exc, ServiceUnavailable):
        return busy_response(exc)
    if isinstance(exc, ComputeError):
        return compute_error_response(exc)
    return None
