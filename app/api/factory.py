"""The FastAPI application: ``create_app()`` wires the routers, the error handlers and the pool.

Every error's response (422, 503, 500, 413) is described and produced in one place,
:mod:`jik.app.api.errors`.
"""

from __future__ import annotations

from contextlib import asynccontextmanager

from fastapi import FastAPI
from fastapi_offline import FastAPIOffline

from jik import __version__

from ..compute.pool import ComputePool
from ..compute.settings import Settings
from .errors import add_error_handlers
from .fastpath import SolveFastPath
from .routes import atlas, computing, dashboard, sessions
from .security import LOOPBACK_HOSTS, SecurityMiddleware


def create_app(settings: Settings | None = None, allowed_hosts: tuple[str, ...] = ()) -> FastAPI:
    """The jik REST API. ``settings`` (default: from the environment) sizes the compute pool and
    says whether well-formed /solve requests take a short path (:mod:`jik.app.api.fastpath`;
    ``fast_solve``, on unless ``JIK_FAST_SOLVE=0``); the server answers to the loopback names,
    ``settings.host_names`` (``JIK_ALLOWED_HOSTS``) and ``allowed_hosts``
    (:mod:`jik.app.api.security`)."""
    settings = settings or Settings()  # (the environment, read here once for the app)
    pool = ComputePool(settings)

    @asynccontextmanager
    async def lifespan(app: FastAPI):
        await pool.warm_up()
        yield
        store = getattr(app.state, "sessions", None)
        if store is not None:  # (first: its dashboards give up their runs in the pool)
            store.close()
        jobs = getattr(app.state, "atlas_jobs", None)
        if jobs is not None:  # (running atlases stop after their chunk)
            jobs.close()
        pool.close()

    # /docs with Swagger UI's files from the fastapi-offline package: the API's documentation
    # works on a machine without internet, and loads nothing from a CDN. No /redoc: ReDoc's
    # bundle draws its side menu's logo from cdn.redoc.ly whatever its options.
    app = FastAPIOffline(
        redoc_url=None,
        title="jik",
        version=__version__,
        summary="Repeatable Jacobian inverse kinematics: pseudoinverse vs extended Jacobian, "
        "and synthesis of augmenting maps (Tchon, Karpinska, Janiak 2009).",
        lifespan=lifespan,
    )
    app.state.pool = pool

    add_error_handlers(app)
    for module in (computing, dashboard, sessions, atlas):
        app.include_router(module.router)
    app.include_router(atlas.session_router)
    if settings.fast_solve:
        app.add_middleware(SolveFastPath, pool=pool)
    # Outermost: hosts, origins, content types and sizes are checked before anything else runs.
    hosts = (*LOOPBACK_HOSTS, *settings.host_names, *allowed_hosts)
    app.add_middleware(SecurityMiddleware, allowed_hosts=hosts)
    return app
