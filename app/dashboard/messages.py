"""What a dashboard sends its listeners (events with JSON data, a result's summary), and its
listeners themselves (:class:`Listeners`)."""

from __future__ import annotations

import asyncio
import hashlib
import json
import threading
from collections import OrderedDict
from collections.abc import Callable, Iterator, Mapping
from dataclasses import dataclass

from ...engine.augmentations import h_change
from ...engine.exports import json_values as finite
from .controls import controls, controls_about
from .model import DashboardState
from .runs import DashboardResult

#: Characters of an event's data in each piece of its server-sent event (:func:`sse_pieces`).
PIECE = 64 * 1024


@dataclass(frozen=True)
class Event:
    """A message to the subscribers: ``data`` is the JSON sent to the page, on one line."""

    #: "state" | "progress" | "result" | "functionals" | "error" | "ahead" | "refused" |
    #: "closed" (the dashboard stopped)
    kind: str
    generation: int
    data: str
    result: DashboardResult | None = None

    @classmethod
    def of(cls, kind: str, generation: int, **data) -> Event:
        """The event whose JSON is ``{"type": kind, "generation": generation, **data}``."""
        return cls(kind, generation, to_json({"type": kind, "generation": generation, **data}))


class LatestEvents:
    """The events a listener has not taken yet, at most one of each kind (the newest; of
    ``ahead``, one per robot): a listener that reads slowly, or never, holds a bounded amount of
    memory, and gets the newest of each kind when it reads.

    :meth:`put` may be called from any thread; :meth:`get` is awaited on ``loop``.
    """

    def __init__(self, loop: asyncio.AbstractEventLoop) -> None:
        self._loop = loop
        self._events: OrderedDict[tuple[str, str], Event] = OrderedDict()
        self._ready = asyncio.Event()

    def __len__(self) -> int:
        return len(self._events)

    def put(self, event: Event) -> None:
        try:
            self._loop.call_soon_threadsafe(self._put, event)
        except RuntimeError:  # (the loop is closed: nobody reads any more)
            pass

    def _put(self, event: Event) -> None:
        robot = event.result.state.robot if event.kind == "ahead" and event.result else ""
        key = (event.kind, robot)
        self._events.pop(key, None)
        self._events[key] = event  # (the newest last: the events keep their order)
        self._ready.set()

    async def get(self) -> Event:
        while not self._events:
            self._ready.clear()
            await self._ready.wait()
        return self._events.popitem(last=False)[1]


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


def sse_pieces(event: Event) -> Iterator[bytes]:
    """``event`` as a server-sent event (its ``id`` the generation, one ``data`` line), in pieces
    of at most :data:`PIECE` characters of its data: each encoded when it is asked for, so that
    the streams that send a large event share its text and hold no copy of it."""
    data = event.data
    text = f"id: {event.generation}\nevent: {event.kind}\ndata: "
    for start in range(0, len(data), PIECE):
        text += data[start : start + PIECE]
        if start + PIECE >= len(data):
            text += "\n\n"
        yield text.encode()
        text = ""


def to_json(obj) -> str:
    """``obj`` as JSON, NaN and infinities as null (the engine's ``json_values``): the one place
    where a dashboard's results become JSON (events, exports), so that an undefined h or a diverged
    iterate never reaches an encoder that refuses it."""
    return json.dumps(finite(obj), separators=(",", ":"), allow_nan=False)


def with_figures(message: dict, figures: Mapping[str, str]) -> str:
    """The JSON of ``message`` with the "digests" of already serialized figures (the page
    redraws a panel only when its digest changed) and a "figures" object of them."""
    digests = {k: hashlib.md5(t.encode()).hexdigest()[:16] for k, t in figures.items()}
    message = {**message, "digests": digests}
    body = ",".join(f'"{k}":{t}' for k, t in figures.items())
    return to_json(message)[:-1] + ',"figures":{' + body + "}}"


def summary(result: DashboardResult) -> dict:
    """Numbers shown beside the plots: per algorithm success, message, drift, final x; where a
    run stopped at an input, its ``field`` and the keys of the controls about it."""
    out = {}
    stopped = any(run.field for run in result.runs.values())
    spec = controls(result.state) if stopped else []
    for a, run in result.runs.items():
        out[a] = {
            "success": run.success,
            "message": run.message,
            "drift": [float(d) for d in run.drift],
            "x_final": [float(v) for v in run.x[-1]],
            "h_change": h_change(run.h),
            "points": len(run.theta),
            "seconds": round(run.seconds, 4),
            "cached": bool(result.cached.get(a, False)),
            "field": run.field,
            "controls": controls_about(spec, run.field),
        }
    for a, report in result.limits.items():  # ({"within": bool, "violation": {...} or None})
        out[a]["limits"] = report.as_dict()
    return out
