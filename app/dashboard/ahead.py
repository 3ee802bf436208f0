"""Solving ahead: while no change comes, a :class:`~jik.app.dashboard.session.Dashboard` solves
the other robots' default states into its run cache and announces their figures (``ahead``
events), so that a switch of robot only draws."""

from __future__ import annotations

import logging
from collections.abc import Callable

from ...engine.exceptions import InvalidInputError, JikError
from .algorithms import cache_key
from .analysis import expensive_map, kinematics_and_map
from .messages import Event, Listeners, with_figures
from .model import DashboardState, updated_state
from .plotting import PANELS
from .runs import Cancelled, DashboardResult

log = logging.getLogger("jik.dashboard")

#: Robots whose default state the idle dashboard solves ahead (:meth:`SolvingAhead._prefetch`).
#: Not the unicycle: its ~1 s would hold the CPU that a change made meanwhile needs (its
#: switch shows progress instead).
PREFETCH_ROBOTS = ("manipulator1", "manipulator2")


class SolvingAhead(Listeners):
    """The dashboard's work while idle (a part of
    :class:`~jik.app.dashboard.session.Dashboard`, run by its worker thread)."""

    _stopped: bool
    _cache: dict
    # When each robot's result solved ahead went to the page (the value of _robot_since then),
    # and since when the robot on screen is (its first result's generation).
    _ahead_sent: dict[str, int]
    _robot_since: int
    _solved: Callable[..., DashboardResult]
    _known_functionals: Callable[[DashboardState], tuple[tuple | None, set[str]]]
    _panel_texts: Callable[..., dict[str, str]]

    def _prefetch(self, generation: int) -> None:
        """While no change comes, solve the other robots' (:data:`PREFETCH_ROBOTS`) default
        states into the run cache, any change cancelling it between legs: a switch of robot
        starts from those defaults (:func:`updated_state`), so it then only draws.

        Each is announced by an ``ahead`` event with the figures the switch will show (the
        page draws them off screen; the 3D scene builds the robot's nodes, hidden, from the
        event's result, given when the runs were solved now), again after every switch of
        robot; meanwhile its figures stay the same and nothing is done again.
        """

        for robot in PREFETCH_ROBOTS:
            if self._generation != generation or self._stopped:
                return
            if robot == self._state.robot:
                continue
            try:  # (the switch keeps the chosen algorithms, which this robot may refuse)
                state = updated_state(self._state, {"robot": robot})
            except InvalidInputError:
                continue
            solved = all(cache_key(state, a) in self._cache for a in state.algorithms)
            if solved and self._ahead_sent.get(robot) == self._robot_since:
                continue  # (its figures stay the same while the robot on screen stays)
            try:
                _, amap = kinematics_and_map(state)
                result = self._solved(state, generation, with_augmenting=not expensive_map(amap))
                cached, stale = self._known_functionals(state)
                functionals, sens = cached or (None, None)
                texts = self._panel_texts(
                    result, functionals, sens, set(PANELS) - stale, remember=False
                )
            except (Cancelled, JikError, ValueError):
                return
            except Exception:  # (work ahead: logged, never shown as the current result's error)
                log.exception("solving %s ahead failed", robot)
                return
            self._ahead_sent[robot] = self._robot_since
            head = {"type": "ahead", "generation": generation, "robot": robot}
            event = Event(
                "ahead", generation, with_figures(head, texts), None if solved else result
            )
            with self._cond:
                self._latest_ahead[robot] = event
            self._emit(event)
