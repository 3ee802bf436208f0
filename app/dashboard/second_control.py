"""A :class:`~jik.app.dashboard.session.Dashboard`'s second phase as the session sees it: run
after each result (:class:`~jik.app.dashboard.second_phase.SecondPhase`, its steps), cancelled
and run again on the page's request, and what the session's snapshot says of it."""

from __future__ import annotations

import threading
from collections.abc import Callable

from .analysis import expensive_map, kinematics_and_map
from .functionals import functionals_key
from .messages import Event
from .model import DashboardState
from .runs import Cancelled, DashboardResult
from .second_phase import SecondPhase, cancelled_message, finished_message


class SecondPhaseControl:
    """The second phase's part of :class:`~jik.app.dashboard.session.Dashboard`: its methods
    share the dashboard's lock, generation and worker."""

    _cond: threading.Condition
    _generation: int
    result: DashboardResult | None
    functionals: dict | None
    _functionals_cache: dict[str, tuple[dict | None, dict]]
    # The generation whose phase runs (None when none does, or it was cancelled), whose phase
    # was cancelled, whose phase to run again, and the grid on screen when it started (kept for
    # a run again).
    _second_running: int | None
    _second_cancelled: int | None
    _rerun: int | None
    _grid_before: dict | None
    _emit: Callable[[Event], None]
    _reporter: Callable[[int, str], Callable[..., None]]
    _known_functionals: Callable[[DashboardState], tuple[tuple | None, set[str]]]

    def _second_status(self) -> str | None:
        """The second phase of the result on screen: "computing", "cancelled" (E1, E2 and
        their sensitivity not computed) or "done"; None without a result. (With the lock.)"""
        if self.result is None:
            return None
        g = self.result.generation
        if self._second_running == g:
            return "computing"
        return "cancelled" if self._second_cancelled == g else "done"

    def _second_phase(
        self,
        generation: int,
        kin,
        amap,
        result: DashboardResult,
        deferred: bool,
        cached,
        grid_before: dict | None,
    ) -> None:
        """h on a grid when it is expensive, then E1 and E2 (quadrature) and their sensitivity
        (:class:`SecondPhase`), unless a newer change comes meanwhile: ``progress`` events
        (``"phase": "second"``, what is computed) and a ``functionals`` event at the end, or,
        when :meth:`cancel_second_phase` stopped it, one that says so (``cancelled``); see
        :func:`~jik.app.dashboard.second_phase.finished_message` for known functionals.
        """
        phase = SecondPhase(
            kin,
            amap,
            result,
            deferred=deferred,
            cached=cached,
            grid_before=grid_before,
            progress=self._reporter(generation, "second"),
            cancelled=lambda: generation != self._generation or generation != self._second_running,
        )
        with self._cond:
            self._grid_before = grid_before
        try:
            functionals, sens = phase.run()
        except Cancelled:
            self._second_stopped(generation, phase)
            return
        finally:
            with self._cond:
                if self._second_running == generation:
                    self._second_running = None
        if not phase.cached:
            self._functionals_cache = {functionals_key(result.state): (functionals, sens)}
        with self._cond:
            if self._generation != generation:
                return
            self.result, self.functionals = phase.result, functionals
        data = finished_message(phase, generation, functionals, sens)
        self._emit(Event("functionals", generation, data))

    def _second_stopped(self, generation: int, phase: SecondPhase) -> None:
        """A second phase stopped: by a newer change (nothing to say: its result follows), or
        cancelled (:meth:`cancel_second_phase`): a ``functionals`` event that says so, the grid
        kept when it was done (:func:`cancelled_message`)."""
        with self._cond:
            if self._generation != generation:
                return
            self.result = phase.result
            self._second_cancelled = generation
        self._emit(Event("functionals", generation, cancelled_message(phase, generation)))

    def cancel_second_phase(self, generation: int) -> bool:
        """Stop the second phase of ``generation`` (E1, E2, their sensitivity, h on a grid) at
        its next step; the result stays on screen. False when it is not running (done, or a
        newer generation is current)."""
        with self._cond:
            if self._second_running != generation or self._generation != generation:
                return False
            self._second_running = None
            return True

    def compute_second_phase(self, generation: int) -> bool:
        """Run again the cancelled second phase of ``generation``, the result on screen. False
        when it was not cancelled or ``generation`` is not current."""
        with self._cond:
            on_screen = self.result
            if (
                self._second_cancelled != generation
                or self._generation != generation
                or on_screen is None
                or on_screen.generation != generation
            ):
                return False
            self._second_cancelled, self._rerun = None, generation
            self._second_running = generation
            self._cond.notify_all()
        return True

    def _second_phase_again(self, generation: int) -> None:
        """The worker's side of :meth:`compute_second_phase`: the phase from where the
        cancelled one left the result (h on its grid when it was done)."""
        result = self.result
        if result is None or result.generation != generation:
            return
        kin, amap = kinematics_and_map(result.state)
        deferred = expensive_map(amap) and result.augmenting is None
        cached, _ = self._known_functionals(result.state)
        self._second_phase(generation, kin, amap, result, deferred, cached, self._grid_before)
