"""What the routes take from the app, as typed dependencies: its compute pool and session store."""

from __future__ import annotations

from typing import Annotated

from fastapi import Depends, Request

from ..compute.pool import ComputePool
from ..dashboard.sessions import SessionStore


async def pool_of(request: Request) -> ComputePool:
    """The app's compute pool (made by ``create_app``; a coroutine, so no thread is used)."""
    return request.app.state.pool


def store_of(request: Request) -> SessionStore:
    """The app's session store (one without 3D scenes unless ``jik serve`` set one up)."""
    store = getattr(request.app.state, "sessions", None)
    if store is None:
        store = request.app.state.sessions = SessionStore(pool=request.app.state.pool)
    return store


Pool = Annotated[ComputePool, Depends(pool_of)]
Store = Annotated[SessionStore, Depends(store_of)]
