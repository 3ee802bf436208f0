"""The listeners of a :class:`~jik.app.dashboard.session.Dashboard` (the page's event stream,
the 3D scene): subscribing with the latest events replayed, telling every listener of an event,
and waiting for a generation's computation."""

from __future__ import annotations

import threading
from collections.abc import Callable

from .messages import Event
from .model import DashboardState


class Listeners:
    """Subscribers and the latest events of a dashboard (a part of
    :class:`~jik.app.dashboard.session.Dashboard`, and the base of its other parts: its lock,
    state and generation are theirs too)."""

    _cond: threading.Condition
    _listeners: list[Callable[[Event], None]]
    _fast: int  # the first ``_fast`` listeners are the quick ones
    _latest: dict[str, Event]  # the newest event of each kind a new listener is given
    _latest_ahead: dict[str, Event]  # results solved ahead, by robot
    _state: DashboardState
    _generation: int
    _done: int
    start: Callable[[], None]  # (the dashboard's: start its worker)

    def subscribe(
        self, listener: Callable[[Event], None], *, last: bool = False
    ) -> Callable[[], None]:
        """Call ``listener(event)`` on every event (from the worker thread); replay the latest.

        ``last``: a slow listener (the 3D scene draws in it) is called after the others, so
        that it does not hold up the events queued for the page.
        """
        with self._cond:
            if last:
                self._listeners.append(listener)
            else:
                self._listeners.insert(self._fast, listener)
                self._fast += 1
            kinds = ["state", "result", "functionals"]
            if self._failed():  # (a newer generation failed: a new viewer sees why)
                kinds.append("error")
            latest = [self._latest[k] for k in kinds if k in self._latest]
            latest += [e for r, e in self._latest_ahead.items() if r != self._state.robot]
        for event in latest:
            listener(event)
        self.start()

        def unsubscribe() -> None:
            with self._cond:
                if listener in self._listeners:
                    if self._listeners.index(listener) < self._fast:
                        self._fast -= 1
                    self._listeners.remove(listener)

        return unsubscribe

    def wait(self, generation: int | None = None, timeout: float = 30.0) -> bool:
        """Block until the computation of ``generation`` (default: current) has finished."""
        self.start()
        with self._cond:
            target = self._generation if generation is None else generation
            return self._cond.wait_for(lambda: self._done >= target, timeout)

    def _failed(self) -> bool:
        """Whether the latest error is newer than the result on screen (call with the lock)."""
        error, result = self._latest.get("error"), self._latest.get("result")
        return error is not None and (result is None or error.generation > result.generation)

    def _emit(self, event: Event) -> None:
        with self._cond:
            if event.kind in ("state", "result", "functionals", "error"):
                self._latest[event.kind] = event
            listeners = list(self._listeners)
        for listener in listeners:
            listener(event)
