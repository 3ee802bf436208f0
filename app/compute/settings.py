"""How the API runs its computations: :class:`Settings`, from ``JIK_*`` environment variables."""

from __future__ import annotations

import os
from dataclasses import dataclass


@dataclass(frozen=True)
class Settings:
    """How the API runs its computations (from the environment by :func:`settings_from_env`).

    ``timeout`` bounds both phases of a request: waiting for a compute slot (then 503 "server
    busy", retry later) and the computation itself (then 422 naming the field that sizes the
    work, e.g. ``cycles``: the request asks for more than the limit allows; the worker is killed
    and replaced).
    """

    workers: int = 2
    timeout: float = 20.0
    batching: bool = True
    batch_window: float = 0.002
    max_batch: int = 64
    #: A batch is split among idle workers only into shares of at least this many requests.
    min_share: int = 4
    #: Address space a worker may use [MB] (0: no limit). A computation that needs more ends
    #: in a 422 naming what to ask for less of; the worker lives on.
    worker_memory: int = 1024


def env_flag(name: str, default: bool = True) -> bool:
    """An on/off environment variable: ``0``, ``false``, ``no`` or ``off`` is off."""
    value = os.environ.get(name)
    if value is None:
        return default
    return value.strip().lower() not in ("0", "false", "no", "off")


def settings_from_env() -> Settings:
    """``JIK_WORKERS`` (default: CPU count, 1..8), ``JIK_TIMEOUT`` [s] (default 20),
    ``JIK_BATCH`` (``0`` disables micro-batching), ``JIK_BATCH_WINDOW_MS`` (default 2),
    ``JIK_WORKER_MEMORY_MB`` (default 1024; 0 for no limit)."""
    env = os.environ
    return Settings(
        workers=max(1, min(8, int(env.get("JIK_WORKERS", os.cpu_count() or 2)))),
        timeout=float(env.get("JIK_TIMEOUT", 20.0)),
        batching=env_flag("JIK_BATCH"),
        batch_window=float(env.get("JIK_BATCH_WINDOW_MS", 2.0)) / 1000.0,
        worker_memory=max(0, int(env.get("JIK_WORKER_MEMORY_MB", Settings.worker_memory))),
    )
