"""A state's augmenting map built with its progress shown and a newer change able to stop it.

A catalogue arm's default map (and a definition's ``e2_synthesized`` map, scalar or, for
p - r > 1, a vector) is synthesized on first use, eq. (19) over all the arm's joints
(:mod:`jik.engine.robot_synthesis`): a few seconds before the extended run can start.
:func:`built_map` builds it with the engine's progress reporting to the page ("synthesizing h",
its fraction done) and polling the session's cancellation between the pieces of the synthesis;
once built, the map is kept with the robot and costs nothing again.
"""

from __future__ import annotations

from collections.abc import Callable

from ...engine.exceptions import RunCancelled
from ...engine.progress import ProgressCallbacks
from ...engine.robot_synthesis import synthesis_progress
from .analysis import kinematics_and_map
from .robots import state_robot
from .runs import Cancelled

#: What the progress of a synthesis says on the page.
SYNTHESIZING = "synthesizing h (E2, eq. (19))"


def built_map(state, progress: Callable[..., None], cancelled: Callable[[], bool]) -> tuple:
    """:func:`~jik.app.dashboard.analysis.kinematics_and_map` of ``state``, a synthesis on the
    way reporting ``progress(fraction, SYNTHESIZING)`` and stopped by ``cancelled()`` (then
    :class:`Cancelled`, nothing kept)."""
    report = ProgressCallbacks(
        on_advance=lambda done, total: progress(min(done / total, 1.0), SYNTHESIZING),
        is_cancelled=cancelled,
    )
    try:
        with synthesis_progress(report):
            kin, amap = kinematics_and_map(state)
            if amap is None:  # (p - r > 1: a synthesized vector, built)
                maps = state_robot(state).map_vectors.get(state.augmentation)
                if callable(maps):
                    maps()
            return kin, amap
    except RunCancelled:
        raise Cancelled from None
