"""A result's second phase, after its runs are on screen: h on a grid when each value of h solves
a problem (the unicycle's characteristics, eqs. (28), (29)), then E1 (13), E2 (18) and their
sensitivity, in steps after each of which it reports its progress and may be cancelled. A
cancelled phase keeps h on its grid when the grid was done; the figures of
:func:`cancelled_message` say what was not computed.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import replace
from typing import Any

from .analysis import (
    augmenting_grid,
    expensive_map,
    grid_batches,
    kinematics_and_map,
    vector_note,
)
from .figures import figure_specs
from .functionals import error_functionals, functionals_key, sensitivity, sensitivity_evaluations
from .map_figures import augmenting_title
from .messages import Event, Listeners, with_figures
from .model import DashboardState
from .plotting import figure_json
from .runs import Cancelled, DashboardResult

#: What the page says is being computed, step by step.
GRID = "h on a grid"
FUNCTIONALS = "E1/E2 and their sensitivity"


class SecondPhase:
    """The second phase of ``result`` (its runs, without h on a grid when ``deferred``: an
    expensive map ``amap``, whose grid is computed here, its box kept from ``grid_before`` while
    it fits), run by :meth:`run`. ``cached``: E1/E2 and their sensitivity when already known, not
    computed again. ``progress(fraction, what)`` after each step: the fraction of the whole phase
    done, and :data:`GRID` or :data:`FUNCTIONALS`; ``cancelled()`` is polled after each step (and
    before every map the sensitivity builds): True stops the phase with :class:`Cancelled`.
    """

    def __init__(
        self,
        kin,
        amap,
        result: DashboardResult,
        *,
        deferred: bool,
        cached: tuple | None,
        grid_before: dict | None,
        progress: Callable[[float, str], None],
        cancelled: Callable[[], bool],
    ) -> None:
        self.kin, self.result, self.deferred, self.cached = kin, result, deferred, cached
        self.grid_before = grid_before
        self._progress, self._cancelled = progress, cancelled
        grid = grid_batches(result.runs, amap) if deferred else 0
        rest = 0 if cached else 2 + sensitivity_evaluations(result.state, amap)
        self.steps = {GRID: grid, FUNCTIONALS: rest}
        self.what = GRID if grid else FUNCTIONALS
        self.fraction = 0.0

    def _step(self, what: str, before: int) -> Callable[[float, float], None]:
        """The progress callback ``(done, _)`` of a stage that starts after ``before`` steps;
        it raises :class:`Cancelled` when the phase is cancelled."""
        whole = max(1, sum(self.steps.values()))

        def step(done: float, _total: float) -> None:
            self.what = what
            self.fraction = min(1.0, (before + done) / whole)
            self._progress(self.fraction, what)
            if self._cancelled():
                raise Cancelled

        return step

    def run(self) -> tuple[dict | None, dict]:
        """E1/E2 and their sensitivity (with h on its grid first, when deferred); raises
        :class:`Cancelled` when cancelled, keeping in :attr:`result` the grid if it was done."""
        if self._cancelled():
            raise Cancelled
        if self.deferred:
            grid = augmenting_grid(
                self.kin,
                self.result.state,
                self.result.runs,
                before=self.grid_before,
                progress=self._step(GRID, 0),
            )
            self.result = replace(self.result, augmenting=grid)
        if self.cached:
            return self.cached
        grid = self.steps[GRID]
        one = self._step(FUNCTIONALS, grid)  # (two steps: E1, E2)
        functionals = error_functionals(
            self.result, lambda done, total: one(2 * done / total, 2), self._cancelled
        )
        sens = sensitivity(
            self.result, functionals, self._cancelled, progress=self._step(FUNCTIONALS, grid + 2)
        )
        return functionals, sens


def finished_message(
    phase: SecondPhase, generation: int, functionals: dict | None, sens: dict | None
) -> str:
    """The ``functionals`` event of a phase that finished: E1/E2, their sensitivity and the
    panels they change. Known functionals went out with the result: the event then only
    carries the h panel's title (a reused panel can lack it, and a page that connects now gets
    this event with the latest result)."""
    panels = {"sensitivity"} if not phase.cached or phase.deferred else set()
    titles = {}
    if phase.deferred:  # the h panel was a placeholder: the whole figure
        panels.add("augmenting")
    elif functionals is not None and phase.result.augmenting is not None:  # (h on screen)
        titles["augmenting"] = augmenting_title(phase.result, functionals)  # (not redrawn)
    specs = figure_specs(phase.result, functionals, panels, sensitivity=sens)
    return _message(generation, functionals, sens, specs, titles=titles or None)


def cancelled_message(phase: SecondPhase, generation: int) -> str:
    """The ``functionals`` event of a cancelled phase: no E1, E2; the figures of the panels it
    would have drawn, each saying what was cancelled (never a value of another state), the h
    panel's new title when its figure stays (h on screen, E1, E2 in its title not computed),
    and ``cancelled``: what was being computed, how far, and those panels."""
    note = f"cancelled at {round(100 * phase.fraction)}% (while computing {phase.what})"
    panels = set() if phase.cached else {"sensitivity"}
    if phase.deferred:  # (the h panel was a placeholder: the whole figure, with h if done)
        panels.add("augmenting")
    specs = figure_specs(phase.result, None, panels, cancelled=note)
    titles = {}
    if not phase.deferred and not phase.cached and vector_note(phase.result.state) is None:
        titles["augmenting"] = augmenting_title(phase.result, None, note)
    shown = sorted(set(specs) | set(titles))
    cancelled = {"what": phase.what, "fraction": phase.fraction, "panels": shown}
    return _message(generation, None, None, specs, titles=titles, cancelled=cancelled)


def _message(generation: int, functionals, sens, specs: dict[str, dict], **more) -> str:
    """A ``functionals`` event: E1/E2, their sensitivity, the figures ``specs`` and ``more``
    fields (those given as None left out)."""
    message: dict[str, Any] = {"type": "functionals", "generation": generation}
    message |= {"functionals": functionals, "sensitivity": sens}
    message |= {k: v for k, v in more.items() if v is not None}
    return with_figures(message, {k: figure_json(f) for k, f in specs.items()})


class SecondPhaseControl(Listeners):
    """The second phase's part of :class:`~jik.app.dashboard.session.Dashboard`: its methods
    share the dashboard's lock, generation and worker."""

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
        """Run :class:`SecondPhase`, unless a newer change comes meanwhile: ``progress`` events
        (``"phase": "second"``) and a ``functionals`` event at the end (:func:`finished_message`),
        or, when :meth:`cancel_second_phase` stopped it, one that says so
        (:func:`cancelled_message`)."""
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
        except Cancelled:  # (by a newer change, whose result follows, or cancelled)
            with self._cond:
                if self._generation != generation:
                    return
                self.result = phase.result  # (the grid kept when it was done)
                self._second_cancelled = generation
            self._emit(Event("functionals", generation, cancelled_message(phase, generation)))
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
