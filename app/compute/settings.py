"""The server's settings: one :class:`Settings`, from the ``JIK_*`` environment variables.

:func:`settings` reads the environment once (pydantic-settings) and every module asks it; a
test or a program that wants other values builds ``Settings(workers=1, ...)`` and passes it on.
"""

from __future__ import annotations

import functools
import os
import re

from pydantic import AliasChoices, Field, ValidationError, field_validator
from pydantic_settings import BaseSettings, SettingsConfigDict

from ...engine.exceptions import InvalidInputError


def cpu_count() -> int:
    """The machine's CPU count (at least 1): the default of ``dashboard_computations``."""
    return max(1, os.cpu_count() or 1)


class Settings(BaseSettings):
    """How the server runs, each field from ``JIK_<FIELD>`` (``JIK_WORKERS=4``).

    ``timeout`` bounds both phases of a request: waiting for a compute slot (then 503 "server
    busy", retry later) and the computation itself (then 422 naming the field that sizes the
    work, e.g. ``cycles``: the request asks for more than the limit allows; the worker is killed
    and replaced).
    """

    model_config = SettingsConfigDict(env_prefix="JIK_", frozen=True, extra="forbid")

    #: Compute worker processes (1..8; default: the CPU count).
    workers: int = Field(default_factory=cpu_count, validate_default=True)
    #: Longest wait for a compute slot, and longest computation [s].
    timeout: float = Field(default=20.0, gt=0)
    #: Micro-batching of concurrent compatible /solve requests (``JIK_BATCH=0``: off).
    batching: bool = Field(default=True, validation_alias=AliasChoices("batching", "JIK_BATCH"))
    #: How long the first /solve of a batch waits for others [ms].
    batch_window_ms: float = Field(default=2.0, ge=0)
    max_batch: int = Field(default=64, ge=1)
    #: A batch is split among idle workers only into shares of at least this many requests.
    min_share: int = Field(default=4, ge=1)
    #: Address space a worker may use [MB] (0: no limit). A computation that needs more ends
    #: in a 422 naming what to ask for less of; the worker lives on.
    worker_memory: int = Field(
        default=1024, ge=0, validation_alias=AliasChoices("worker_memory", "JIK_WORKER_MEMORY_MB")
    )
    #: Longest build of a robot's formulas and their derivatives [s] (then 422 naming the
    #: robot's field); at most half of ``timeout``.
    build_seconds: float = Field(default=5.0, gt=0)
    #: /solve's short path (:mod:`jik.app.api.fastpath`).
    fast_solve: bool = True
    #: Host names the server answers to besides the loopback names (comma-separated).
    allowed_hosts: str = ""
    #: A request must arrive whole within this many seconds (slow senders are cut off).
    read_seconds: float = Field(default=10.0, gt=0)
    #: Open connections and running requests; beyond, uvicorn answers 503 at once.
    max_connections: int = Field(default=1000, ge=1)
    #: Dashboard sessions kept at once, how long an idle one lives [s], and how many of their
    #: computations run in their threads at once (default: the CPU count).
    max_sessions: int = Field(default=32, ge=1)
    session_idle_seconds: float = Field(default=600.0, ge=1.0)
    dashboard_computations: int = Field(default_factory=cpu_count)

    @field_validator("workers")
    @classmethod
    def _clip_workers(cls, value: int) -> int:
        return max(1, min(8, value))

    @property
    def batch_window(self) -> float:
        """``batch_window_ms`` in seconds."""
        return self.batch_window_ms / 1000.0

    @property
    def build_budget(self) -> float:
        """Seconds a robot's formulas may take to build: ``build_seconds``, at most half of
        ``timeout`` (the rest is the computation's)."""
        return min(self.build_seconds, self.timeout / 2)

    @property
    def host_names(self) -> tuple[str, ...]:
        """``allowed_hosts`` as names."""
        return tuple(h.strip() for h in self.allowed_hosts.split(",") if h.strip())


def read_environment() -> Settings:
    """The settings of the ``JIK_*`` environment variables.

    Raises
    ------
    InvalidInputError
        If a variable's value is not valid; its ``field`` is the variable (``JIK_WORKERS``, or
        a setting's own alias: ``JIK_BATCH`` of ``batching``).
    """
    try:
        return Settings()
    except ValidationError as error:
        first = error.errors()[0]
        name = str(first["loc"][0]) if first["loc"] else ""
        field = Settings.model_fields.get(name)
        alias = field.validation_alias if field else None
        choices = alias.choices if isinstance(alias, AliasChoices) else []
        named = [c for c in choices if isinstance(c, str) and c.startswith("JIK_")]
        variable = named[0] if named else f"JIK_{name.upper()}"
        raise InvalidInputError(
            f"{variable}={first.get('input')!r}: {first['msg']}", field=variable
        ) from None


@functools.cache
def settings() -> Settings:
    """The settings of the environment, read once (:func:`read_environment`)."""
    return read_environment()


#: A Host header: a name or an IPv6 address in brackets, and an optional port of digits.
_HOST = re.compile(r"(\[[0-9A-Fa-f:.]+\]|[^:\[\]]+)(?::[0-9]{1,5})?")


def host_name(host: str) -> str:
    """The name of a Host header, which the server's hosts (loopback, ``allowed_hosts``) are
    compared with: ``example.org:8000`` -> ``example.org``, ``[::1]:8000`` -> ``[::1]``; a
    header of another form (``127.0.0.1:80@evil``, ``localhost:``) whole, which no name is."""
    match = _HOST.fullmatch(host)
    port = host[match.end(1) + 1 :] if match else ""
    return match.group(1) if match and (not port or int(port) < 65536) else host
