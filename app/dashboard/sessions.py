"""Dashboard sessions: one :class:`~jik.app.dashboard.Dashboard` (and its 3D scene) per tab.

Every browser tab creates its own session from the state in its URL; the session's id is a
random token that only that tab holds. Sessions are bounded in number (``max_sessions``) and
expire when idle: a session with no page listening (event stream) and no scene connected,
untouched for ``session_idle_seconds``, is stopped. When the store is full, the session idle the
longest makes room; if every session is in use the new one is refused (the route answers 503).
"""

from __future__ import annotations

import secrets
import threading
import time
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from typing import Any

from ..compute.settings import Settings
from .model import default_state, updated_state
from .offload import FairSlots
from .session import Dashboard


class ExportUnavailable(Exception):
    """No result of a session's current state to export: ``status`` 409 when its computation
    failed, 503 when it is not finished yet."""

    def __init__(self, status: int, detail: str) -> None:
        super().__init__(detail)
        self.status = status


class SessionNotFound(KeyError):
    """No session with that id (never created, or expired)."""


class SessionsFull(RuntimeError):
    """Every session slot is in use; the message says how many and what to do."""


@dataclass
class Session:
    """One tab's dashboard and, when the server draws scenes, its viser scene."""

    id: str
    dashboard: Dashboard
    scene: Any = None  # a jik.app.scene.DashboardScene (.connect(), .stop()), or None
    touched: float = field(default_factory=time.monotonic)
    #: Open event streams and scene connections: a session with any is in use.
    users: int = 0

    def touch(self) -> None:
        self.touched = time.monotonic()

    def stop(self) -> None:
        if self.scene is not None:
            self.scene.stop()
        self.dashboard.stop()

    def exported(self, generation: int | None, wait: float) -> tuple[Any, Any]:
        """The result to export and its functionals: with ``generation``, that generation's,
        the result on screen that the page's link names, at once; else the current state's,
        once in (waiting up to ``wait`` seconds), never an older result in its place.

        Raises
        ------
        ExportUnavailable
            409 when ``generation`` is no longer the result on screen, or the current state's
            computation failed (the message says which generation and why); 503 when it has
            not finished in time.
        """
        dashboard = self.dashboard
        result, functionals = dashboard.result, dashboard.functionals
        if generation is not None:
            if result is None or result.generation != generation:
                shown = "none" if result is None else f"generation {result.generation}"
                detail = f"generation {generation} is not the result on screen ({shown})"
                raise ExportUnavailable(409, f"{detail}; export again")
            return result, functionals
        done = dashboard.wait(None, wait)
        error = dashboard.snapshot()["error"]
        if error is not None:
            raise ExportUnavailable(
                409,
                f"generation {error.get('generation')} failed: {error.get('message')}; there is "
                "no result of the current state to export (change the state, then export)",
            )
        if not done or dashboard.result is None:
            raise ExportUnavailable(503, "no result of the current state computed yet; retry")
        return dashboard.result, dashboard.functionals


class SessionStore:
    """The server's sessions, by id.

    Parameters
    ----------
    settings : Settings, optional
        The server's: ``max_sessions``, ``session_idle_seconds`` and ``dashboard_computations``
        (how many of the sessions' computations run in their threads at once; the other
        algorithm's runs are the compute pool's); default: the environment's.
    scene_factory : callable, optional
        ``scene_factory(dashboard, low_end)`` starts the 3D scene of a new session (``jik
        serve`` gives :class:`jik.app.scene.DashboardScene`: a viser server on a loopback port);
        without it sessions have no scene.
    pool : ComputePool, optional
        The server's compute pool (:class:`jik.app.compute.pool.ComputePool`), which the
        dashboards share with the API; without it each session computes in its own thread.
    """

    def __init__(
        self,
        settings: Settings | None = None,
        scene_factory: Callable[[Dashboard, bool], Any] | None = None,
        pool: Any = None,
    ) -> None:
        self.settings = settings or Settings()
        self._scene_factory = scene_factory
        self._sessions: dict[str, Session] = {}
        self._lock = threading.Lock()
        self._pool = pool
        self._slots = FairSlots(self.settings.dashboard_computations)
        self._closed = threading.Event()
        self._reaper: threading.Thread | None = None
        #: Called with a session's id when it ends (deleted, expired, evicted, closed): what
        #: else it started stops too (its atlas jobs, :meth:`when_ended`).
        self._ended: dict[Callable[[str], None], None] = {}

    def __len__(self) -> int:
        return len(self._sessions)

    def create(self, patch: Mapping[str, object] | None = None, low_end: bool = False) -> Session:
        """A new session whose state is the defaults changed by ``patch`` (validated first);
        ``low_end``: its scene is drawn for a software renderer.

        Raises
        ------
        InvalidInputError
            ``patch`` names an unknown field or a value the registry refuses.
        SessionsFull
            Every slot holds a session in use.
        """
        state = default_state()
        if patch:
            state = updated_state(state, patch)
        self.expire()
        with self._lock:
            if len(self._sessions) >= self.settings.max_sessions:
                self._evict_idlest()
            session_id = secrets.token_urlsafe(16)
            dashboard = Dashboard(
                state, pool=self._pool, slots=self._slots, time_limit=self.settings.timeout
            )
            session = Session(session_id, dashboard)
            self._sessions[session_id] = session
        if self._scene_factory is not None:
            session.scene = self._scene_factory(dashboard, low_end)
        dashboard.start()
        self._start_reaper()
        return session

    def _start_reaper(self) -> None:
        """Expire idle sessions every quarter of the idle limit (at most every 30 s), so that a
        server nobody opens a new tab on still frees them."""
        with self._lock:
            if self._reaper is not None:
                return
            period = min(30.0, self.settings.session_idle_seconds / 4)

            def reap() -> None:
                while not self._closed.wait(period):
                    self.expire()

            self._reaper = threading.Thread(target=reap, name="jik-session-reaper", daemon=True)
            self._reaper.start()

    def get(self, session_id: str) -> Session:
        """The session ``session_id``, touched; :class:`SessionNotFound` if there is none."""
        with self._lock:
            session = self._sessions.get(session_id)
        if session is None:
            raise SessionNotFound(session_id)
        session.touch()
        return session

    def when_ended(self, callback: Callable[[str], None]) -> None:
        """Call ``callback(session_id)`` when a session ends (once per callback)."""
        self._ended[callback] = None

    def _end(self, session: Session) -> None:
        session.stop()
        for callback in list(self._ended):
            callback(session.id)

    def delete(self, session_id: str) -> None:
        with self._lock:
            session = self._sessions.pop(session_id, None)
        if session is None:
            raise SessionNotFound(session_id)
        self._end(session)

    def expire(self) -> int:
        """Stop the sessions idle for longer than the limit; how many were stopped."""
        deadline = time.monotonic() - self.settings.session_idle_seconds
        with self._lock:
            old = [s for s in self._sessions.values() if s.users == 0 and s.touched < deadline]
            for session in old:
                del self._sessions[session.id]
        for session in old:
            self._end(session)
        return len(old)

    def _evict_idlest(self) -> None:
        """Make room (with the lock held): stop the session unused the longest."""
        idle = [s for s in self._sessions.values() if s.users == 0]
        if not idle:
            raise SessionsFull(
                f"the server has {len(self._sessions)} dashboard sessions in use, its limit "
                "(JIK_MAX_SESSIONS); close a tab or try again later"
            )
        oldest = min(idle, key=lambda s: s.touched)
        del self._sessions[oldest.id]
        threading.Thread(
            target=self._end, args=(oldest,), name="jik-session-stop", daemon=True
        ).start()

    def close(self) -> None:
        """Stop every session (the compute pool is the app's, closed with it)."""
        self._closed.set()
        with self._lock:
            sessions, self._sessions = list(self._sessions.values()), {}
        for session in sessions:
            self._end(session)
