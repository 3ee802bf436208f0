"""One session's live dashboard: its state, a worker thread that computes each change, and the
listeners (the page's event stream, the scene) it tells.

Every change is validated (:mod:`jik.app.dashboard.model`), bumps a generation counter and wakes
the worker, which solves the chosen algorithms (:func:`jik.app.dashboard.results.compute`),
builds the figures once and pushes them to every listener; a newer change cancels a stale
computation between legs. The second phase (:mod:`.second_phase`) and solving ahead
(:mod:`.ahead`) are the mixins :class:`Dashboard` is made of, sharing its lock and generation.
"""

from __future__ import annotations

import contextlib
import json
import logging
import math
import threading
import time
from collections.abc import Callable, Mapping
from typing import Any, NoReturn

from ...engine.exceptions import InvalidInputError, JikError
from ..compute.exceptions import ServiceUnavailable
from .ahead import SolvingAhead
from .algorithms import COLORS, LABELS, cache_key, runs_key
from .analysis import built_map, expensive_map
from .controls import controls_message
from .figures import figure_specs, gamma_free_panels
from .functionals import functionals_key
from .messages import Event, finite, summary, with_figures
from .model import DashboardState, default_state, updated_state, validate
from .offload import FairSlots, OffloadLane
from .plotting import PANELS, figure_json, keep_ranges
from .results import compute
from .runs import Cancelled, DashboardResult
from .second_phase import SecondPhaseControl
from .verdict import verdict

log = logging.getLogger("jik.dashboard")
#: Seconds the worker waits after a change for a newer one (short: the page already coalesces a
#: slider drag into one request in flight at a time).
DEBOUNCE = 0.002


class Dashboard(SecondPhaseControl, SolvingAhead):
    """One session's live dashboard: one state, a worker thread, and subscribers.

    Parameters
    ----------
    state : DashboardState, optional
        Initial state (registry defaults of :data:`DEFAULT_ROBOT`).
    pool : ComputePool, optional
        The server's compute pool (:class:`jik.app.compute.pool.ComputePool`, shared with the API
        and the other dashboards): one algorithm runs there, in this dashboard's own lane
        (:class:`~jik.app.dashboard.offload.OffloadLane`); ``jik serve`` gives it.
    slots : FairSlots, optional
        Turns for the computations in the sessions' threads (first come, first served), shared
        by the dashboards of a server.
    """

    def __init__(
        self,
        state: DashboardState | None = None,
        *,
        pool: Any = None,
        slots: FairSlots | None = None,
        time_limit: float | None = None,
    ) -> None:
        self._cond = threading.Condition()
        self._slots = slots
        #: Seconds the runs of a state may take, all its algorithms together (the server's
        #: request time limit; None: no limit), after which the computation stops with an error.
        self._time_limit = time_limit
        self._offload = OffloadLane(pool) if pool is not None else None
        self._state = validate((state or default_state()).as_dict())
        self._generation = 1
        self._done = 0  # last generation whose computation finished (or failed)
        self._announced = 1  # last generation whose state event went out (see update)
        self._changed_at = {1: time.perf_counter()}
        self._cache: dict = {}
        self._figures: dict[tuple[str, str], str] = {}  # (panel, key) -> figure JSON
        # (what the parts share, each typed and described where its part declares it)
        self._listeners, self._fast = [], 0  # (Listeners)
        self._latest = {"state": self._state_event(1, self._state, "initial")}
        self._layouts: dict[str, tuple[tuple, dict]] = {}  # panel -> (robot, task), last layout
        # key -> (E1/E2 functionals or None, their sensitivity)
        self._functionals_cache: dict[str, tuple[dict | None, dict]] = {}
        self._ahead_sent, self._latest_ahead, self._robot_since = {}, {}, 0  # (SolvingAhead)
        self.result, self.functionals, self._grid_before = None, None, None  # (SecondPhaseControl)
        self._second_running = self._second_cancelled = self._rerun = None
        #: What the 3D scene last drew (set by app.scene), for the page and the tests.
        self.scene_status: dict = {}
        self._thread: threading.Thread | None = None
        self._stopped = False

    # -- public API -------------------------------------------------------------------------
    @property
    def state(self) -> DashboardState:
        return self._state

    @property
    def generation(self) -> int:
        return self._generation

    def start(self) -> None:
        """Start the worker thread (idempotent)."""
        with self._cond:
            if self._thread is None:
                self._thread = threading.Thread(
                    target=self._work, name="jik-dashboard", daemon=True
                )
                self._thread.start()

    def stop(self) -> None:
        """End the dashboard: its worker, its runs in the pool; a ``closed`` event tells the
        listeners (a page's event stream ends, and the page starts a new session)."""
        with self._cond:
            if self._stopped:
                return
            self._stopped = True
            self._generation += 1  # (every computation of the session sees itself superseded)
            self._cond.notify_all()
        if self._offload is not None:
            self._offload.close()
        self._emit(Event("closed", self._generation, "{}"))

    def refuse(self, refusal: InvalidInputError, source: str = "page") -> NoReturn:
        """Announce a refused change to every listener as a ``refused`` event (the page and
        the scene show it beside the field, their controls back to the values in force) and
        raise it."""
        with self._cond:
            generation, state = self._generation, self._state
        fields = dict(field=refusal.field, message=str(refusal))
        self._emit(self._state_event(generation, state, source, "refused", **fields))
        raise refusal

    def update(
        self, patch: Mapping[str, object], source: str = "page"
    ) -> tuple[int, DashboardState]:
        """Validate and apply a change; the worker recomputes. Returns (generation, state).
        A change the registry refuses is announced and raised by :meth:`refuse`."""
        refusal: InvalidInputError | None = None
        with self._cond:
            try:
                state = updated_state(self._state, patch)
            except InvalidInputError as exc:
                refusal = exc
            else:
                if state == self._state:
                    return self._generation, state
                self._state = state
                self._generation += 1
                generation = self._generation
                self._changed_at[generation] = time.perf_counter()
                if self._offload is not None:
                    self._offload.newest(generation)
                self._cond.notify_all()
        if refusal is not None:
            self.refuse(refusal, source)
        try:
            self._emit(self._state_event(generation, state, source))
        finally:
            with self._cond:  # (the worker waits for this: its events follow the state's)
                self._announced = max(self._announced, generation)
                self._cond.notify_all()
        self.start()
        return generation, state

    def snapshot(self) -> dict:
        """The current state, the summary of the last result, and the error of a newer
        generation that failed (None when the result is the newest computed)."""
        with self._cond:
            result = self.result
            error = json.loads(self._latest["error"].data) if self._failed() else None
            return finite(
                {
                    "error": error,
                    "generation": self._generation,
                    "computed_generation": None if result is None else result.generation,
                    "state": self._state.as_dict(),
                    "summary": None if result is None else summary(result),
                    "functionals": self.functionals,
                    "second_phase": self._second_status(),
                    "scene": dict(self.scene_status),
                }
            )

    # -- worker -----------------------------------------------------------------------------
    def _state_event(
        self, generation: int, state: DashboardState, source: str, kind: str = "state", **more
    ) -> Event:
        """A ``state`` event (or ``kind``, with ``more``): the state and its controls."""
        message = controls_message(state, more.get("field"))
        data = dict(state=state.as_dict(), source=source, **more, **message)
        return Event.of(kind, generation, **data)

    def _work(self) -> None:
        while True:
            with self._cond:
                while self._done >= self._generation and self._rerun is None:
                    if self._stopped:
                        return
                    self._cond.wait()
                if self._stopped:
                    return
                rerun, self._rerun = self._rerun, None
                if self._done < self._generation:  # (a change: the rerun is superseded)
                    rerun = None
                    # Debounce: wait until no change arrived for DEBOUNCE seconds.
                    while True:
                        seen = self._generation
                        self._cond.wait(DEBOUNCE)
                        if self._generation == seen or self._stopped:
                            break
                # A generation's result or error never goes out before its state event (a
                # page ignores an error of a generation it has not heard of).
                self._cond.wait_for(lambda: self._announced >= self._generation or self._stopped)
                if self._stopped:
                    return
                generation, state = self._generation, self._state
            try:
                if rerun is not None:
                    self._second_phase_again(rerun)
                    continue
                self._compute(generation, state)
                self._prefetch(generation)
            except Exception as exc:  # keep the worker alive; the page shows the message
                log.exception("dashboard computation failed")
                self._failure(generation, f"internal error: {type(exc).__name__}: {exc}")

    def _failure(self, generation: int, message: str) -> None:
        """Announce that ``generation`` failed with ``message``, and which result (if any)
        stays on screen: its generation and state (``shown``, None when there is none)."""
        res = self.result
        shown = (
            None if res is None else {"generation": res.generation, "state": res.state.as_dict()}
        )
        self._emit(Event.of("error", generation, message=message, shown=shown))
        self._finish(generation)

    def _finish(self, generation: int) -> None:
        with self._cond:
            self._done = max(self._done, generation)
            self._cond.notify_all()

    def _solved(self, state: DashboardState, generation: int, **more) -> DashboardResult:
        """:func:`compute` of ``state`` (``more``: its options) in this session's turn
        (:class:`FairSlots`; at once without slots), with its run cache and lane of the pool;
        :class:`Cancelled` when a newer change comes, also while it waits for its turn."""
        with self._slots.slot() if self._slots is not None else contextlib.nullcontext():
            if self._generation != generation:
                raise Cancelled
            limit = self._time_limit
            deadline = math.inf if limit is None else time.monotonic() + limit
            try:
                return compute(
                    state,
                    generation,
                    cancelled=lambda: self._generation != generation or time.monotonic() > deadline,
                    cache=self._cache,
                    offload=self._offload,
                    **more,
                )
            except Cancelled:
                if self._generation != generation or time.monotonic() <= deadline:
                    raise
                raise InvalidInputError(
                    f"the computation exceeded the time limit of {limit:g} s and was stopped; "
                    "ask for less work (a lower max_iterations, a larger tolerance, fewer cycles "
                    "or algorithms)",
                    "max_iterations",
                ) from None

    def _reporter(self, generation: int, phase: str) -> Callable[..., None]:
        """``report(fraction, what="the runs")``: a ``progress`` event of ``phase`` ("runs", or
        "second": :meth:`_second_phase`) at most every 0.1 s, and at the end of the runs (the
        page then hides its bar; a second phase ends with its ``functionals`` event). A
        fraction None is work whose progress is not known (a synthesis in a compute worker)."""
        t0, last = time.perf_counter(), [0.0]

        def report(fraction: float | None, what: str = "the runs") -> None:
            now = time.perf_counter()
            end = fraction is not None and fraction >= 1 and phase == "runs"
            if now - last[0] > 0.1 or end:
                last[0] = now
                self._emit(
                    Event.of(
                        "progress",
                        generation,
                        phase=phase,
                        what=what,
                        fraction=fraction,
                        elapsed=now - t0,
                    )
                )

        return report

    def _known_functionals(self, state: DashboardState) -> tuple[tuple | None, set[str]]:
        """E1/E2 and their sensitivity for ``state`` when known (same map, same fixed
        variables), and the panels that wait for the second phase: the E1/E2 panel unless
        known (the page dims it meanwhile instead of redrawing a placeholder)."""
        cached = self._functionals_cache.get(functionals_key(state))
        return cached, (set() if cached else {"sensitivity"})

    def _panel_texts(
        self, result: DashboardResult, functionals, sens, todo: set[str], remember: bool
    ) -> dict[str, str]:
        """The JSON of the panels in ``todo``, with sticky axes (keep_ranges): against the
        layout each panel last went out with, for the same robot and task. ``remember``: these
        panels go out now (a result, not one solved ahead)."""
        layout_key = (result.state.robot, result.state.task)
        texts = {}
        for k, f in figure_specs(result, functionals, todo, sensitivity=sens).items():
            shown = self._layouts.get(k)
            keep_ranges(f, shown[1] if shown is not None and shown[0] == layout_key else None)
            if remember:
                self._layouts[k] = (layout_key, f["layout"])
            texts[k] = figure_json(f)
        return texts

    def _compute(self, generation: int, state: DashboardState) -> None:

        started = self._changed_at.get(generation, time.perf_counter())
        t0 = time.perf_counter()
        progress = self._reporter(generation, "runs")

        # The h panel's box stays while it fits (augmenting_grid), for the same robot and task.
        on_screen = self.result
        grid_before = (
            on_screen.augmenting
            if on_screen is not None
            and (on_screen.state.robot, on_screen.state.task) == (state.robot, state.task)
            else None
        )
        try:
            kin, amap = built_map(
                state,
                progress,
                lambda: self._generation != generation,
                None if self._offload is None else self._offload.synthesize,
            )
            deferred = expensive_map(amap)
            result = self._solved(
                state,
                generation,
                progress=progress,
                with_augmenting=not deferred,
                grid_before=grid_before,
            )
        except Cancelled:
            return
        except (JikError, ValueError, ServiceUnavailable) as exc:
            self._failure(generation, str(exc))
            return
        # Panels that do not depend on gamma are reused from the last result with the same key
        # (the map, every run, and the axes the configuration space is drawn on).
        key = "|".join((cache_key(state, "extended"), *runs_key(state), str(state.cspace_axes)))
        reuse = {k for k in gamma_free_panels(result) if (k, key) in self._figures}
        texts = {k: self._figures[(k, key)] for k in reuse}
        cached, stale = self._known_functionals(state)
        todo = set(PANELS) - reuse - stale
        functionals, sens = cached or (None, None)
        texts.update(self._panel_texts(result, functionals, sens, todo, remember=True))
        texts = {k: texts[k] for k in PANELS if k not in stale}
        self._figures = {(k, key): texts[k] for k in gamma_free_panels(result)}
        ready = time.perf_counter()
        head = {
            "type": "result",
            "generation": generation,
            "state": state.as_dict(),
            "summary": summary(result),
            "verdict": verdict(result),
            "colors": COLORS,
            "labels": LABELS,
            "timing": {
                "compute": result.seconds,
                "figures": ready - t0 - result.seconds,
                "server_total": ready - started,
            },
            "stale": sorted(stale),
        }
        data = with_figures(head, texts)
        with self._cond:
            if self.result is None or self.result.state.robot != state.robot:
                self._robot_since = generation
            self.result, self.functionals = result, functionals
            self._changed_at = {g: t for g, t in self._changed_at.items() if g > generation}
            self._second_running, self._second_cancelled = generation, None
        self._emit(Event("result", generation, data, result))
        self._finish(generation)
        self._second_phase(generation, kin, amap, result, deferred, cached, grid_before)
